// A run as a library call (solver/pulsatile_call.hpp): a network built here and a run
// configuration in, the results folder and the outcome out, with no command line; and the
// time step decided in one place (solver/run_configuration.hpp).
#include <csignal>
#include <filesystem>
#include <numbers>

#include <gtest/gtest.h>
#include <unistd.h>

#include "cli/setting_words.hpp"
#include "core/errors.hpp"
#include "core/setting_error.hpp"
#include "network_builders.hpp"
#include "solver/outcome_lines.hpp"
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

// The run names its settings by their own names to a caller from code (no words), and by
// hemosolve's flags through hemosolve's words: no library text carries a flag.
SettingError refusal_of(const Network& net, const RunConfiguration& config) {
  Recorder observer;
  try {
    run_pulsatile(net, config, observer);
  } catch (const SettingError& e) {
    return e;
  }
  ADD_FAILURE() << "the run was not refused";
  return SettingError("", "");
}

TEST(RunCall, NamesSettingsInTheCallersWords) {
  const SeriesOfThree case_;
  const Folder folder;
  RunConfiguration config = two_cycles(folder);
  config.solver.dt = SeriesOfThree::period / 4;  // far above the stability limit
  SettingError e = refusal_of(case_.net, config);
  EXPECT_EQ(e.setting(), "dt");
  const std::string own(e.what()), flags = e.in_words(hemosolve_words());
  EXPECT_EQ(own.rfind("dt 0.025 s is ", 0), 0u) << own;
  EXPECT_NE(own.find("use a dt of at most the limit, or force to run it anyway"), std::string::npos) << own;
  EXPECT_EQ(own.find("--"), std::string::npos) << own;
  EXPECT_EQ(flags.rfind("--dt 0.025 s is ", 0), 0u) << flags;
  EXPECT_NE(flags.find("use a --dt of at most the limit, or --force to run it anyway"), std::string::npos) << flags;

  // A setting whose flag is not its name: the periodic tolerance is hemosolve's --until-periodic.
  config = two_cycles(folder);
  config.until_periodic = true;
  config.periodic_tolerance = 2;
  e = refusal_of(case_.net, config);
  EXPECT_STREQ(e.what(), "periodic_tolerance must lie in (0, 1) (got 2)");
  EXPECT_EQ(e.in_words(hemosolve_words()), "--until-periodic must lie in (0, 1) (got 2)");

  config = two_cycles(folder);
  config.cycles = 0;
  e = refusal_of(case_.net, config);
  EXPECT_STREQ(e.what(), "cycles must lie in [1, 100000] (got 0)");
  EXPECT_EQ(e.in_words(hemosolve_words()), "--cycles must lie in [1, 100000] (got 0)");
}

// Texts the run keeps (the outcome's lines) are worded by the configuration's words.
TEST(RunCall, SaysItsOutcomeInTheCallersWords) {
  RunConfiguration config;
  config.out_dir = "out";
  config.max_cycles = 4;
  config.periodic_tolerance = 1e-3;
  RunResult result;
  result.outcome = RunOutcome::not_periodic;
  EXPECT_EQ(outcome_warning(result, config, ""),
            "not periodic within 4 cycles (max_cycles), above periodic_tolerance 0.001; exit status 3");
  config.words = hemosolve_words();
  EXPECT_EQ(outcome_warning(result, config, ""),
            "not periodic within 4 cycles (--max-cycles), above --until-periodic 0.001; exit status 3");
  result.outcome = RunOutcome::interrupted;
  result.cycles_done = 1;
  EXPECT_EQ(outcome_warning(result, config, "SIGINT"),
            "interrupted by SIGINT after 1 cycle: out holds the results of the last whole cycle and its "
            "checkpoint; --resume out continues");
}

}  // namespace
}  // namespace hemotree
