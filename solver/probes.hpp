// Time series of p, Q, A and u at chosen points of chosen vessels (`hemosolve --probe`),
// held in memory and written as probes.csv at the end of a run (or at a breakdown).
#pragma once

#include <cstdint>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "formats/network.hpp"
#include "solver/pulse_solver.hpp"

namespace hemotree {

struct Probe {
  std::size_t vessel;  // index
  std::int64_t id;
  double x;            // fraction along the vessel, in [0, 1]
};

// "ID" or "ID:x" (x 0.5 by default); InputError naming the flag otherwise.
Probe parse_probe(const std::string& text, const Network& net);

class ProbeRecorder {
 public:
  explicit ProbeRecorder(std::vector<Probe> probes) : probes_(std::move(probes)) {}
  void sample(const PulseSolver& solver);  // one row at the solver's time
  // probes.csv: a header with units, then one row per sample; nothing without probes.
  void write(const std::filesystem::path& file) const;
  // The rows recorded so far, as text (a checkpoint keeps them).
  std::string rows() const { return rows_.str(); }
  void restore_rows(const std::string& rows) { rows_.str(rows); rows_.seekp(0, std::ios::end); }

 private:
  std::vector<Probe> probes_;
  std::ostringstream rows_;
};

}  // namespace hemotree
