// PulseSolver with its 1D vessels spread over ranks (docs/scaling.md, "1D vessels across a
// cut"; pulse/one_d_cut.hpp): a rank's share, the traces exchanged at every evaluation, the
// 1D-0D couplings across the cut, and the 1D state made whole on the lead rank for a
// checkpoint. Each rank steps its own vessels' elements (runs_), solves the junctions where
// it has an end, and holds the 0D vessels meeting at its nodes as a 0D system of its own; a
// 1D end at another rank's 0D node takes that node's pressures from it each step.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

#include "pulse/pulse_solver.hpp"
#include "pulse/stability_limit.hpp"
#include "pulse/step_cost.hpp"

namespace hemotree {

std::vector<double> PulseSolver::vessel_step_costs(const SolverOptions& options) const {
  // The 1D substeps a 0D step takes, from the reference lumens' wave speeds (the run's own
  // come from its start, which needs the share): a 0D step of a thousandth of the period.
  const std::size_t n = net_.vessel_count();
  double substep = std::numeric_limits<double>::infinity();
  for (std::size_t v = 0; v < n; ++v) {
    if (zero_d_[v]) continue;
    const TubeLaw& law = laws_[v];
    const double h = net_.length[v] / elements_per_vessel_;
    substep = std::min(substep, options.cfl * courant_limit(vessel_degree_[v], TimeScheme::adams_bashforth2) * h /
                                    law.wave_speed(law.reference_area));
  }
  const double substeps = lumped_vessels_in_run() > 0 && std::isfinite(substep)
                              ? std::max(1.0, std::floor(step_cost::step_per_coupling_pass * period_ / substep))
                              : 1.0;
  std::vector<double> cost(n);
  for (std::size_t v = 0; v < n; ++v)
    cost[v] = zero_d_[v] ? step_cost::per_lumped_vessel
                         : substeps * elements_per_vessel_ * step_cost::element_step_seconds(vessel_degree_[v]);
  return cost;
}

void PulseSolver::take_spread_share(const PulseRanks& ranks, const VesselRanks& dealt) {
  const std::size_t n = net_.vessel_count();
  const std::vector<std::int32_t>& vessel_rank = dealt.rank;
  rank_ = ranks.rank;
  rank_count_ = ranks.ranks;
  std::vector<std::int32_t> node_rank(net_.node_count(), -1);
  std::optional<LumpedHalo> halo;
  if (dealt.zero_d_spread) {
    // The 0D vessels spread too: each node its first vessel's rank's, this rank's vessels and
    // a halo of the others' at its nodes (pulse/lumped_halo.hpp).
    halo = lumped_halo(net_, subtree_lumped_order(net_, zero_d_), vessel_rank, ranks.ranks, rank_);
    std::copy_n(halo->key_rank.begin(), net_.node_count(), node_rank.begin());  // the network nodes' keys
  } else {
    // The 0D vessels meeting at a node on one rank: each rank's 0D system is then whole.
    for (std::size_t v = 0; v < n; ++v)
      if (zero_d_[v])
        for (const std::int32_t node : {net_.from[v], net_.to[v]}) {
          std::int32_t& r = node_rank[static_cast<std::size_t>(node)];
          if (r >= 0 && r != vessel_rank[v])
            throw std::invalid_argument("PulseSolver: 0D vessel " + std::to_string(net_.id[v]) + " on rank " +
                                        std::to_string(vessel_rank[v]) + ", another 0D vessel at its node on rank " + std::to_string(r));
          r = vessel_rank[v];
        }
  }
  std::vector<bool> own_zero_d(n, false);
  steps_vessel_.assign(n, 0);
  for (std::size_t v = 0; v < n; ++v) {
    steps_vessel_[v] = vessel_rank[v] == rank_;
    own_zero_d[v] = zero_d_[v] && steps_vessel_[v];
  }
  if (halo) {
    lumped_ = LumpedVessels(net_, laws_, viscosity_, blood_, zero_d_, taper_of_, tapers_, lumped_sections_, nullptr, &*halo);
    lumped_.set_halo_link(ranks.halo_link(lumped_.halo_system()));
  } else {
    lumped_ = LumpedVessels(net_, laws_, viscosity_, blood_, own_zero_d, taper_of_, tapers_, lumped_sections_);
  }
  const RunBoundaries run(net_);
  for (std::size_t i = 0; i < run.size(); ++i)
    if (run.is_outlet(i)) holds_outlet_.push_back(steps_vessel_[static_cast<std::size_t>(run.outlet(i).vessel)]);
  one_d_cut_ = one_d_cut(boundaries_, blocks_, element_vessel_, vessel_rank, rank_);
  vessel_rank_ = vessel_rank;
  lumped_node_rank_ = node_rank;
  runs_ = one_d_cut_->runs;
  trace_out_.assign(one_d_cut_->neighbours.size(), {});
  trace_in_.assign(one_d_cut_->neighbours.size(), {});
  for (std::size_t i = 0; i < one_d_cut_->neighbours.size(); ++i) {
    trace_out_[i].resize(2 * one_d_cut_->neighbours[i].send.size());
    trace_in_[i].resize(2 * one_d_cut_->neighbours[i].receive.size());
  }
  trace_ranks_ = one_d_cut_->ranks();
  coupling_cut_ = coupling_cut(boundaries_, vessel_rank, node_rank, rank_);
  coupling_ranks_ = coupling_cut_->ranks();
  coupling_out_.assign(coupling_ranks_.size(), {});
  coupling_in_.assign(coupling_ranks_.size(), {});
  remote_node_.assign(boundaries_.coupled.size(), {0.0, 0.0, 0.0, 0.0});
  end_volume_.assign(boundaries_.coupled.size(), 0.0);
  exchange_ = ranks.exchange;
  least_key_ = ranks.least_key;
  make_whole_ = ranks.make_whole;
  lead_whole_ = ranks.lead_whole;
  lead_places_ = ranks.lead_places;
  std::vector<std::int32_t> vessels, first;
  for (std::size_t j = 0; j < one_d_vessels_.size(); ++j)
    if (steps_vessel_[static_cast<std::size_t>(one_d_vessels_[j])]) {
      vessels.push_back(one_d_vessels_[j]);
      first.push_back(one_d_first_element_[j]);
    }
  one_d_vessels_ = std::move(vessels);
  one_d_first_element_ = std::move(first);
  one_d_here_ = true;  // every rank takes the substeps, for its own vessels
}

void PulseSolver::exchange_traces() {
  const OneDCut& cut = *one_d_cut_;
  for (std::size_t i = 0; i < cut.neighbours.size(); ++i) {
    const auto& send = cut.neighbours[i].send;
    for (std::size_t k = 0; k < send.size(); ++k) trace(send[k], trace_out_[i][2 * k], trace_out_[i][2 * k + 1]);
  }
  exchange_(trace_ranks_, trace_out_, trace_in_);
  for (std::size_t i = 0; i < cut.neighbours.size(); ++i) {
    const auto& receive = cut.neighbours[i].receive;
    for (std::size_t k = 0; k < receive.size(); ++k) {
      const VesselEnd& e = receive[k];
      (e.distal ? area_right_ : area_left_)(e.element) = trace_in_[i][2 * k];
      (e.distal ? flow_right_ : flow_left_)(e.element) = trace_in_[i][2 * k + 1];
    }
  }
}

void PulseSolver::send_to_nodes(std::vector<double>& per_end) {
  const CouplingCut& cut = *coupling_cut_;
  for (std::size_t i = 0; i < cut.neighbours.size(); ++i) {
    coupling_out_[i].clear();
    for (const std::int32_t k : cut.neighbours[i].ends) coupling_out_[i].push_back(per_end[static_cast<std::size_t>(k)]);
    coupling_in_[i].resize(cut.neighbours[i].nodes.size());
  }
  exchange_(coupling_ranks_, coupling_out_, coupling_in_);
  for (std::size_t i = 0; i < cut.neighbours.size(); ++i)
    for (std::size_t j = 0; j < cut.neighbours[i].nodes.size(); ++j)
      per_end[static_cast<std::size_t>(cut.neighbours[i].nodes[j])] = coupling_in_[i][j];
}

void PulseSolver::share_coupling_nodes() {
  const CouplingCut& cut = *coupling_cut_;
  for (std::size_t i = 0; i < cut.neighbours.size(); ++i) {
    coupling_out_[i].clear();
    for (const std::int32_t k : cut.neighbours[i].nodes) {
      const auto slot = static_cast<std::size_t>(coupled_slot_[static_cast<std::size_t>(k)]);
      coupling_out_[i].insert(coupling_out_[i].end(), {lumped_.start_pressure(slot), lumped_.predicted_pressure(slot),
                                                       lumped_.impedance(slot), lumped_.dynamic_pressure(slot)});
    }
    coupling_in_[i].resize(4 * cut.neighbours[i].ends.size());
  }
  exchange_(coupling_ranks_, coupling_out_, coupling_in_);
  for (std::size_t i = 0; i < cut.neighbours.size(); ++i)
    for (std::size_t j = 0; j < cut.neighbours[i].ends.size(); ++j)
      std::copy_n(coupling_in_[i].begin() + static_cast<std::ptrdiff_t>(4 * j), 4,
                  remote_node_[static_cast<std::size_t>(cut.neighbours[i].ends[j])].begin());
}

PulseSolver::WholeOneD PulseSolver::whole_one_d_state() const {
  // Each number from the rank that steps its vessel, at its place in the one-process arrays:
  // matrices entry by entry (column-major), per element row.
  auto element_mine = [&](Eigen::Index rows, Eigen::Index cols) {
    std::vector<unsigned char> mine(static_cast<std::size_t>(rows * cols), 0);
    for (const ElementRun& r : runs_)
      for (Eigen::Index c = 0; c < cols; ++c)
        std::fill_n(mine.begin() + c * rows + r.first, r.count, 1);
    return mine;
  };
  auto whole_matrix = [&](const Eigen::MatrixXd& m) {
    std::vector<double> values(m.data(), m.data() + m.size());
    if (!values.empty()) lead_whole_(values, element_mine(m.rows(), m.cols()));
    return Eigen::MatrixXd(Eigen::Map<const Eigen::MatrixXd>(values.data(), m.rows(), m.cols()));
  };
  auto whole_vector = [&](const Eigen::VectorXd& x, const std::vector<unsigned char>& mine) {
    std::vector<double> values(x.data(), x.data() + x.size());
    if (!values.empty()) lead_whole_(values, mine);
    return Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(values.data(), x.size()));
  };
  // Per capacitor, coupled end and 1D boundary: its vessel's rank's.
  std::vector<unsigned char> capacitor(static_cast<std::size_t>(state_.capacitor.size()), 0),
      coupled(boundaries_.coupled.size(), 0), boundary(static_cast<std::size_t>(state_.boundary.size()), 0);
  for (const auto& o : boundaries_.outlets) {
    if (o.capacitor >= 0) capacitor[static_cast<std::size_t>(o.capacitor)] = steps_end(o.end);
    boundary[static_cast<std::size_t>(o.slot)] = steps_end(o.end);
  }
  for (const auto* given : {&boundaries_.flows, &boundaries_.pressures})
    for (const auto& g : *given) boundary[static_cast<std::size_t>(g.slot)] = steps_end(g.end);
  for (std::size_t k = 0; k < coupled.size(); ++k) coupled[k] = steps_end(boundaries_.coupled[k].end);
  auto whole_state = [&](const PulseState& s) {
    PulseState w;
    w.area = whole_matrix(s.area);
    w.flow = whole_matrix(s.flow);
    w.capacitor = s.capacitor.size() == state_.capacitor.size() ? whole_vector(s.capacitor, capacitor) : s.capacitor;
    w.coupled = s.coupled.size() == state_.coupled.size() ? whole_vector(s.coupled, coupled) : s.coupled;
    w.boundary = s.boundary.size() == state_.boundary.size() ? whole_vector(s.boundary, boundary) : s.boundary;
    w.faces = s.faces;
    if (s.faces.size() == state_.area.rows()) w.faces = whole_matrix(s.faces);
    return w;
  };
  WholeOneD whole;
  whole.state = whole_state(state_);
  whole.previous_rate = whole_state(previous_rate_);
  whole.previous_flow = whole_matrix(previous_flow_);
  // The ends' last states (the junctions' Newton guesses), per 1D vessel in vessel order.
  std::vector<unsigned char> mine;
  for (const auto& [v, first] : first_elements_) {
    for (const bool distal : {false, true}) {
      const EndState& e = boundaries_.state_at(vessel_end(static_cast<std::size_t>(v), distal));
      whole.ends.insert(whole.ends.end(), {e.area, e.flow});
    }
    mine.insert(mine.end(), 4, steps_vessel_[static_cast<std::size_t>(v)]);
  }
  if (!whole.ends.empty()) lead_whole_(whole.ends, mine);
  return whole;
}

}  // namespace hemotree
