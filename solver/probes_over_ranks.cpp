#include "solver/probes_over_ranks.hpp"

#include <algorithm>

#include "distributed/gather_rows.hpp"
#include "mpi/session.hpp"

namespace hemotree {

ProbesOverRanks::ProbesOverRanks(const std::vector<Probe>& probes, const PulseSolver& solver) : probes_(probes) {
  for (std::size_t j = 0; j < probes_.size(); ++j)
    if (solver.steps_vessel(probes_[j].vessel)) mine_.push_back(static_cast<std::int32_t>(j));
}

void ProbesOverRanks::sample(const PulseSolver& solver) {
  times_.push_back(solver.time());
  for (const std::int32_t j : mine_) {
    const Probe& p = probes_[static_cast<std::size_t>(j)];
    const double a = solver.area_at(p.vessel, p.x);  // as ProbeRecorder::sample takes them
    values_.insert(values_.end(), {solver.law_at(p.vessel, p.x).pressure(a), solver.flow_at(p.vessel, p.x), a});
    for (std::size_t c = 0; c < columns_; ++c) values_.push_back(column_(c, p));
  }
}

void ProbesOverRanks::gather_into(ProbeRecorder& recorder) const {
  // Each probe's series (p, Q, A and the columns at every sample) a row of that many numbers.
  const std::size_t each = 3 + columns_, samples = times_.size(), width = each * samples;
  std::vector<double> rows;
  rows.reserve(mine_.size() * width);
  for (std::size_t m = 0; m < mine_.size(); ++m)
    for (std::size_t k = 0; k < samples; ++k)
      rows.insert(rows.end(), values_.begin() + static_cast<std::ptrdiff_t>(each * (k * mine_.size() + m)),
                  values_.begin() + static_cast<std::ptrdiff_t>(each * (k * mine_.size() + m + 1)));
  std::vector<double> series(world_rank() == 0 ? probes_.size() * width : 0);
  gather_rows(mine_, rows, width, probes_.size(), [&](std::int32_t j, const double* row) {
    std::copy(row, row + width, series.begin() + static_cast<std::ptrdiff_t>(static_cast<std::size_t>(j) * width));
  });
  if (world_rank() != 0) return;
  for (std::size_t k = 0; k < samples; ++k) {
    std::size_t j = 0;  // the recorder asks for its probes in their order: the run's
    const double* v = nullptr;
    recorder.add_row(
        times_[k],
        [&](const Probe&) {
          v = series.data() + (j++) * width + each * k;
          return ProbeRecorder::Values{v[0], v[1], v[2]};
        },
        [&](std::size_t c, const Probe&) { return v[3 + c]; });
  }
}

}  // namespace hemotree
