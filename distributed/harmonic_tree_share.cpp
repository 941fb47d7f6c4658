#include "distributed/harmonic_tree_share.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace hemotree {

namespace {

// A zero pivot named by the forest's node, not by the place of a share's or the top's system.
[[noreturn]] void singular(const SingularHarmonicSystem& e, const CutForest& forest) {
  const auto node = static_cast<std::size_t>(forest.nodes[e.node]);
  throw SingularHarmonicSystem(node, "harmonic system: node " + std::to_string(node) +
                                         " lies in a part with no admittance to ground");
}

// Per place, its edge in the forest's system (-1 where it has none).
std::vector<std::int32_t> edge_of_place(const CutForest& forest) {
  std::vector<std::int32_t> out(forest.nodes.size(), -1);
  for (std::size_t e = 0; e < forest.b.size(); ++e) out[static_cast<std::size_t>(forest.b[e])] = static_cast<std::int32_t>(e);
  return out;
}

// The edge (m_pi, m_ip) as a system whose edges run from the parent's place to the child's reads it.
HarmonicSystem::Coupling coupling_of(Complex up, Complex down) { return {down, up}; }

}  // namespace

HarmonicTreeShare::HarmonicTreeShare(const TreeCut& cut, int rank)
    : forest_(cut_forest(cut, cut.share_nodes(rank))), system_(forest_.nodes.size(), forest_.a, forest_.b) {
  system_.open_roots();
  const std::size_t n = forest_.nodes.size();
  for (std::size_t j = 0; j < n; ++j)
    if (forest_.parent_place[j] < 0) roots_.push_back(static_cast<std::int32_t>(j));
  by_edge_.resize(n);
  for (std::size_t j = 0; j < n; ++j) by_edge_[j] = static_cast<std::int32_t>(j);
  auto edge_number = [&](std::int32_t j) { return cut.parent_edge[static_cast<std::size_t>(forest_.nodes[static_cast<std::size_t>(j)])]; };
  std::sort(by_edge_.begin(), by_edge_.end(), [&](std::int32_t x, std::int32_t y) { return edge_number(x) < edge_number(y); });
  coupling_.resize(forest_.b.size());
}

std::vector<Complex> HarmonicTreeShare::eliminate(std::span<const Complex> shunt, std::span<const EdgeToParent> edge,
                                                  std::span<Complex> current) {
  const std::size_t n = forest_.nodes.size();
  if (shunt.size() != n || edge.size() != n || current.size() != n)
    throw std::invalid_argument("HarmonicTreeShare::eliminate: " + std::to_string(n) + " numbers of each kind expected");
  // The diagonals as the whole system sums them: each node's shunt, then the edges' terms by
  // their numbers; a root's edge term at its parent goes to the top.
  pivot_.assign(shunt.begin(), shunt.end());
  for (const std::int32_t place : by_edge_) {
    const auto j = static_cast<std::size_t>(place);
    pivot_[j] += edge[j].own;
    if (const std::int32_t p = forest_.parent_place[j]; p >= 0) pivot_[static_cast<std::size_t>(p)] += edge[j].parent;
  }
  for (std::size_t e = 0; e < forest_.b.size(); ++e) {
    const EdgeToParent& y = edge[static_cast<std::size_t>(forest_.b[e])];
    coupling_[e] = coupling_of(y.up, y.down);
  }
  try {
    system_.eliminate_forest_up(coupling_, pivot_, current);
  } catch (const SingularHarmonicSystem& e) {
    singular(e, forest_);
  }
  std::vector<Complex> message;
  message.reserve(message_size * roots_.size());
  for (const std::int32_t r : roots_) {
    const auto j = static_cast<std::size_t>(r);
    message.insert(message.end(), {edge[j].up, edge[j].down, edge[j].parent, pivot_[j], current[j]});
  }
  return message;
}

void HarmonicTreeShare::substitute(std::span<const Complex> root_potential, std::span<Complex> current) const {
  if (root_potential.size() != roots_.size() || current.size() != forest_.nodes.size() || pivot_.size() != current.size())
    throw std::invalid_argument("HarmonicTreeShare::substitute: one potential per root, one number per node, after eliminate");
  for (std::size_t k = 0; k < roots_.size(); ++k) current[static_cast<std::size_t>(roots_[k])] = root_potential[k];
  system_.substitute_forest_down(coupling_, pivot_, current);
}

