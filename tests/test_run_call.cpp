// A run as a library call (solver/pulsatile_call.hpp): a network built here and a run
// configuration in, the results folder and the outcome out, with no command line; and the
// time step decided in one place (solver/run_configuration.hpp).
#include <csignal>
#include <filesystem>
#include <numbers>

#include <gtest/gtest.h>
#include <unistd.h>

#include "core/errors.hpp"
#include "network_builders.hpp"
#include "solver/pulsatile_call.hpp"

namespace hemotree {
namespace {

using namespace test_networks;

// Three equal vessels in series, a constant inflow Q into the first and a resistance R to
// p = 0 at the end of the last: in the steady state the mean pressure at a vessel's middle is
// Q R plus the Poiseuille drop 8 mu Q / (pi r^4) over the length downstream of it.
struct SeriesOfThree {
  static constexpr double q = 5e-7, r_outlet = 2e10, mu = 4e-3, d = 3e-3, length = 0.2, period = 0.1;
  Network net;
  SeriesOfThree() {
    const double area = std::numbers::pi / 4 * d * d;
    // A stiff wall (c = 50 m/s, beta = 2e9 Pa/m) referred to the outlet's pressure: over the
    // Poiseuille drop (200 Pa) sqrt(A) moves by 200 / beta = 4e-5 of its 2.7e-3 m^(1/2), so the
    // resistance (as A^-2) stays within 1.5e-4 of the rigid tube's over that drop: 0.03 Pa,
    // 3e-6 of the pressure.
    net = chain(3, length, d, beta_for_wave_speed(50.0, area), q * r_outlet, newtonian(mu));
    net.inlet = Inlet{0, tabulate([](double) { return q; }, period, 11, period)};
    net.outlets.push_back(resistance_outlet(2, r_outlet, 0));
  }
  double expected_mean_pressure(int vessel) const {
    const double poiseuille = 8 * mu / (std::numbers::pi * std::pow(d / 2, 4));  // per metre [Pa s/m^4]
    const double downstream = length / 3 * (2 - vessel + 0.5);
    return q * r_outlet + q * poiseuille * downstream;
  }
};

struct Folder {
  std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("run-call-" + std::to_string(::getpid()));
  ~Folder() {
    std::filesystem::remove_all(path);
    std::filesystem::remove_all(path.string() + ".partial");
  }
};

RunConfiguration two_cycles(const Folder& folder) {
  RunConfiguration config;
  config.network_name = "series of three (built in the test)";
  config.out_dir = folder.path.string();
  config.solver.model = ModelChoice::one_d;
  config.solver.degree = 2;
  config.cycles = 2;
  return config;
}

// Records what the run says, and asks it to stop at the first poll when told to.
struct Recorder : RunObserver {
  std::vector<std::string> notes, warnings;
  int stop_with = 0;
  void note(const std::string& m) override { notes.push_back(m); }
  void warn(const std::string& m) override { warnings.push_back(m); }
  int poll_interrupt() override { return stop_with; }
};

TEST(RunCall, ASteadyFlowThroughThreeVesselsHasPoiseuillesPressures) {
  const SeriesOfThree case_;
  const Folder folder;
  Recorder observer;
  const RunResult result = run_pulsatile(case_.net, two_cycles(folder), observer);
  ASSERT_EQ(result.outcome, RunOutcome::complete) << result.error;
  EXPECT_EQ(result.cycles_done, 2);
  EXPECT_TRUE(observer.warnings.empty());
  // The mean inflow is the prescribed constant: it is imposed, up to round-off.
  EXPECT_NEAR(result.last_cycle.inlet_mean_flow, SeriesOfThree::q, 1e-12 * SeriesOfThree::q);
  ASSERT_EQ(result.last_cycle.vessels.size(), 3u);
  for (int v = 0; v < 3; ++v) {
    const double expected = case_.expected_mean_pressure(v);
    // 1e-5: the wall's distension (3e-6 of the pressure, above), with room. No kinetic term:
    // the vessels are equal, so the velocity and rho u^2 / 2 are the same at every junction,
    // and the outlet's resistance takes the static pressure. (Measured: 1e-6.)
    EXPECT_NEAR(result.last_cycle.vessels[static_cast<std::size_t>(v)].mean_pressure, expected, 1e-5 * expected)
        << "vessel " << v;
    EXPECT_NEAR(result.last_cycle.vessels[static_cast<std::size_t>(v)].mean_flow, SeriesOfThree::q,
                1e-9 * SeriesOfThree::q);
  }
  // The step is a whole number per cycle, and the folder holds the run's files.
  EXPECT_NEAR(result.time_step * static_cast<double>(result.steps_per_cycle), SeriesOfThree::period, 1e-15);
  EXPECT_TRUE(std::filesystem::is_regular_file(folder.path / "summary.json"));
  EXPECT_TRUE(std::filesystem::is_regular_file(folder.path / "vessels.csv"));
}

TEST(RunCall, AnInterruptBeforeTheFirstStepWritesNothing) {
  const SeriesOfThree case_;
  const Folder folder;
  Recorder observer;
  observer.stop_with = SIGINT;
  const RunResult result = run_pulsatile(case_.net, two_cycles(folder), observer);
  EXPECT_EQ(result.outcome, RunOutcome::interrupted);
  EXPECT_FALSE(result.started);
  EXPECT_EQ(result.signal, SIGINT);
  EXPECT_FALSE(std::filesystem::exists(folder.path));
  ASSERT_EQ(observer.warnings.size(), 1u);
}

TEST(RunCall, RefusesAConfigurationOutOfItsRanges) {
  const SeriesOfThree case_;
  const Folder folder;
  Recorder observer;
  RunConfiguration config = two_cycles(folder);
  config.cycles = 0;
  EXPECT_THROW(run_pulsatile(case_.net, config, observer), InputError);
  config = two_cycles(folder);
  config.sample_interval = 2 * SeriesOfThree::period;  // beyond the period
  EXPECT_THROW(run_pulsatile(case_.net, config, observer), InputError);
}

TEST(DecideCycleStep, RoundsTheStepDownToAWholeNumberPerCycle) {
  const CycleStep a = decide_cycle_step(1.0, 0.3, "test");
  EXPECT_EQ(a.steps_per_cycle, 4u);
  EXPECT_DOUBLE_EQ(a.dt, 0.25);
  // A step that divides the period within round-off keeps its count.
  const CycleStep b = decide_cycle_step(1.0, 0.1 * (1 + 1e-12), "test");
  EXPECT_EQ(b.steps_per_cycle, 10u);
  // No machine runs 1e13 steps a cycle.
  EXPECT_THROW(decide_cycle_step(1.0, 1e-13, "a vessel's friction"), InputError);
}

}  // namespace
}  // namespace hemotree
