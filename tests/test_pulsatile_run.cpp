// The time loop of a run (solver/pulsatile_run): its cycles, its own measurement of the step
// against the longest cycle it may take, interrupt requests answered at a step's end, and a
// resume from its in-memory checkpoint that goes on as the run would have, a checkpoint
// changed after it was written refused, and a resume with no cycle left to run.
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <numbers>

#include <gtest/gtest.h>
#include <unistd.h>

#include "core/errors.hpp"
#include "cli/interrupt.hpp"
#include "cli/setting_words.hpp"
#include "core/setting_error.hpp"
#include "network_builders.hpp"
#include "solver/pulsatile_run.hpp"

namespace hemotree {
namespace {

using namespace test_networks;

// The run's interrupt requests are the process's signals, as hemosolve's are.
struct Interrupts : RunObserver {
  InterruptRequests requests;
  int poll_interrupt() override { return requests.poll(); }
  int poll() { return requests.poll(); }
};

Network pulsed_vessel() {
  const double d = 3e-3, a = std::numbers::pi / 4 * d * d;
  Network net = chain(1, 0.2, d, beta_for_wave_speed(5.0, a), 1e4, newtonian(4e-3));
  auto inflow = [](double t) { return 5e-6 + 3e-6 * std::sin(2 * std::numbers::pi * t / 0.1); };
  net.inlet = Inlet{0, tabulate(inflow, 0.1, 101, 0.1)};
  net.outlets.push_back(resistance_outlet(0, 2e9, 0));
  return net;
}

struct Fixture {
  Network net = pulsed_vessel();
  SolverOptions options;
  std::filesystem::path folder = std::filesystem::temp_directory_path() / ("pulsatile-run-" + std::to_string(::getpid()));
  Fixture() {
    options.degree = 2;
    std::filesystem::create_directories(folder);
  }
  ~Fixture() { std::filesystem::remove_all(folder); }
  RunPlan plan(PulseSolver& s, int cycles) {
    RunPlan p;
    p.cycles = cycles;
    p.steps_per_cycle = static_cast<std::size_t>(std::ceil(net.inlet->waveform.period / s.dt()));
    s.set_time_step(net.inlet->waveform.period / static_cast<double>(p.steps_per_cycle));
    return p;
  }
};

TEST(PulsatileRun, RunsItsCycles) {
  Fixture f;
  PulseSolver s(f.net, f.options);
  PulsatileRun run(f.net, s, {}, f.plan(s, 3), f.folder);
  Interrupts interrupts;
  EXPECT_EQ(run.run(interrupts), RunStatus::complete);
  EXPECT_EQ(run.cycles_done(), 3);
  EXPECT_NEAR(s.time(), 0.3, 1e-12);
  EXPECT_GT(run.measured_step(), 0);
  EXPECT_LT(std::abs(run.last_cycle().conservation_error), 1e-12);
}

TEST(PulsatileRun, StopsWhenItsOwnStepSaysACycleIsTooLong) {
  Fixture f;
  PulseSolver s(f.net, f.options);
  RunPlan plan = f.plan(s, 3);
  plan.longest_cycle = 1e-9;  // [s]: no machine does a cycle in a nanosecond
  PulsatileRun run(f.net, s, {}, plan, f.folder);
  Interrupts interrupts;
  EXPECT_EQ(run.run(interrupts), RunStatus::too_long);
  EXPECT_EQ(run.cycles_done(), 0);
}

TEST(PulsatileRun, AnswersAnInterruptAtAStepsEnd) {
  Fixture f;
  PulseSolver s(f.net, f.options);
  PulsatileRun run(f.net, s, {}, f.plan(s, 3), f.folder);
  Interrupts interrupts;
  ::raise(SIGTERM);  // blocked: pending until polled, the process lives on
  EXPECT_EQ(run.run(interrupts), RunStatus::interrupted);
  EXPECT_EQ(run.signal(), SIGTERM);
  EXPECT_EQ(run.cycles_done(), 0);
  EXPECT_EQ(interrupts.poll(), 0);  // consumed
}

// Stopped within its second cycle, a run reports its first: the per-vessel results it set
// aside in its snapshot while the cycle ran, read back, are a one-cycle run's, bit for bit.
TEST(PulsatileRun, StoppedWithinACycleReportsTheCycleBefore) {
  Fixture f;
  PulseSolver one(f.net, f.options);
  PulsatileRun a(f.net, one, {}, f.plan(one, 1), f.folder);
  Interrupts quiet;
  ASSERT_EQ(a.run(quiet), RunStatus::complete);
  const CycleSummary first = a.last_cycle();
  PulseSolver three(f.net, f.options);
  PulsatileRun b(f.net, three, {}, f.plan(three, 3), f.folder);
  struct StopInTheSecond : RunObserver {
    const PulsatileRun* run = nullptr;
    int poll_interrupt() override { return run->cycles_done() >= 1 ? SIGINT : 0; }
  } stop;
  stop.run = &b;
  ASSERT_EQ(b.run(stop), RunStatus::interrupted);
  EXPECT_EQ(b.cycles_done(), 1);
  ASSERT_EQ(b.last_cycle().vessels.size(), first.vessels.size());
  ASSERT_FALSE(first.vessels.empty());
  for (std::size_t v = 0; v < first.vessels.size(); ++v) {
    const VesselCycle &got = b.last_cycle().vessels[v], &want = first.vessels[v];
    EXPECT_EQ(std::memcmp(&got, &want, sizeof got), 0) << "vessel " << v;  // NaN wave speeds too
    EXPECT_GT(want.mean_pressure, 0.0);
  }
  EXPECT_EQ(b.last_cycle().conservation_error, first.conservation_error);
  EXPECT_EQ(b.last_cycle().boundary_mean_flow, first.boundary_mean_flow);
  ASSERT_FALSE(first.boundary_mean_flow.empty());
}

// The cycle before the last's mean pressures are not held while a cycle runs but read back
// from the last cycle end's snapshot: the change after cycle 3 is that of cycle 2's results
// (as a run of two cycles reports them) against cycle 3's, to the bit.
TEST(PulsatileRun, ComparesEachCycleWithTheOneBefore) {
  Fixture f;
  Interrupts interrupts;
  PulseSolver two(f.net, f.options);
  PulsatileRun a(f.net, two, {}, f.plan(two, 2), f.folder);
  ASSERT_EQ(a.run(interrupts), RunStatus::complete);
  std::vector<double> second;
  for (const VesselCycle& v : a.last_cycle().vessels) second.push_back(v.mean_pressure);
  PulseSolver three(f.net, f.options);
  PulsatileRun b(f.net, three, {}, f.plan(three, 3), f.folder);
  ASSERT_EQ(b.run(interrupts), RunStatus::complete);
  ASSERT_TRUE(b.has_change());
  const PeriodicityChange want = cycle_change(second, b.last_cycle().vessels);
  EXPECT_GT(want.change, 0.0);
  EXPECT_EQ(b.change().change, want.change);
  EXPECT_EQ(b.change().vessel, want.vessel);
}

// A settling cycle (solver/settling_cycle.hpp) is not one of the run's: the run's cycles
// start after it at t = 0, and an interrupt within it stops the run with nothing kept.
TEST(PulsatileRun, TakesItsSettlingCycleBeforeItsOwn) {
  Fixture f;
  Interrupts quiet;
  PulseSolver settled(f.net, f.options);
  RunPlan plan = f.plan(settled, 1);
  plan.settling_steps = plan.steps_per_cycle;
  PulsatileRun a(f.net, settled, {}, plan, f.folder);
  ASSERT_EQ(a.run(quiet), RunStatus::complete);
  EXPECT_EQ(a.cycles_done(), 1);
  EXPECT_EQ(a.settling().steps, plan.steps_per_cycle);
  EXPECT_FALSE(a.stopped_settling());
  EXPECT_EQ(settled.steps(), plan.steps_per_cycle);  // the run's own steps alone
  EXPECT_NEAR(settled.time(), f.net.inlet->waveform.period, 1e-12);
  a.discard_snapshot();

  PulseSolver stopped(f.net, f.options);
  PulsatileRun b(f.net, stopped, {}, plan, f.folder);
  struct StopAtOnce : RunObserver {
    int poll_interrupt() override { return SIGINT; }
  } stop;
  ASSERT_EQ(b.run(stop), RunStatus::interrupted);
  EXPECT_TRUE(b.stopped_settling());
  EXPECT_EQ(b.signal(), SIGINT);
  EXPECT_EQ(b.cycles_done(), 0);
  EXPECT_FALSE(std::filesystem::exists(f.folder / "snapshot.pending"));
}

// A settling cycle taken by another solver (the 1D vessels at a lower degree): the run starts
// from the state it leaves; where it breaks down (here a step 20 times its stable one), the
// run stops with nothing computed and says how to go without it: --settling-degree 0 (its
// default takes one).
TEST(PulsatileRun, SettlesWithAnotherSolverAndNamesItsOptionWhereItBreaksDown) {
  Fixture f;
  Interrupts quiet;
  SolverOptions coarse_options = f.options;
  coarse_options.degree = 1;
  PulseSolver settled(f.net, f.options);
  RunPlan plan = f.plan(settled, 1);
  auto coarse = std::make_unique<PulseSolver>(f.net, coarse_options);
  plan.settling_steps = static_cast<std::size_t>(std::ceil(f.net.inlet->waveform.period / coarse->dt()));
  PulsatileRun a(f.net, settled, {}, plan, f.folder);
  a.settle_with(std::move(coarse));
  ASSERT_EQ(a.run(quiet), RunStatus::complete);
  EXPECT_EQ(a.settling().degree, 1);
  EXPECT_EQ(a.cycles_done(), 1);
  EXPECT_EQ(settled.steps(), plan.steps_per_cycle);  // its own steps alone, from t = 0
  a.discard_snapshot();

  // Twenty elements: short ones, whose stable step the settling cycle's exceeds twentyfold.
  SolverOptions fine = f.options;
  fine.elements = coarse_options.elements = 20;
  PulseSolver broken(f.net, fine);
  RunPlan broken_plan = f.plan(broken, 1);
  auto unstable = std::make_unique<PulseSolver>(f.net, coarse_options);
  broken_plan.settling_steps = std::max<std::size_t>(1, static_cast<std::size_t>(f.net.inlet->waveform.period / (20 * unstable->dt())));
  PulsatileRun b(f.net, broken, {}, broken_plan, f.folder);
  b.settle_with(std::move(unstable));
  ASSERT_EQ(b.run(quiet), RunStatus::broken_down);
  EXPECT_EQ(b.cycles_done(), 0);
  EXPECT_NE(in_words(b.breakdown(), hemosolve_words()).find("(with --settling-degree 0 the run takes none)"),
            std::string::npos)
      << b.breakdown();
}

TEST(PulsatileRun, ResumesFromItsCheckpointAsIfNeverStopped) {
  Fixture f;
  PulseSolver whole(f.net, f.options);
  PulsatileRun a(f.net, whole, {}, f.plan(whole, 4), f.folder);
  Interrupts interrupts;
  ASSERT_EQ(a.run(interrupts), RunStatus::complete);

  PulseSolver first(f.net, f.options);
  PulsatileRun b(f.net, first, {}, f.plan(first, 2), f.folder);
  ASSERT_EQ(b.run(interrupts), RunStatus::complete);
  b.write_checkpoint();
  PulseSolver second(f.net, f.options);
  PulsatileRun c(f.net, second, {}, f.plan(second, 4), f.folder);
  c.resume(std::make_unique<CheckpointReader>(f.folder / "checkpoint.bin"));  // from the file
  EXPECT_EQ(c.cycles_done(), 2);
  ASSERT_EQ(c.run(interrupts), RunStatus::complete);
  EXPECT_EQ(c.cycles_done(), 4);
  EXPECT_TRUE((second.state().area.array() == whole.state().area.array()).all());
  EXPECT_TRUE((second.state().flow.array() == whole.state().flow.array()).all());
  EXPECT_EQ(c.last_cycle().vessels[0].mean_pressure, a.last_cycle().vessels[0].mean_pressure);
  EXPECT_EQ(c.change().change, a.change().change);
}

// A run's own checkpoint file, each of its bytes flipped in turn: every one is refused
// before the run takes anything from it (the probes' rows and the cycle results too).
TEST(PulsatileRun, RefusesItsCheckpointWithAnyByteChanged) {
  Fixture f;
  PulseSolver first(f.net, f.options);
  PulsatileRun a(f.net, first, {}, f.plan(first, 2), f.folder);
  Interrupts interrupts;
  ASSERT_EQ(a.run(interrupts), RunStatus::complete);
  a.write_checkpoint();
  const std::string bytes = read_checkpoint_file(f.folder / "checkpoint.bin");
  PulseSolver second(f.net, f.options);
  PulsatileRun b(f.net, second, {}, f.plan(second, 4), f.folder);
  std::size_t refused = 0;
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    std::string changed = bytes;
    changed[i] = static_cast<char>(changed[i] ^ 0x04);
    try {
      b.resume(std::make_unique<CheckpointReader>(changed, "checkpoint.bin"));
      ADD_FAILURE() << "byte " << i << " of " << bytes.size() << " changed and accepted";
    } catch (const InputError&) {
      ++refused;
    }
  }
  EXPECT_EQ(refused, bytes.size());
  EXPECT_EQ(b.cycles_done(), 0);
  b.resume(std::make_unique<CheckpointReader>(bytes, "checkpoint.bin"));  // the file as written
  EXPECT_EQ(b.cycles_done(), 2);
}

// A checkpoint at the run's end: nothing is left to compute. A published run's is refused as
// it stands; a killed run's (in the folder the run writes) is taken, its results written from
// it, and its checkpoint written again byte for byte.
TEST(PulsatileRun, ResumedAtItsEnd) {
  Fixture f;
  PulseSolver first(f.net, f.options);
  PulsatileRun a(f.net, first, {}, f.plan(first, 2), f.folder);
  Interrupts interrupts;
  ASSERT_EQ(a.run(interrupts), RunStatus::complete);
  a.write_checkpoint();
  const std::string bytes = read_checkpoint_file(f.folder / "checkpoint.bin");
  const std::filesystem::path staging = f.folder.string() + ".partial";
  std::filesystem::create_directories(staging);

  PulseSolver s1(f.net, f.options);
  PulsatileRun published(f.net, s1, {}, f.plan(s1, 2), staging);
  try {
    published.resume(std::make_unique<CheckpointReader>(bytes, (f.folder / "checkpoint.bin").string()));
    FAIL() << "resumed a published run that has its cycles";
  } catch (const SettingError& e) {  // the setting by its name; hemosolve's user reads its flag
    EXPECT_NE(std::string(e.what()).find("the run already has its 2 cycles; raise cycles to continue"),
              std::string::npos)
        << e.what();
    EXPECT_NE(e.in_words(hemosolve_words()).find("the run already has its 2 cycles; raise --cycles to continue"),
              std::string::npos)
        << e.in_words(hemosolve_words());
  }

  PulseSolver s2(f.net, f.options);
  PulsatileRun fewer(f.net, s2, {}, f.plan(s2, 1), f.folder);
  EXPECT_THROW(fewer.resume(std::make_unique<CheckpointReader>(bytes, (f.folder / "checkpoint.bin").string())), InputError);  // beyond --cycles 1

  PulseSolver s3(f.net, f.options);
  RunPlan with_frames = f.plan(s3, 2);
  with_frames.frames = 2;
  PulsatileRun framed(f.net, s3, {}, with_frames, f.folder);
  EXPECT_THROW(framed.resume(std::make_unique<CheckpointReader>(bytes, (f.folder / "checkpoint.bin").string())), InputError);  // no frames of it here

  PulseSolver s4(f.net, f.options);
  PulsatileRun killed(f.net, s4, {}, f.plan(s4, 2), f.folder);
  // From a file removed once it is read: the run copies the checkpoint it holds open.
  const std::filesystem::path kept = f.folder / "kept.bin";
  std::filesystem::copy_file(f.folder / "checkpoint.bin", kept);
  killed.resume(std::make_unique<CheckpointReader>(kept));
  std::filesystem::remove(kept);
  EXPECT_FALSE(killed.cycles_left());
  EXPECT_FALSE(killed.keeps_frames());  // none asked for
  EXPECT_EQ(killed.run(interrupts), RunStatus::complete);
  EXPECT_EQ(killed.cycles_done(), 2);
  EXPECT_EQ(killed.last_cycle().vessels[0].mean_pressure, a.last_cycle().vessels[0].mean_pressure);
  std::filesystem::remove(f.folder / "checkpoint.bin");
  killed.write_checkpoint();
  EXPECT_EQ(read_checkpoint_file(f.folder / "checkpoint.bin"), bytes);
  std::filesystem::remove_all(staging);
}

}  // namespace
}  // namespace hemotree
