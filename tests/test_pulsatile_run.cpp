// The time loop of a run (solver/pulsatile_run): its cycles, its own measurement of the step
// against the longest cycle it may take, interrupt requests answered at a step's end, and a
// resume from its in-memory checkpoint that goes on as the run would have.
#include <csignal>
#include <filesystem>
#include <numbers>

#include <gtest/gtest.h>
#include <unistd.h>

#include "cli/interrupt.hpp"
#include "network_builders.hpp"
#include "solver/pulsatile_run.hpp"

namespace hemotree {
namespace {

using namespace test_networks;

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
  InterruptRequests interrupts;
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
  InterruptRequests interrupts;
  EXPECT_EQ(run.run(interrupts), RunStatus::too_long);
  EXPECT_EQ(run.cycles_done(), 0);
}

TEST(PulsatileRun, AnswersAnInterruptAtAStepsEnd) {
  Fixture f;
  PulseSolver s(f.net, f.options);
  PulsatileRun run(f.net, s, {}, f.plan(s, 3), f.folder);
  InterruptRequests interrupts;
  ::raise(SIGTERM);  // blocked: pending until polled, the process lives on
  EXPECT_EQ(run.run(interrupts), RunStatus::interrupted);
  EXPECT_EQ(run.signal(), SIGTERM);
  EXPECT_EQ(run.cycles_done(), 0);
  EXPECT_EQ(interrupts.poll(), 0);  // consumed
}

TEST(PulsatileRun, ResumesFromItsCheckpointAsIfNeverStopped) {
  Fixture f;
  PulseSolver whole(f.net, f.options);
  PulsatileRun a(f.net, whole, {}, f.plan(whole, 4), f.folder);
  InterruptRequests interrupts;
  ASSERT_EQ(a.run(interrupts), RunStatus::complete);

  PulseSolver first(f.net, f.options);
  PulsatileRun b(f.net, first, {}, f.plan(first, 2), f.folder);
  ASSERT_EQ(b.run(interrupts), RunStatus::complete);
  b.write_checkpoint();
  PulseSolver second(f.net, f.options);
  PulsatileRun c(f.net, second, {}, f.plan(second, 4), f.folder);
  c.resume(read_checkpoint_file(f.folder / "checkpoint.bin"), "checkpoint.bin");
  EXPECT_EQ(c.cycles_done(), 2);
  ASSERT_EQ(c.run(interrupts), RunStatus::complete);
  EXPECT_EQ(c.cycles_done(), 4);
  EXPECT_TRUE((second.state().area.array() == whole.state().area.array()).all());
  EXPECT_TRUE((second.state().flow.array() == whole.state().flow.array()).all());
  EXPECT_EQ(c.last_cycle().vessels[0].mean_pressure, a.last_cycle().vessels[0].mean_pressure);
  EXPECT_EQ(c.change().change, a.change().change);
}

}  // namespace
}  // namespace hemotree
