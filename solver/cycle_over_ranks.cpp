#include "solver/cycle_over_ranks.hpp"

#include <algorithm>
#include <limits>
#include <utility>
#include <vector>

#include <mpi.h>

#include "distributed/gather_rows.hpp"
#include "mpi/session.hpp"
#include "pulse/lumped_order.hpp"

namespace hemotree {

double network_volume_over_ranks(const Network& net, const PulseSolver& solver) {
  const LumpedVessels& lumped = solver.lumped();
  std::vector<std::int32_t> mine;
  std::vector<double> volume;
  for (std::size_t n = 0; n < net.node_count(); ++n) {
    const std::int32_t k = lumped.node_of(static_cast<std::int64_t>(n));
    if (k < 0 || lumped.ghost_node(k)) continue;
    mine.push_back(static_cast<std::int32_t>(n));
    volume.push_back(lumped.stored_volume(k));
  }
  std::vector<double> at_node(world_rank() == 0 ? net.node_count() : 0, 0.0);
  gather_rows(mine, volume, 1, net.node_count(), [&](std::int32_t node, const double* v) { at_node[static_cast<std::size_t>(node)] = *v; });
  // The 1D elements' volumes, a vessel's a row, from the rank that steps it.
  const auto e = static_cast<std::size_t>(solver.elements_per_vessel());
  std::vector<std::int32_t> one_d_mine;
  std::vector<double> one_d_rows;
  for (const std::int32_t v : solver.one_d_vessels()) {
    one_d_mine.push_back(v);
    const std::vector<double> terms = solver.one_d_volumes(static_cast<std::size_t>(v));
    one_d_rows.insert(one_d_rows.end(), terms.begin(), terms.end());
  }
  std::vector<double> one_d(world_rank() == 0 ? net.vessel_count() * e : 0, 0.0);
  gather_rows(one_d_mine, one_d_rows, e, net.vessel_count(),
              [&](std::int32_t v, const double* row) { std::copy_n(row, e, one_d.begin() + static_cast<std::ptrdiff_t>(static_cast<std::size_t>(v) * e)); });
  if (world_rank() != 0) return std::numeric_limits<double>::quiet_NaN();
  // The one-process sum: the 0D vessels' nodes by first appearance in the network's order of
  // the 0D vessels (LumpedVessels::stored_volume), then the 1D elements.
  std::vector<std::int32_t> zero_d;
  for (std::size_t v = 0; v < net.vessel_count(); ++v)
    if (solver.is_lumped(v)) zero_d.push_back(static_cast<std::int32_t>(v));
  double total = 0;
  for (const std::int32_t node : nodes_by_first_appearance(zero_d, net.from, net.to, net.node_count()))
    total += at_node[static_cast<std::size_t>(node)];
  for (std::size_t v = 0; v < net.vessel_count(); ++v)
    if (!solver.is_lumped(v))
      for (std::size_t k = 0; k < e; ++k) total += one_d[v * e + k];
  return total;
}

Eigen::VectorXd boundary_volumes_over_ranks(const PulseSolver& solver) {
  const std::vector<std::int32_t> mine = solver.held_boundaries();
  const Eigen::VectorXd here = solver.boundary_volumes();
  std::vector<double> rows;
  for (const std::int32_t b : mine) rows.push_back(here(b));
  const std::size_t count = solver.boundary_list().size();
  Eigen::VectorXd all = Eigen::VectorXd::Zero(world_rank() == 0 ? static_cast<Eigen::Index>(count) : 0);
  gather_rows(mine, rows, 1, count, [&](std::int32_t b, const double* v) { all(b) = *v; });
  return all;
}

void gather_vessel_values(const Network& net, const PulseSolver& solver, std::span<std::vector<double>* const> values) {
  const std::size_t width = values.size();
  std::vector<std::int32_t> mine;
  std::vector<double> rows;
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    if (!solver.steps_vessel(v)) continue;
    mine.push_back(static_cast<std::int32_t>(v));
    for (const std::vector<double>* column : values) rows.push_back((*column)[v]);
  }
  gather_rows(mine, rows, width, net.vessel_count(), [&](std::int32_t v, const double* row) {
    for (std::size_t j = 0; j < width; ++j) (*values[j])[static_cast<std::size_t>(v)] = row[j];
  });
}

