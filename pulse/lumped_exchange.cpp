// The 0D vessels of a run over ranks (pulse/lumped_cut.hpp): what a rank holds of the cut, and
// the messages of every step, as LumpedVessels' predict() and complete() send them: the roots
// up, the potentials at their ends down, u's pressures down.
#include <algorithm>
#include <stdexcept>
#include <string>

#include "pulse/lumped_vessels.hpp"

namespace hemotree {

void LumpedVessels::hold_cut(const LumpedCut& cut) {
  share_.on = true;
  share_.top = cut.top();
  if (!cut.ghost_nodes.empty()) share_.ghost_node.assign(network_nodes_, 0);
  for (const std::int32_t node : cut.ghost_nodes) share_.ghost_node[static_cast<std::size_t>(node_of_[static_cast<std::size_t>(node)])] = 1;
  if (share_.top && !cut.root_vessels.empty()) share_.ghost_edge.assign(a_.size(), 0);
  for (const std::int32_t v : cut.root_vessels) {
    const std::int32_t index = index_of_vessel_[static_cast<std::size_t>(v)];
    if (index < 0 || sections(index) != 1)
      throw std::invalid_argument("LumpedVessels: root vessel " + std::to_string(v) + " is not one of this rank's 0D vessels of one section");
    const auto e = first_edge(static_cast<std::size_t>(index));
    share_.root_edge.push_back(static_cast<std::int32_t>(e));
    if (share_.top) share_.ghost_edge[e] = 1;
  }
  share_.root_row.assign(share_.root_edge.size() * (share_.top ? LumpedLink::up_per_root : 1), 0.0);
  // The top's nodes above the roots: their rows wait for the messages.
  if (share_.top) {
    for (const std::int32_t edge : share_.root_edge) {
      const auto e = static_cast<std::size_t>(edge);
      const std::size_t u = root_upper(e);
      if (share_.ghost_node[u] == 0) share_.waiting_node.push_back(static_cast<std::int32_t>(u));
      share_.ghost_node[u] = 2;
    }
    std::sort(share_.waiting_node.begin(), share_.waiting_node.end());
  }
}

void LumpedVessels::abandon_step(std::exception_ptr failure) {
  // The top's rank takes the shares' messages in first (they are waiting to send them).
  if (share_.top && share_.awaiting_roots) {
    share_.awaiting_roots = false;
    bool failed = false;
    share_.link.up({}, failure, failed);
  }
  // In the step's next message down (a refusal ends the step on every rank: none follows); a
  // failure after both went down is this rank's alone.
  if (!share_.potentials_down) {
    share_.potentials_down = share_.pressures_down = true;
    share_.link.down({}, failure, LumpedLink::potentials_per_root);
  } else if (!share_.pressures_down) {
    share_.pressures_down = true;
    share_.link.down({}, failure, LumpedLink::pressures_per_root);
  }
  std::rethrow_exception(failure);  // a link that did not throw it: this rank's own
}

void LumpedVessels::send_roots(std::exception_ptr failure) {
  // Per root vessel (u, r): its line, and what r's subtree leaves at r.
  std::vector<double> message;
  if (!failure) try {
      message.reserve(LumpedLink::up_per_root * share_.root_edge.size());
      for (const std::int32_t edge : share_.root_edge) {
        const auto e = static_cast<std::size_t>(edge);
        const std::size_t r = root_lower(e);
        message.insert(message.end(), {conductance_[e], system_.open_root_conductance(r), rhs_[r], history_[e]});
      }
    } catch (...) {
      failure = std::current_exception();
    }
  bool failed = false;
  share_.link.up(message, failure, failed);
  if (failure) abandon_step(failure);
}

void LumpedVessels::take_roots() {
  share_.awaiting_roots = false;
  bool failed = false;
  const std::vector<double> message = share_.link.up({}, nullptr, failed);
  if (failed) abandon_step(std::make_exception_ptr(std::runtime_error("a rank's 0D step failed")));
  if (message.size() != share_.root_row.size())
    abandon_step(std::make_exception_ptr(std::logic_error(
        "LumpedVessels: " + std::to_string(message.size()) + " numbers from the shares, " +
        std::to_string(share_.root_row.size()) + " expected")));
  share_.root_row = message;
}

std::vector<double> LumpedVessels::exchange_down(std::span<const double> answers, std::size_t per_root, bool& sent) {
  sent = true;
  std::vector<double> mine;
  try {
    mine = share_.link.down(answers, nullptr, per_root);
  } catch (...) {
    share_.potentials_down = share_.pressures_down = true;  // a refusal: the step ends on every rank
    throw;
  }
  if (!share_.top && mine.size() != per_root * share_.root_edge.size())
    throw std::logic_error("LumpedVessels: " + std::to_string(mine.size()) + " numbers from the top, " +
                           std::to_string(per_root * share_.root_edge.size()) + " expected");
  return mine;
}

void LumpedVessels::answer_potentials() {
  // Per root vessel (u, r): the potentials at its ends.
  std::vector<double> answers;
  answers.reserve(LumpedLink::potentials_per_root * share_.root_edge.size());
  for (const std::int32_t edge : share_.root_edge) {
    const auto e = static_cast<std::size_t>(edge);
    answers.insert(answers.end(), {rhs_[root_lower(e)], rhs_[root_upper(e)]});
  }
  exchange_down(answers, LumpedLink::potentials_per_root, share_.potentials_down);
}

void LumpedVessels::take_potentials() {
  const std::vector<double> answer = exchange_down({}, LumpedLink::potentials_per_root, share_.potentials_down);
  if (empty()) return;
  for (std::size_t j = 0; j < share_.root_edge.size(); ++j) {
    const auto e = static_cast<std::size_t>(share_.root_edge[j]);
    rhs_[root_lower(e)] = answer[LumpedLink::potentials_per_root * j];
    rhs_[root_upper(e)] = answer[LumpedLink::potentials_per_root * j + 1];
  }
}

void LumpedVessels::answer_pressures() {
  // Per root vessel (u, r): u's pressure after the step.
  std::vector<double> answers;
  answers.reserve(share_.root_edge.size());
  for (const std::int32_t edge : share_.root_edge) answers.push_back(pressure_[root_upper(static_cast<std::size_t>(edge))]);
  exchange_down(answers, LumpedLink::pressures_per_root, share_.pressures_down);
}

void LumpedVessels::take_pressures() {
  const std::vector<double> answer = exchange_down({}, LumpedLink::pressures_per_root, share_.pressures_down);
  std::copy(answer.begin(), answer.end(), share_.root_row.begin());
}

}  // namespace hemotree