HarmonicTreeTop::HarmonicTreeTop(const TreeCut& cut)
    : places_(top_places(cut)),
      edge_of_place_(edge_of_place(places_.forest)),
      system_(places_.forest.nodes.size(), places_.forest.a, places_.forest.b) {
  const CutForest& forest = places_.forest;
  std::vector<std::int32_t> source(forest.nodes.size(), 0);
  for (std::size_t i = 0; i < places_.own.size(); ++i) source[static_cast<std::size_t>(places_.own[i])] = static_cast<std::int32_t>(i);
  for (std::size_t s = 0; s < places_.root_place.size(); ++s)
    source[static_cast<std::size_t>(places_.root_place[s])] = ~static_cast<std::int32_t>(s);
  std::vector<std::pair<std::int32_t, std::int32_t>> edges;  // (number, place below)
  for (std::size_t j = 0; j < forest.nodes.size(); ++j)
    if (forest.parent_place[j] >= 0)
      edges.emplace_back(cut.parent_edge[static_cast<std::size_t>(forest.nodes[j])], static_cast<std::int32_t>(j));
  std::sort(edges.begin(), edges.end());
  for (const auto& [number, place] : edges) {
    edge_below_.push_back(place);
    edge_source_.push_back(source[static_cast<std::size_t>(place)]);
  }
  coupling_.resize(forest.b.size());
}

void HarmonicTreeTop::solve(std::span<const Complex> shunt, std::span<const Complex> current,
                            std::span<const EdgeToParent> edge, std::span<const Complex> messages, std::span<Complex> x,
                            std::span<Complex> answer) {
  const std::size_t own = places_.own.size(), roots = places_.root_place.size();
  if (shunt.size() != own || current.size() != own || edge.size() != own || x.size() != own ||
      messages.size() != HarmonicTreeShare::message_size * roots || answer.size() != roots)
    throw std::invalid_argument("HarmonicTreeTop::solve: " + std::to_string(own) + " own numbers of each kind and " +
                                std::to_string(HarmonicTreeShare::message_size * roots) + " from the shares expected");
  const CutForest& forest = places_.forest;
  pivot_.assign(forest.nodes.size(), 0.0);
  x_.assign(forest.nodes.size(), 0.0);
  for (std::size_t i = 0; i < own; ++i) {
    const auto j = static_cast<std::size_t>(places_.own[i]);
    pivot_[j] = shunt[i];
    x_[j] = current[i];
  }
  for (std::size_t s = 0; s < roots; ++s) {
    const auto j = static_cast<std::size_t>(places_.root_place[s]);
    const Complex* m = messages.data() + HarmonicTreeShare::message_size * s;
    pivot_[j] = m[3];  // d_r: its own edge's term in it already
    x_[j] = m[4];
  }
  for (std::size_t k = 0; k < edge_below_.size(); ++k) {
    const auto j = static_cast<std::size_t>(edge_below_[k]);
    const auto p = static_cast<std::size_t>(forest.parent_place[j]);
    const auto e = static_cast<std::size_t>(edge_of_place_[j]);
    if (const std::int32_t source = edge_source_[k]; source >= 0) {
      const EdgeToParent& y = edge[static_cast<std::size_t>(source)];
      pivot_[j] += y.own;
      pivot_[p] += y.parent;
      coupling_[e] = coupling_of(y.up, y.down);
    } else {
      const Complex* m = messages.data() + HarmonicTreeShare::message_size * static_cast<std::size_t>(~source);
      pivot_[p] += m[2];
      coupling_[e] = coupling_of(m[0], m[1]);
    }
  }
  try {
    system_.solve_forest_in_place(coupling_, pivot_, x_);
  } catch (const SingularHarmonicSystem& e) {
    singular(e, forest);
  }
  for (std::size_t i = 0; i < own; ++i) x[i] = x_[static_cast<std::size_t>(places_.own[i])];
  for (std::size_t s = 0; s < roots; ++s) answer[s] = x_[static_cast<std::size_t>(places_.root_place[s])];
}

}  // namespace hemotree