void gather_cycle_rows(const Network& net, const PulseSolver& solver, const CycleSummary& own,
                       std::span<const std::int32_t> entry_vessel,
                       const std::function<void(std::size_t first, std::span<const double> rows)>& block_rows,
                       std::size_t block_vessels) {
  constexpr std::size_t width = cycle_row_width;
  // A block of the vessels at a time, so that a rank's rows are a block's (at most 5 MB), not its
  // whole share's: 80 B an own vessel would be more than its sums themselves, a share's largest
  // moment; and rank 0 holds a block's rows, not the whole cycle's (64 B a vessel).
  const std::size_t n = net.vessel_count();
  const std::size_t block = std::clamp<std::size_t>(n, 1, std::max<std::size_t>(block_vessels, 1));
  const bool lead = world_rank() == 0;
  std::vector<std::int32_t> mine;
  std::vector<double> rows, placed(lead ? block * width : 0);
  // By entry: this rank's own vessels' entries in the vessels' order, for the blocks.
  std::vector<std::pair<std::int32_t, std::int32_t>> own_entries;  // (vessel, entry)
  for (std::size_t k = 0; k < entry_vessel.size(); ++k)
    if (solver.steps_vessel(static_cast<std::size_t>(entry_vessel[k])))
      own_entries.emplace_back(entry_vessel[k], static_cast<std::int32_t>(k));
  std::ranges::sort(own_entries);
  auto next_own = own_entries.begin();
  auto add_row = [&](std::size_t v, const VesselCycle& c) {
    mine.push_back(static_cast<std::int32_t>(v));
    const auto row = cycle_row(c, own.wave_speeds(v));
    rows.insert(rows.end(), row.begin(), row.end());
  };
  mine.reserve(block);
  rows.reserve(block * width);
  for (std::size_t first = 0; first < n; first += block) {
    mine.clear();
    rows.clear();
    const std::size_t last = std::min(n, first + block);
    if (entry_vessel.empty()) {
      for (std::size_t v = first; v < last; ++v)
        if (solver.steps_vessel(v)) add_row(v, own.vessels[v]);
    } else {
      for (; next_own != own_entries.end() && static_cast<std::size_t>(next_own->first) < last; ++next_own)
        add_row(static_cast<std::size_t>(next_own->first), own.vessels[static_cast<std::size_t>(next_own->second)]);
    }
    // Each vessel is stepped by one rank: every row of the block is placed once.
    gather_rows(mine, rows, width, n, [&](std::int32_t vessel, const double* f) {
      std::copy_n(f, width, placed.begin() + static_cast<std::ptrdiff_t>((static_cast<std::size_t>(vessel) - first) * width));
    });
    if (lead) block_rows(first, std::span<const double>(placed.data(), (last - first) * width));
  }
}

void gather_cycle_vessels(const Network& net, const PulseSolver& solver, CycleSummary& summary,
                          std::span<const std::int32_t> entry_vessel) {
  std::vector<VesselCycle> whole;
  std::vector<std::pair<std::size_t, WaveSpeeds>> waves;
  if (world_rank() == 0) whole.resize(net.vessel_count());
  gather_cycle_rows(net, solver, summary, entry_vessel, [&](std::size_t first, std::span<const double> rows) {
    for (std::size_t k = 0; k * cycle_row_width < rows.size(); ++k) {
      const double* f = rows.data() + k * cycle_row_width;
      const std::size_t v = first + k;
      whole[v] = row_cycle(f);
      if (!solver.is_lumped(v)) waves.emplace_back(v, row_wave_speeds(f));
    }
  });
  if (world_rank() != 0) return;
  summary.vessels = std::move(whole);
  summary.waves = std::move(waves);  // in the vessels' order, as they came
}

std::vector<double> gather_mean_pressures(const Network& net, const PulseSolver& solver, const CycleSummary& own,
                                          std::span<const std::int32_t> entry_vessel) {
  std::vector<double> p(world_rank() == 0 ? net.vessel_count() : 0);
  gather_cycle_rows(net, solver, own, entry_vessel, [&](std::size_t first, std::span<const double> rows) {
    for (std::size_t k = 0; k * cycle_row_width < rows.size(); ++k)
      p[first + k] = row_cycle(rows.data() + k * cycle_row_width).mean_pressure;
  });
  return p;
}

}  // namespace hemotree
