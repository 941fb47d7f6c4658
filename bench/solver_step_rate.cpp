// Step rate of hemosolve's solver on a network: time step, steps per second (median of
// several timed batches) and the wall time per cardiac cycle that follows from them.
// usage: [HEMOTREE_THREADS=n] solver_step_rate NET [degree|auto|auto:LOW:RAISE] [steps per batch] [batches] [etd2|ab2|rk4]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "core/setting_error.hpp"
#include "formats/network_io.hpp"
#include "pulse/pulse_solver.hpp"
#include "solver/run_estimate.hpp"

using namespace hemotree;

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: solver_step_rate NET [degree] [steps per batch] [batches]\n");
    return 2;
  }
  const Network net = read_network(argv[1]);
  SolverOptions options;
  const std::string degree = argc > 2 ? argv[2] : "auto";
  if (degree.starts_with("auto")) {
    if (degree.size() > 4 && std::sscanf(degree.c_str(), "auto:%d:%d", &options.degree_rule.low,
                                         &options.degree_rule.raise_to) != 2) {
      std::fprintf(stderr, "degree: auto, auto:LOW:RAISE or a number\n");
      return 2;
    }
  } else {
    options.degree = std::atoi(degree.c_str());
  }
  if (const char* t = std::getenv("HEMOTREE_THREADS")) options.threads = std::atoi(t);
  if (argc > 5) {
    const std::string scheme = argv[5];
    options.scheme = scheme == "ab2"   ? TimeScheme::adams_bashforth2
                     : scheme == "rk4" ? TimeScheme::runge_kutta4
                                       : TimeScheme::exponential_ab2;
  }
  const int steps = argc > 3 ? std::atoi(argv[3]) : 200;
  const int batches = argc > 4 ? std::atoi(argv[4]) : 5;
  PulseSolver solver(net, options);
  std::vector<double> rates;
  for (int b = 0; b < batches; ++b) {
    const auto t0 = std::chrono::steady_clock::now();
    for (int k = 0; k < steps; ++k) solver.step();
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    rates.push_back(steps / wall);
  }
  std::sort(rates.begin(), rates.end());
  const double rate = rates[rates.size() / 2];
  const double period = net.inlet->waveform.period;
  std::printf("vessels %zu, elements %zu, degree %s, threads %d, dt %.3g s (%s)\n",
              net.vessel_count(), solver.element_count(), degree.c_str(), options.threads, solver.dt(),
              in_words(solver.dt_reason()).c_str());
  std::printf("median %.1f steps/s over %d batches of %d steps (min %.1f, max %.1f)\n", rate,
              batches, steps, rates.front(), rates.back());
  std::printf("wall time per %.3g s cycle: %.3g s (%.3g h)\n", period, period / solver.dt() / rate,
              period / solver.dt() / rate / 3600);
  // hemosolve's cost model (solver/run_estimate), against the measured step.
  std::vector<double> elements_of_degree(static_cast<std::size_t>(solver.max_degree()) + 1, 0.0);
  for (std::size_t v = 0; v < net.vessel_count(); ++v)
    if (!solver.is_lumped(v)) elements_of_degree[static_cast<std::size_t>(solver.degree(v))] += options.elements;
  const double model = estimate_run(elements_of_degree, 1, options.threads, solver.substeps(),
                                    static_cast<double>(solver.lumped_count())).seconds;
  std::printf("cost model: %.3g us per step, measured %.3g us (model / measured %.2f)\n", model * 1e6,
              1e6 / rate, model * rate);
  return 0;
}
