#include "distributed/tree_share.hpp"

#include <algorithm>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

#include "network_flow/forest_order.hpp"

namespace hemotree {

TreeCut::TreeCut(std::size_t nodes, std::span<const std::int32_t> a, std::span<const std::int32_t> b,
                 std::span<const std::int32_t> edge_owner, int rank_count, int top_rank_)
    : ranks(rank_count), top_rank(top_rank_) {
  if (ranks < 1 || top_rank < 0 || top_rank >= ranks)
    throw std::invalid_argument("TreeCut: the top's rank " + std::to_string(top_rank) + " of " + std::to_string(ranks));
  if (edge_owner.size() != a.size() || a.size() != b.size())
    throw std::invalid_argument("TreeCut: an owner and two nodes per edge");
  // NodalSystem's order, from the same functions (network_flow/forest_order.hpp).
  if (parents_below(nodes, a, b, parent_edge)) {
    parent.assign(nodes, -1);
    order.resize(nodes);
    for (std::size_t c = 0; c < nodes; ++c) {
      order[c] = static_cast<std::int32_t>(c);
      if (const std::int32_t e = parent_edge[c]; e >= 0)
        parent[c] = std::min(a[static_cast<std::size_t>(e)], b[static_cast<std::size_t>(e)]);
    }
  } else {
    if (!peel_leaves(nodes, a, b, order, parent, parent_edge))
      throw std::invalid_argument("TreeCut: the graph has a loop or a doubled edge: not a forest");
    std::reverse(order.begin(), order.end());
  }
  owner.assign(nodes, top);
  for (std::size_t c = 0; c < nodes; ++c)
    if (const std::int32_t e = parent_edge[c]; e >= 0) owner[c] = edge_owner[static_cast<std::size_t>(e)];
  place.assign(nodes, 0);
  for (std::size_t k = 0; k < nodes; ++k) place[static_cast<std::size_t>(order[k])] = static_cast<std::int32_t>(k);
  roots.assign(static_cast<std::size_t>(ranks), {});
  for (const std::int32_t node : order) {
    const auto c = static_cast<std::size_t>(node);
    const std::int32_t mine = owner[c], p = parent[c];
    if (mine != top && (mine < 0 || mine >= ranks))
      throw std::invalid_argument("TreeCut: edge " + std::to_string(parent_edge[c]) + " on rank " +
                                  std::to_string(mine) + " of " + std::to_string(ranks));
    const std::int32_t above = p >= 0 ? owner[static_cast<std::size_t>(p)] : top;
    if (above != top && above != mine)
      throw std::invalid_argument("TreeCut: node " + std::to_string(c) + " (" +
                                  (mine == top ? std::string("the top") : "rank " + std::to_string(mine)) +
                                  ") hangs from node " + std::to_string(p) + " of rank " + std::to_string(above) +
                                  ": a share must be whole subtrees below the top");
    if (mine != top && above == top) roots[static_cast<std::size_t>(mine)].push_back(node);
  }
}

std::vector<std::int32_t> TreeCut::share_nodes(int rank) const {
  std::vector<std::int32_t> out;
  for (const std::int32_t node : order)
    if (owner[static_cast<std::size_t>(node)] == rank) out.push_back(node);
  return out;
}

std::vector<std::int32_t> TreeCut::top_nodes() const { return share_nodes(top); }

std::vector<std::vector<std::int32_t>> TreeCut::held_nodes() const {
  std::vector<std::vector<std::int32_t>> held(static_cast<std::size_t>(ranks));
  std::vector<std::int32_t> top_part;
  for (const std::int32_t node : order) {
    const std::int32_t o = owner[static_cast<std::size_t>(node)];
    (o == top ? top_part : held[static_cast<std::size_t>(o)]).push_back(node);
  }
  auto& top_rank_nodes = held[static_cast<std::size_t>(top_rank)];
  top_rank_nodes.insert(top_rank_nodes.end(), top_part.begin(), top_part.end());
  return held;
}

CutForest cut_forest(const TreeCut& cut, std::vector<std::int32_t> nodes) {
  CutForest out{std::move(nodes), {}, {}, {}};
  const std::vector<std::int32_t>& on = out.nodes;
  // Places by binary search in the forest's order: the nodes are a subsequence of it.
  auto local_place = [&](std::int32_t node) -> std::int32_t {
    const std::int32_t k = cut.place[static_cast<std::size_t>(node)];
    const auto it = std::lower_bound(on.begin(), on.end(), k, [&](std::int32_t n, std::int32_t key) {
      return cut.place[static_cast<std::size_t>(n)] < key;
    });
    return it != on.end() && *it == node ? static_cast<std::int32_t>(it - on.begin()) : -1;
  };
  out.parent_place.assign(on.size(), -1);
  for (std::size_t j = 0; j < on.size(); ++j) {
    const std::int32_t p = cut.parent[static_cast<std::size_t>(on[j])];
    if (p < 0) continue;
    const std::int32_t above = local_place(p);
    if (above < 0) continue;
    out.parent_place[j] = above;
    out.a.push_back(above);
    out.b.push_back(static_cast<std::int32_t>(j));
  }
  return out;
}

TopPlaces top_places(const TreeCut& cut) {
  std::vector<std::pair<std::int32_t, std::int32_t>> members;  // (place in the forest, source)
  const std::vector<std::int32_t> own = cut.top_nodes();
  for (std::size_t i = 0; i < own.size(); ++i)
    members.emplace_back(cut.place[static_cast<std::size_t>(own[i])], static_cast<std::int32_t>(i));
  std::int32_t slot = 0;
  for (const auto& rank_roots : cut.roots)
    for (const std::int32_t r : rank_roots) members.emplace_back(cut.place[static_cast<std::size_t>(r)], ~slot++);
  std::sort(members.begin(), members.end());
  std::vector<std::int32_t> nodes(members.size());
  TopPlaces out;
  out.own.resize(own.size());
  out.root_place.resize(static_cast<std::size_t>(slot));
  for (std::size_t k = 0; k < members.size(); ++k) {
    const auto [where, source] = members[k];
    nodes[k] = cut.order[static_cast<std::size_t>(where)];
    if (source >= 0)
      out.own[static_cast<std::size_t>(source)] = static_cast<std::int32_t>(k);
    else
      out.root_place[static_cast<std::size_t>(~source)] = static_cast<std::int32_t>(k);
  }
  out.forest = cut_forest(cut, std::move(nodes));
  return out;
}

std::vector<std::int32_t> TreeCut::edge_ranks() const {
  // A forest's every edge is one node's edge to its parent.
  const auto edges = static_cast<std::size_t>(std::count_if(parent_edge.begin(), parent_edge.end(), [](std::int32_t e) { return e >= 0; }));
  std::vector<std::int32_t> out(edges, top_rank);
  for (std::size_t c = 0; c < parent_edge.size(); ++c)
    if (const std::int32_t e = parent_edge[c]; e >= 0) out[static_cast<std::size_t>(e)] = owner[c] == top ? top_rank : owner[c];
  return out;
}

namespace {

NodalSystem system_of(const CutForest& forest) {
  return NodalSystem(forest.nodes.size(), forest.a, forest.b, NodalSystem::Method::tree_elimination);
}

}  // namespace

TreeShare::TreeShare(const TreeCut& cut, int rank) {
  CutForest forest = cut_forest(cut, cut.share_nodes(rank));
  system_ = system_of(forest);
  nodes_ = std::move(forest.nodes);
  edge_place_ = std::move(forest.b);
  system_.open_roots();
  edge_conductance_.resize(edge_place_.size());
  // The roots come in elimination order, as cut.roots lists them.
  for (std::size_t j = 0; j < nodes_.size(); ++j) {
    const std::int32_t p = cut.parent[static_cast<std::size_t>(nodes_[j])];
    if (p >= 0 && cut.owner[static_cast<std::size_t>(p)] == TreeCut::top) roots_.push_back(static_cast<std::int32_t>(j));
  }
}

std::vector<double> TreeShare::factorize_forward(std::span<const double> conductance, std::span<const double> shunt,
                                                 std::span<double> y) {
  if (conductance.size() != nodes_.size() || shunt.size() != nodes_.size() || y.size() != nodes_.size())
    throw std::invalid_argument("TreeShare::factorize_forward: " + std::to_string(nodes_.size()) +
                                " numbers of each kind expected");
  for (std::size_t e = 0; e < edge_place_.size(); ++e)
    edge_conductance_[e] = conductance[static_cast<std::size_t>(edge_place_[e])];
  // A root's edge into the top is the top's to eliminate, but this share's to answer for.
  for (std::size_t k = 0; k < roots_.size(); ++k) {
    const double g = conductance[static_cast<std::size_t>(roots_[k])];
    if (!(g > 0 && g < std::numeric_limits<double>::infinity()))
      throw std::invalid_argument("TreeShare::factorize_forward: the conductance of node " +
                                  std::to_string(nodes_[static_cast<std::size_t>(roots_[k])]) +
                                  "'s edge into the top is " + std::to_string(g));
  }
  system_.factorize_forward(edge_conductance_, shunt, y);  // open roots: never singular here
  std::vector<double> message;
  message.reserve(3 * roots_.size());
  for (const std::int32_t r : roots_) {
    const auto j = static_cast<std::size_t>(r);
    message.insert(message.end(), {conductance[j], system_.open_root_conductance(j), y[j]});
  }
  return message;
}

std::vector<double> TreeShare::forward(std::span<double> y) const {
  system_.forward(y);
  std::vector<double> message(roots_.size());
  for (std::size_t k = 0; k < roots_.size(); ++k) message[k] = y[static_cast<std::size_t>(roots_[k])];
  return message;
}

void TreeShare::backward(std::span<const double> root_potential, std::span<double> y) const {
  if (root_potential.size() != roots_.size() || y.size() != nodes_.size())
    throw std::invalid_argument("TreeShare::backward: one potential per root, one number per node");
  for (std::size_t k = 0; k < roots_.size(); ++k) y[static_cast<std::size_t>(roots_[k])] = root_potential[k];
  system_.backward(y, y);
}

TreeTop::TreeTop(const TreeCut& cut) : places_(top_places(cut)) {
  const std::vector<std::int32_t>& nodes = places_.forest.nodes;
  system_ = system_of(places_.forest);
  edge_conductance_.resize(places_.forest.b.size());
  shunt_.resize(nodes.size());
  y_.resize(nodes.size());
  // The lowest node below each place, for naming a singular component as the whole forest's
  // system does (its lowest node): an own node stands for itself, a share root for its
  // subtree.
  std::vector<std::int32_t> lowest(cut.order.size());
  std::iota(lowest.begin(), lowest.end(), 0);
  for (std::size_t k = cut.order.size(); k-- > 0;) {
    const auto c = static_cast<std::size_t>(cut.order[k]);
    if (const std::int32_t p = cut.parent[c]; p >= 0)
      lowest[static_cast<std::size_t>(p)] = std::min(lowest[static_cast<std::size_t>(p)], lowest[c]);
  }
  lowest_.assign(nodes.begin(), nodes.end());
  for (const std::int32_t k : places_.root_place)
    lowest_[static_cast<std::size_t>(k)] = lowest[static_cast<std::size_t>(nodes[static_cast<std::size_t>(k)])];
}

void TreeTop::gather(std::span<const double> b, std::span<const double> messages, std::size_t stride,
                     std::span<const double> conductance, std::span<const double> shunt) {
  if (b.size() != places_.own.size() || messages.size() != stride * places_.root_place.size())
    throw std::invalid_argument("TreeTop: " + std::to_string(places_.own.size()) + " own numbers and " +
                                std::to_string(stride * places_.root_place.size()) + " from the shares expected");
  const bool factorizing = stride == 3;
  std::vector<double> below_conductance;  // per place: the conductance of its edge to its parent
  if (factorizing) below_conductance.assign(places_.forest.nodes.size(), 0.0);
  for (std::size_t i = 0; i < places_.own.size(); ++i) {
    const auto k = static_cast<std::size_t>(places_.own[i]);
    y_[k] = b[i];
    if (factorizing) {
      shunt_[k] = shunt[i];
      below_conductance[k] = conductance[i];
    }
  }
  for (std::size_t s = 0; s < places_.root_place.size(); ++s) {
    const auto k = static_cast<std::size_t>(places_.root_place[s]);
    const double* m = messages.data() + stride * s;
    y_[k] = m[stride - 1];
    if (factorizing) {
      below_conductance[k] = m[0];
      shunt_[k] = m[1];
    }
  }
  if (factorizing)
    for (std::size_t e = 0; e < places_.forest.b.size(); ++e)
      edge_conductance_[e] = below_conductance[static_cast<std::size_t>(places_.forest.b[e])];
}

void TreeTop::solve_and_scatter(std::span<double> x, std::span<double> answer) {
  if (x.size() != places_.own.size() || answer.size() != places_.root_place.size())
    throw std::invalid_argument("TreeTop: a potential per own node and per share root");
  system_.backward(y_, y_);
  for (std::size_t i = 0; i < places_.own.size(); ++i) x[i] = y_[static_cast<std::size_t>(places_.own[i])];
  for (std::size_t s = 0; s < places_.root_place.size(); ++s) answer[s] = y_[static_cast<std::size_t>(places_.root_place[s])];
}

std::int64_t TreeTop::factorize_solve(std::span<const double> conductance, std::span<const double> shunt,
                                      std::span<const double> b, std::span<const double> messages, std::span<double> x,
                                      std::span<double> answer) {
  if (conductance.size() != places_.own.size() || shunt.size() != places_.own.size())
    throw std::invalid_argument("TreeTop::factorize_solve: a conductance and a shunt per own node");
  gather(b, messages, 3, conductance, shunt);
  const std::int64_t singular = system_.factorize_forward(edge_conductance_, shunt_, y_);
  if (singular >= 0) {
    // Its component: the places whose root is the singular place's (parents come first).
    std::vector<std::int32_t> root(places_.forest.nodes.size());
    for (std::size_t k = 0; k < places_.forest.nodes.size(); ++k)
      root[k] = places_.forest.parent_place[k] < 0 ? static_cast<std::int32_t>(k) : root[static_cast<std::size_t>(places_.forest.parent_place[k])];
    const std::int32_t component = root[static_cast<std::size_t>(singular)];
    std::int32_t named = std::numeric_limits<std::int32_t>::max();
    for (std::size_t k = 0; k < places_.forest.nodes.size(); ++k)
      if (root[k] == component) named = std::min(named, lowest_[k]);
    return named;
  }
  solve_and_scatter(x, answer);
  return -1;
}

void TreeTop::solve(std::span<const double> b, std::span<const double> messages, std::span<double> x,
                    std::span<double> answer) {
  gather(b, messages, 1, {}, {});
  system_.forward(y_);
  solve_and_scatter(x, answer);
}

}  // namespace hemotree
