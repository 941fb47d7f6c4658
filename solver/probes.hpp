// Time series of p, Q, A and u at chosen points of chosen vessels (`hemosolve --probe`),
// held in memory and written as probes.csv at the end of a run (or at a breakdown).
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "formats/network.hpp"
#include "pulse/pulse_solver.hpp"

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
  // One row at time t of values given per probe (a run without a solver: hemosolve --linear).
  struct Values {
    double pressure, flow, area;
  };
  void add_row(double t, const std::function<Values(const Probe&)>& at);
  // The same with the further columns' values given too (column(j, probe), add_columns').
  void add_row(double t, const std::function<Values(const Probe&)>& at,
               const std::function<double(std::size_t, const Probe&)>& column);
  // Further columns at every probe (the transported red cells and tracers): their headers'
  // names and units, and the value of column j at a probe now.
  void add_columns(std::vector<std::string> headers, std::function<double(std::size_t, const Probe&)> value) {
    headers_ = std::move(headers);
    column_ = std::move(value);
  }
  const std::vector<std::string>& column_headers() const { return headers_; }
  // probes.csv: a header with units, then one row per sample; nothing without probes.
  void write(const std::filesystem::path& file) const;
  bool empty() const { return probes_.empty(); }
  // probes.csv's columns, their names unquoted ("t [s]", "p vessel 3 x 0.5 [Pa]", ...), and
  // its values row by row (the numbers probes.csv holds): results.h5's /probes.
  std::vector<std::string> column_names() const;
  std::vector<double> values() const;
  // The rows recorded so far, as text (a checkpoint keeps them).
  std::string rows() const { return rows_.str(); }
  void restore_rows(const std::string& rows) { rows_.str(rows); rows_.seekp(0, std::ios::end); }

 private:
  std::vector<Probe> probes_;
  std::ostringstream rows_;
  std::vector<std::string> headers_;
  std::function<double(std::size_t, const Probe&)> column_;
};

}  // namespace hemotree
