// What a checkpoint must share with the run that resumes it: the network, all of it, and the
// options that shape the state the run evolves. A resumed run continues bit for bit only
// from a state of the same discretised problem; anything else is refused with one line.
//
//   network identity   64-bit FNV-1a over a canonical serialisation of every member of
//                      Network: each array with its name and length, the blood and the
//                      boundary conditions in their file form (full precision)
//   state shaping      a canonical text of every configuration value that shapes the state
//                      (model, degrees, elements, scheme, step, wall, start, balance, probes,
//                      red cells, tracers), readable, so that a refusal can say what differs
//
// Neither can forget a field: both are written over a structured binding of the whole
// struct (Network, SolverOptions, DegreeRule, RunConfiguration, Probe, TracerSpec), which
// stops compiling when a member is added until the new member is either serialised or
// declared not to shape the state, with the reason.
#pragma once

#include <cstdint>
#include <string>

#include "formats/network.hpp"
#include "solver/run_configuration.hpp"

namespace hemotree {

std::uint64_t network_identity(const Network& net);

// dt: the step the run takes (decide_time_step's); rheology: the one it uses (the file's, or
// the configuration's override).
std::string state_shaping(const RunConfiguration& config, const Network& net, double dt, Rheology rheology);

struct RunIdentity {
  std::uint64_t network = 0;
  std::string shaping;
  // Both as one number (64-bit FNV-1a): equal identities, equal values.
  std::uint64_t value() const;
};

RunIdentity run_identity(const Network& net, const RunConfiguration& config, double dt, Rheology rheology);

}  // namespace hemotree
