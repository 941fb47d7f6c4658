// The compliance balance of PulseSolver (docs/solver.md §6): at each cycle end, the network's
// compliances (vessels and RCR capacitors) move to where their filling over the cycle says
// the periodic state lies.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "core/free_memory.hpp"
#include "physics/poiseuille.hpp"
#include "steady/loaded_tree.hpp"
#include "pulse/pulse_solver.hpp"

namespace hemotree {

std::vector<double> PulseSolver::capacitor_pressures() const {
  std::vector<double> p(outlet_count_, std::numeric_limits<double>::quiet_NaN());
  for (const auto& o : boundaries_.outlets)
    if (o.capacitor >= 0) p[static_cast<std::size_t>(o.index)] = state_.capacitor(o.capacitor);
  for (std::size_t k = 0; k < p.size(); ++k)
    if (std::isnan(p[k])) p[k] = lumped_.capacitor_pressure(k);
  if (lead_whole_) lead_whole_(p, holds_outlet_);  // over ranks: each outlet's from its rank, on the lead
  return p;
}

double PulseSolver::vessel_volume(std::size_t v) const {
  double volume = 0.0;
  if (zero_d_[v]) {  // half at each node's pressure, as the 0D scheme holds it
    const std::int32_t e = lumped_.vessel_index(v);
    const TubeLaw tube = law(v);
    volume = is_tapered(v)              ? lumped_.tapered_volume(e)
             : lumped_.sections(e) > 1 ? lumped_.sectioned_volume(e)
                                       : net_.length[v] * 0.5 * (tube.area(lumped_.pressure_at(e, 0)) + tube.area(lumped_.pressure_at(e, 1)));
  }
  for (auto el = first_element(v), end = end_element(v); el < end; ++el) volume += 2 * half_length_(el) * state_.area(el, 0);
  return volume;
}

double PulseSolver::area_per_pressure_at(std::size_t v, double volume) const {
  return law(v).compliance_per_length(volume / net_.length[v]);
}

std::vector<double> PulseSolver::vessel_volumes() const {
  if (!lead_places_) {
    std::vector<double> volume(net_.vessel_count());
    for (std::size_t v = 0; v < volume.size(); ++v) volume[v] = vessel_volume(v);
    return volume;
  }
  // Over ranks each rank's own vessels' to the lead, each at its place: nothing the network's
  // size on the other ranks.
  std::vector<double> own;
  std::vector<std::int32_t> place;
  for (std::size_t v = 0; v < net_.vessel_count(); ++v)
    if (steps_vessel(v)) {
      own.push_back(vessel_volume(v));
      place.push_back(static_cast<std::int32_t>(v));
    }
  return lead_places_(own, place, net_.vessel_count());
}

std::size_t PulseSolver::balance_compliances(double period, std::vector<double> mean_pressure) {
  if (!can_balance_) return 0;
  // What the cycle end freed before it (the step's arrays, the cycle's sums and records) lies
  // in the allocator's heap in pieces the balance's arrays and tree do not fit: handed back,
  // not left resident beside them (the million-vessel tree's peak 477 -> 428 MB, the full
  // tree's 1.70 -> 1.54 GB).
  return_free_memory();
  const std::size_t n = net_.vessel_count();
  // Every vessel's volume and dA/dp at its mean area, the lead's alone (over ranks the others
  // send their vessels' volumes); each rank moves its own vessels by the dA/dp it computes
  // alike (move_compliances).
  const std::vector<double> volume = vessel_volumes();
  std::vector<double> area_per_pressure;
  if (leads()) {
    area_per_pressure.resize(n);
    for (std::size_t v = 0; v < n; ++v) area_per_pressure[v] = area_per_pressure_at(v, volume[v]);
  }
  // A tapered vessel's dA/dp changes along it: each element's at its mean area and centre
  // (a 0D one's, the mean of its ends'), and the vessel's the mean of those, from its rank.
  std::vector<double> element_area_per_pressure;
  if (!tapers_.empty()) {
    element_area_per_pressure.assign(static_cast<std::size_t>(state_.area.rows()), 0.0);
    std::vector<double> own;
    std::vector<std::int32_t> place;
    for (std::size_t v = 0; v < n; ++v) {
      if (!is_tapered(v) || !steps_vessel(v)) continue;
      double sum = 0;
      if (zero_d_[v]) {
        const std::int32_t e = lumped_.vessel_index(v);
        for (const double x : {0.0, 1.0}) {
          const TubeLaw at = law_at(v, x);
          sum += at.compliance_per_length(at.area(lumped_.pressure_at(e, x))) / 2;  // the mean of the two ends'
        }
      } else {
        const auto first = first_element(v);
        for (auto el = first, end = end_element(v); el < end; ++el) {
          const double x = (el - first + 0.5) / elements_per_vessel_;
          const double c = law_at(v, x).compliance_per_length(state_.area(el, 0));
          element_area_per_pressure[static_cast<std::size_t>(el)] = c;
          sum += c / elements_per_vessel_;
        }
      }
      own.push_back(sum);
      place.push_back(static_cast<std::int32_t>(v));
    }
    if (lead_places_) {
      const std::vector<double> tapered = lead_places_(own, place, n);  // the tapered vessels' from their ranks
      if (leads())
        for (std::size_t v = 0; v < n; ++v)
          if (is_tapered(v)) area_per_pressure[v] = tapered[v];
    } else {
      for (std::size_t k = 0; k < own.size(); ++k) area_per_pressure[static_cast<std::size_t>(place[k])] = own[k];
    }
  }
  // Without RCR outlets no capacitor is balanced: their arrays stay empty (a tree's two
  // million capillary outlets would hold 15 MB of NaN or 0 in each).
  const std::vector<double> capacitor_now = rcr_outlets_ ? capacitor_pressures() : std::vector<double>();
  if (!cycle_marked_) {
    if (leads()) {
      cycle_volume_ = volume;
      cycle_capacitor_ = capacitor_now;
    }
    cycle_marked_ = true;
    return 0;
  }
  // The moves: the lead's solve of the whole network, sent to every other rank.
  TreePotentials move;
  if (leads()) move = compliance_moves(period, std::move(mean_pressure), volume, area_per_pressure, capacitor_now);
  if (from_lead_) {
    from_lead_(move.node);
    from_lead_(move.capacitor);
  }
  move_compliances(move, element_area_per_pressure);
  move = {};
  cycle_volume_ = vessel_volumes();  // the marks are the lead's (empty elsewhere)
  cycle_capacitor_ = rcr_outlets_ ? capacitor_pressures() : std::vector<double>();
  if (!leads()) std::vector<double>().swap(cycle_capacitor_);
  have_previous_rate_ = false;  // the multistep history belongs to the state before the move
  return n;
}

TreePotentials PulseSolver::compliance_moves(double period, std::vector<double> mean_pressure,
                                             const std::vector<double>& volume,
                                             const std::vector<double>& area_per_pressure,
                                             const std::vector<double>& capacitor_now) {
  const std::size_t n = net_.vessel_count();
  std::vector<double> resistance(steady_resistance_.begin(), steady_resistance_.end());
  // The conductances at the last cycle's mean state, where the run has one: in a full tree
  // every resistance is a compliant vessel's, and the pulsatile means sit well below the
  // steady pressures (9.8 mmHg at the root of the paper's tree).
  if (!mean_pressure.empty())
    for (std::size_t v = 0; v < n; ++v) {
      const double area = law(v).area(mean_pressure[v]);
      if (is_tapered(v)) {
        const double area_to = end_law(v, true).area(mean_pressure[v]);
        if (area > 0 && area_to > 0)
          resistance[v] = tapered_poiseuille_resistance(
              [&](double d) { return viscosity_(std::numbers::pi / 4 * d * d); }, net_.length[v],
              std::sqrt(4 / std::numbers::pi * area), std::sqrt(4 / std::numbers::pi * area_to), blood_.alpha);
        continue;
      }
      if (area > 0)
        resistance[v] = poiseuille_resistance(viscosity_(area), net_.length[v], std::sqrt(4 / std::numbers::pi * area), blood_.alpha);
    }
  std::vector<double>().swap(mean_pressure);
  // Volume rates over the last cycle: each vessel's half to each of its nodes.
  TreeLoads loads;
  loads.node_shunt.assign(net_.node_count(), 0.0);
  loads.node_current.assign(net_.node_count(), 0.0);
  loads.capacitor_shunt.assign(capacitor_now.size(), 0.0);
  loads.capacitor_current.assign(capacitor_now.size(), 0.0);
  std::vector<double> node_compliance(net_.node_count(), 0.0), capacitor_compliance(capacitor_now.size(), 0.0);
  for (std::size_t v = 0; v < n; ++v) {
    const double rate = (volume[v] - cycle_volume_[v]) / period, compliance = area_per_pressure[v] * net_.length[v];
    for (const auto node : {net_.from[v], net_.to[v]}) {
      loads.node_current[static_cast<std::size_t>(node)] += rate / 2;
      node_compliance[static_cast<std::size_t>(node)] += compliance / 2;
    }
  }
  std::vector<double>().swap(cycle_volume_);  // its rates taken; made again after the move
  for (std::size_t k = 0; k < capacitor_now.size(); ++k) {
    if (std::isnan(capacitor_now[k])) continue;
    capacitor_compliance[k] = outlet_capacitance_[k];
    loads.capacitor_current[k] = outlet_capacitance_[k] * (capacitor_now[k] - cycle_capacitor_[k]) / period;
  }
  // move = delta = K^-1 I: the shifts that cancel the rates in the linear network (K its conductance).
  LoadedTree tree(net_, boundaries_.list, resistance);
  std::vector<double>().swap(resistance);  // the tree holds the conductances
  TreePotentials move = tree.solve(loads);
  // The distance still to go after a cycle that moved by the drift dP is f(Z) dP with
  // f(z) = e^(-z) / (1 - e^(-z)) = g(z) / z, g(z) = z / (e^z - 1), Z = C^-1 K T, and
  // Z^-1 dP = delta. g is taken as 1 / ((1 + a z)(1 + b z)), two solves of (C + a K T) y =
  // C x with real a and b (a rational g with real poles only: the tree solver is real): a
  // mode of Z contracts per cycle by e^(-z) |1 - g_a(z) / g(z)|, whose largest over all z is
  // 2.9 % with a = 0.315, b = 0.354 (fitted to equal ripple at z = 0.44 and 3), where the
  // earlier 1 / (1 + z/2) left 8.2 % (at z = 2: the modes that decay in about a cycle).
  // (move starts as delta, and each solve replaces it.)
  for (const double a : {0.315, 0.354}) {
    for (std::size_t node = 0; node < node_compliance.size(); ++node) {
      loads.node_shunt[node] = node_compliance[node] / (a * period);
      loads.node_current[node] = loads.node_shunt[node] * move.node[node];
    }
    for (std::size_t k = 0; k < capacitor_compliance.size(); ++k) {
      loads.capacitor_shunt[k] = capacitor_compliance[k] / (a * period);
      loads.capacitor_current[k] = loads.capacitor_shunt[k] * move.capacitor[k];
    }
    move = {};  // in the loads now: freed before the solve makes the next
    move = tree.solve(loads);
  }
  // The linearisation holds for small moves: none may change a lumen by more than 20 %
  // (far from the periodic state, e.g. after a start at rest, the moves shrink to that).
  double largest = 0;
  for (std::size_t v = 0; v < n; ++v)
    for (const auto node : {net_.from[v], net_.to[v]})
      largest = std::max(largest, std::abs(area_per_pressure[v] * move.node[static_cast<std::size_t>(node)]) /
                                      (volume[v] / net_.length[v]));
  const double scale = largest > 0.2 ? 0.2 / largest : 1.0;
  for (auto& y : move.node) y *= scale;
  for (auto& y : move.capacitor) y *= scale;
  return move;
}

void PulseSolver::move_compliances(const TreePotentials& move, const std::vector<double>& element_area_per_pressure) {
  // Every vessel's pressure shifts linearly between its nodes' moves, its area by dA/dp at its
  // mean area (the value the lead's solve took).
  const int e = elements_per_vessel_;
  for (std::size_t v = 0; v < net_.vessel_count(); ++v) {
    if (zero_d_[v] || !steps_vessel(v)) continue;
    const double y0 = move.node[static_cast<std::size_t>(net_.from[v])], y1 = move.node[static_cast<std::size_t>(net_.to[v])];
    const double area_per_pressure = is_tapered(v) ? 0.0 : area_per_pressure_at(v, vessel_volume(v));
    for (int k = 0; k < e; ++k) {
      const auto el = first_element(v) + k;
      const double c = is_tapered(v) ? element_area_per_pressure[static_cast<std::size_t>(el)] : area_per_pressure;
      state_.area(el, 0) += c * (y0 + (y1 - y0) * (k + 0.5) / e);
      if (state_.area.cols() > 1 && vessel_degree_[v] >= 1) state_.area(el, 1) += c * (y1 - y0) / (2 * e);
    }
  }
  for (const auto& o : boundaries_.outlets)
    if (o.capacitor >= 0) state_.capacitor(o.capacitor) += move.capacitor[static_cast<std::size_t>(o.index)];
  lumped_.shift_pressures(move.node, move.capacitor);
}

}  // namespace hemotree
