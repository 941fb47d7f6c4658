// The linear periodic state as a run's result (hemosolve --linear): the network linearised
// about its loaded steady state, harmonic by harmonic (harmonic/linear_periodic.hpp), written
// as every run writes its results: summary.json, vessels.csv (per vessel the mean, systolic
// and diastolic pressure at its middle, the mean, peak and least flow, the pulsatility index,
// the mean wall shear stress, the wave speeds measured from the phase lag along it), probes.csv
// (one period at the probes) and results.vtp. For screening: no time stepping, seconds on a
// full tree. What it leaves out, and its error against the time-stepped periodic state, in
// docs/solver.md (§6a).
#pragma once

#include "formats/network.hpp"
#include "solver/run_configuration.hpp"
#include "solver/run_observer.hpp"

namespace hemotree {

// InputError where the network has no steady state (a reflection outlet) or no path to
// ground; nothing is written then.
void run_linear(const Network& net, const RunConfiguration& config, RunObserver& observer);

}  // namespace hemotree
