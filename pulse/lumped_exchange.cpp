// The 0D vessels of a run over ranks (pulse/lumped_cut.hpp): what a rank holds of the cut, and
// the two messages of every step, as LumpedVessels' predict() and complete() send them.
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
  // Once: a failure after the step's answers went down (or its refusal) is this rank's alone.
  if (!share_.answered) {
    share_.answered = true;
    share_.link.down({}, failure);
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

void LumpedVessels::answer_roots() {
  // Per root vessel (u, r): the potentials at its ends, and u's pressure after the step.
  std::vector<double> answers;
  answers.reserve(LumpedLink::down_per_root * share_.root_edge.size());
  for (const std::int32_t edge : share_.root_edge) {
    const auto e = static_cast<std::size_t>(edge);
    const std::size_t r = root_lower(e), u = root_upper(e);
    answers.insert(answers.end(), {rhs_[r], rhs_[u], pressure_[u]});
  }
  share_.answered = true;
  share_.link.down(answers, nullptr);
}

void LumpedVessels::take_answers() {
  const std::vector<double> answer = share_.link.down({}, nullptr);
  if (answer.size() != LumpedLink::down_per_root * share_.root_edge.size())
    throw std::logic_error("LumpedVessels: " + std::to_string(answer.size()) + " numbers from the top, " +
                           std::to_string(LumpedLink::down_per_root * share_.root_edge.size()) + " expected");
  if (empty()) return;
  for (std::size_t j = 0; j < share_.root_edge.size(); ++j) {
    const auto e = static_cast<std::size_t>(share_.root_edge[j]);
    const std::size_t u = root_upper(e), r = root_lower(e);
    rhs_[r] = answer[LumpedLink::down_per_root * j];
    rhs_[u] = answer[LumpedLink::down_per_root * j + 1];
    share_.root_row[j] = answer[LumpedLink::down_per_root * j + 2];
  }
}

}  // namespace hemotree
