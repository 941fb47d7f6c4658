// Cutting a full tree to a budget (docs/pruning.md).
//
// Everything works on flat arrays over the vessels of the full tree: the children in CSR
// form (topology.hpp), the breadth-first order with the offsets of each generation, and one
// keep byte per vessel. After that set-up and one sweep that counts every vessel's
// descendants a few generations down, the profile strategy touches only the kept vessels and
// their candidate daughters: its cost is a few sweeps of the full tree, whatever the budget.
#include "pruner/pruning_strategies.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

#include "core/errors.hpp"
#include "core/uniform_source.hpp"
#include "formats/topology.hpp"

namespace hemotree {

namespace {

// The full tree seen from its root.
struct RootedTree {
  std::int32_t root = -1;
  Children children;
  std::vector<std::int32_t> parent;        // -1 at the root
  std::vector<std::int32_t> order;         // breadth first from the root
  std::vector<std::int64_t> level_offset;  // generation g is order[level_offset[g] .. [g+1])

  std::int64_t daughters(std::int32_t v) const {
    return children.offset[v + 1] - children.offset[v];
  }
  const std::int32_t* first_daughter(std::int32_t v) const {
    return children.index.data() + children.offset[v];
  }
  std::size_t generations() const { return level_offset.size() - 1; }
  std::vector<double> profile() const {
    std::vector<double> p(generations());
    for (std::size_t g = 0; g < p.size(); ++g)
      p[g] = static_cast<double>(level_offset[g + 1] - level_offset[g]);
    return p;
  }
};

// Finds the root and the generations by topology (the vessel arrays, not the stored
// `generation` field, so that the result is a tree whatever the file says). The checks are
// those of check_rooted_tree, in a single pass without a graph library.
RootedTree rooted_tree(const Network& net) {
  const std::size_t n = net.vessel_count();
  if (n == 0) throw InputError("the network has no vessels");
  if (n > static_cast<std::size_t>(INT32_MAX)) throw InputError("too many vessels to prune");
  RootedTree t;

  std::vector<std::int32_t> entering(net.node_count(), -1);
  for (std::size_t v = 0; v < n; ++v) {
    std::int32_t& e = entering[net.to[v]];
    if (e >= 0)
      throw InputError("not a tree: vessels " + std::to_string(net.id[v]) + " and " +
                       std::to_string(net.id[e]) + " end at the same node");
    e = static_cast<std::int32_t>(v);
  }
  t.parent.resize(n);
  for (std::size_t v = 0; v < n; ++v) {
    t.parent[v] = entering[net.from[v]];
    if (t.parent[v] >= 0) continue;
    if (t.root >= 0)
      throw InputError("not a tree: vessels " + std::to_string(net.id[t.root]) + " and " +
                       std::to_string(net.id[v]) + " are both fed by no vessel");
    t.root = static_cast<std::int32_t>(v);
  }
  if (t.root < 0) throw InputError("not a tree: every vessel is fed by another (a closed loop)");

  t.children = children_of(net);
  t.order.reserve(n);
  t.order.push_back(t.root);
  t.level_offset = {0, 1};
  for (std::size_t begin = 0; begin < t.order.size();) {
    const std::size_t end = t.order.size();
    for (std::size_t k = begin; k < end; ++k) {
      const std::int32_t v = t.order[k];
      t.order.insert(t.order.end(), t.first_daughter(v), t.first_daughter(v) + t.daughters(v));
    }
    if (t.order.size() > end) t.level_offset.push_back(static_cast<std::int64_t>(t.order.size()));
    begin = end;
  }
  if (t.order.size() != n)
    throw InputError("not a tree: " + std::to_string(n - t.order.size()) +
                     " vessels are not reached from the root (a closed loop)");
  return t;
}

// Uniform integer in [lo, hi) from the portable uniform source.
std::size_t draw(UniformSource& uniform, std::size_t lo, std::size_t hi) {
  const auto k = lo + static_cast<std::size_t>(uniform() * static_cast<double>(hi - lo));
  return std::min(k, hi - 1);
}

// Roles of vessels in the profile selection.
constexpr std::uint8_t free_vessel = 0;   // chosen at random against the target
constexpr std::uint8_t forced = 1;        // always kept, counted against the target (a path)
constexpr std::uint8_t forced_extra = 2;  // always kept, on top of the target (a subtree)

// How many generations ahead the selection looks when it checks that the kept vessels leave
// enough candidates below them (see ProfileSelection). The target's decline, from the end of
// its binary growth to its last generations, spans up to about twenty generations; with
// sixteen the deepest ones are in sight from the start of the decline, and the achieved
// profile meets the target to the last generation (docs/pruning.md measures 1 to 16). The
// price is 2 bytes per vessel and generation of look-ahead.
constexpr int lookahead = 16;
using Reach = std::array<std::int32_t, lookahead + 1>;  // [k]: vessels k generations below

// A sibling group: the daughters of one parent, named by that parent.
struct Group {
  std::int32_t parent;
  std::int64_t size;  // vessels in the group
  Reach below;        // counted descendants of its vessels, by generations below them
};

// Top-down selection against a target profile, the heart of prune_by_profile.
//
// Generation g's candidates are the sibling groups whose parent was kept at g - 1. The
// forced groups are kept; then groups are drawn without replacement (a partial Fisher-Yates
// shuffle) until the generation holds want = target[g] + carry vessels. carry is what the
// generations above missed (or, negative, exceeded): too few candidates at g pass their
// deficit on to g + 1.
//
// In the declining tail the target falls exactly as the full tree does, so a uniform draw
// leaves each next generation, on average, just as many candidates as its target: half the
// time fewer, and the deficit would then grow down the tail, the deepest (capillary)
// generations coming out short. And the deepest generations of the full tree hang below few
// vessels higher up, which a uniform draw easily misses. So after the draw the descendants
// of the kept vessels 1 .. lookahead generations down are compared with the wants there; where
// they fall short, the fewest possible drawn groups are exchanged for undrawn ones of the same
// size with more descendants at that depth (poorest for richest, ties in random order),
// nearest generation first, never undoing a nearer one. The draw stays uniform except for
// that correction, which acts mostly in the last generations.
//
// Whatever the generations could not place is finally added below the kept tree, at random
// among the groups whose parent is kept, deepest generation first, so that the right tail
// thickens rather than the trunk.
class ProfileSelection {
 public:
  ProfileSelection(const RootedTree& tree, const std::vector<std::uint8_t>* role,
                   UniformSource& uniform)
      : tree_(tree), role_(role), uniform_(uniform), keep_(tree.order.size(), 0) {
    count_descendants();
  }

  KeepMask run(const std::vector<double>& target, std::vector<double>& achieved) {
    auto target_at = [&](std::size_t g) {
      return g < target.size() ? static_cast<std::int64_t>(std::llround(target[g])) : 0;
    };
    keep_[tree_.root] = 1;
    level_ = {tree_.root};
    achieved.assign(1, 1.0);
    std::int64_t counted_total = counted(tree_.root) ? 1 : 0;
    std::int64_t carry = target_at(0) - counted_total;

    for (std::size_t g = 1; !level_.empty(); ++g) {
      next_.clear();
      groups_.clear();
      std::int64_t counted_here = 0;
      std::array<std::int64_t, lookahead + 1> offered{};  // descendants of generation g's kept
      for (const std::int32_t p : level_) {
        const std::int64_t size = tree_.daughters(p);
        if (size == 0) continue;
        const auto r = role(tree_.first_daughter(p)[0]);
        if (r == free_vessel) {
          groups_.push_back({p, size, reach_of_group(p)});
          continue;
        }
        keep_group(p);
        if (r == forced) {
          counted_here += size;
          add(offered, reach_of_group(p));
        }
      }
      if (next_.empty() && groups_.empty()) break;

      const std::int64_t want = target_at(g) + carry;
      const std::size_t drawn = draw_groups(want - counted_here);
      for (std::size_t k = 0; k < drawn; ++k) {
        counted_here += groups_[k].size;
        add(offered, groups_[k].below);
      }
      carry = want - counted_here;

      std::array<std::int64_t, lookahead + 1> shortfall{};
      for (int k = 1; k <= lookahead; ++k)
        shortfall[k] = target_at(g + static_cast<std::size_t>(k)) - offered[k];
      shortfall[1] += carry;
      enrich(drawn, shortfall);

      for (std::size_t k = 0; k < drawn; ++k) keep_group(groups_[k].parent);
      achieved.push_back(static_cast<double>(next_.size()));
      counted_total += counted_here;
      level_.swap(next_);
    }

    std::int64_t target_total = 0;
    for (std::size_t g = 0; g < target.size(); ++g) target_total += target_at(g);
    fill_below(target_total - counted_total, achieved);
    while (achieved.size() > 1 && achieved.back() == 0.0) achieved.pop_back();
    return std::move(keep_);
  }

 private:
  std::uint8_t role(std::int32_t v) const { return role_ ? (*role_)[v] : free_vessel; }
  bool counted(std::int32_t v) const { return role(v) != forced_extra; }
  static void add(std::array<std::int64_t, lookahead + 1>& a, const Reach& b) {
    for (int k = 0; k <= lookahead; ++k) a[k] += b[k];
  }

  // descendants_[v * lookahead + k - 1]: counted vessels k generations below v, k = 1 ..
  // lookahead, for every vessel, from the leaves up (one sweep, saturating at 65535).
  void count_descendants() {
    descendants_.assign(tree_.order.size() * lookahead, 0);
    for (auto it = tree_.order.rbegin(); it != tree_.order.rend(); ++it) {
      const std::int32_t v = *it;
      std::uint16_t* row = &descendants_[static_cast<std::size_t>(v) * lookahead];
      const std::int32_t* d = tree_.first_daughter(v);
      for (std::int64_t j = 0; j < tree_.daughters(v); ++j) {
        if (!counted(d[j])) continue;
        const std::uint16_t* below = &descendants_[static_cast<std::size_t>(d[j]) * lookahead];
        row[0] = saturated(row[0] + 1);
        for (int k = 1; k < lookahead; ++k) row[k] = saturated(row[k] + below[k - 1]);
      }
    }
  }
  static std::uint16_t saturated(int x) { return static_cast<std::uint16_t>(std::min(x, 65535)); }

  // Counted descendants of the daughters of p, 1 .. lookahead generations below them.
  Reach reach_of_group(std::int32_t p) const {
    Reach r{};
    const std::int32_t* d = tree_.first_daughter(p);
    for (std::int64_t j = 0; j < tree_.daughters(p); ++j) {
      const std::uint16_t* row = &descendants_[static_cast<std::size_t>(d[j]) * lookahead];
      for (int k = 1; k <= lookahead; ++k) r[k] += row[k - 1];
    }
    return r;
  }

  void keep_group(std::int32_t p) {
    const std::int32_t* d = tree_.first_daughter(p);
    for (std::int64_t k = 0; k < tree_.daughters(p); ++k) {
      keep_[d[k]] = 1;
      next_.push_back(d[k]);
    }
  }

  // Draws groups at random until they hold `want` vessels (a group that would overshoot
  // by more than it helps is passed over). Moves the drawn groups to the front of groups_,
  // returns how many.
  std::size_t draw_groups(std::int64_t want) {
    std::size_t drawn = 0;
    std::int64_t held = 0;
    for (std::size_t i = 0; i < groups_.size() && held < want; ++i) {
      std::swap(groups_[i], groups_[draw(uniform_, i, groups_.size())]);
      if (2 * (want - held) > groups_[i].size) {  // closer to want with it than without
        held += groups_[i].size;
        std::swap(groups_[drawn++], groups_[i]);
      }
    }
    return drawn;
  }

  // Exchanges drawn groups (groups_[0, drawn)) for undrawn ones of equal size with more
  // descendants, depth by depth from the nearest, until no depth falls short or no exchange
  // helps; an exchange never opens a shortfall at a nearer depth.
  void enrich(std::size_t drawn, std::array<std::int64_t, lookahead + 1>& shortfall) {
    bool shuffled = false;
    for (int k = 1; k <= lookahead; ++k) {
      if (shortfall[k] <= 0 || drawn == groups_.size()) continue;
      if (!shuffled) {  // the undrawn part is only partly shuffled: finish, for random ties
        for (std::size_t i = drawn; i < groups_.size(); ++i)
          std::swap(groups_[i], groups_[draw(uniform_, i, groups_.size())]);
        shuffled = true;
      }
      const auto poor_end = groups_.begin() + static_cast<std::ptrdiff_t>(drawn);
      std::stable_sort(groups_.begin(), poor_end, [k](const Group& a, const Group& b) {
        return a.below[k] < b.below[k];
      });
      std::stable_sort(poor_end, groups_.end(), [k](const Group& a, const Group& b) {
        return a.below[k] > b.below[k];
      });
      std::size_t poor = 0, rich = drawn;
      while (shortfall[k] > 0 && poor < drawn && rich < groups_.size()) {
        Group& a = groups_[poor];
        Group& b = groups_[rich];
        if (b.below[k] <= a.below[k]) break;  // sorted: no exchange can help any more
        bool harmless = a.size == b.size;
        for (int j = 1; j < k && harmless; ++j) {
          const std::int64_t after = shortfall[j] + a.below[j] - b.below[j];
          harmless = after <= std::max<std::int64_t>(shortfall[j], 0);
        }
        if (!harmless) {
          ++rich;
          continue;
        }
        for (int j = 1; j <= lookahead; ++j) shortfall[j] -= b.below[j] - a.below[j];
        std::swap(a, b);
        ++poor;
        ++rich;
      }
    }
  }

  // Adds up to `deficit` vessels as whole groups whose parent is kept, deepest generation
  // first, at random within a generation. Repeats while groups added open new ones.
  void fill_below(std::int64_t deficit, std::vector<double>& achieved) {
    while (deficit > 0) {
      bool added = false;
      for (std::size_t g = tree_.generations(); g-- > 1 && deficit > 0;) {
        // Groups of generation g: the daughters of kept generation g - 1 vessels, not kept.
        groups_.clear();
        for (std::int64_t k = tree_.level_offset[g - 1]; k < tree_.level_offset[g]; ++k) {
          const std::int32_t p = tree_.order[k];
          if (!keep_[p] || tree_.daughters(p) == 0) continue;
          const std::int32_t first = tree_.first_daughter(p)[0];
          if (!keep_[first] && role(first) == free_vessel)
            groups_.push_back({p, tree_.daughters(p), Reach{}});
        }
        next_.clear();
        const std::size_t drawn = draw_groups(deficit);
        for (std::size_t k = 0; k < drawn; ++k) keep_group(groups_[k].parent);
        const auto placed = static_cast<std::int64_t>(next_.size());
        if (placed == 0) continue;
        if (achieved.size() <= g) achieved.resize(g + 1, 0.0);
        achieved[g] += static_cast<double>(placed);
        deficit -= placed;
        added = true;
      }
      if (!added) return;  // the full tree is exhausted (or no group fits the remainder)
    }
  }

  const RootedTree& tree_;
  const std::vector<std::uint8_t>* role_;
  UniformSource& uniform_;
  KeepMask keep_;
  std::vector<std::uint16_t> descendants_;
  std::vector<std::int32_t> level_, next_;
  std::vector<Group> groups_;
};

void require_budget(std::size_t budget) {
  if (budget == 0) throw InputError("the budget must be at least one vessel");
}

}  // namespace

KeepMask prune_by_profile(const Network& full, std::size_t budget, std::uint64_t seed,
                          ProfileReport* report) {
  require_budget(budget);
  const RootedTree tree = rooted_tree(full);
  const std::vector<double> profile = tree.profile();
  const std::vector<double> target = rescale_profile(profile, budget);
  UniformSource uniform(seed);
  std::vector<double> achieved;
  KeepMask keep = ProfileSelection(tree, nullptr, uniform).run(target, achieved);
  if (report) *report = {profile, target, achieved};
  return keep;
}

KeepMask prune_by_diameter(const Network& full, double cutoff) {
  const RootedTree tree = rooted_tree(full);
  KeepMask keep(full.vessel_count(), 0);
  keep[tree.root] = 1;
  // Breadth-first order visits a parent before its daughters.
  for (const std::int32_t v : tree.order) {
    if (!keep[v] || !(full.diameter[v] >= cutoff)) continue;
    const std::int32_t* d = tree.first_daughter(v);
    for (std::int64_t k = 0; k < tree.daughters(v); ++k) keep[d[k]] = 1;
  }
  return keep;
}

KeepMask prune_by_generation(const Network& full, int max_generation) {
  if (max_generation < 0) throw InputError("the last generation kept must be 0 or more");
  const RootedTree tree = rooted_tree(full);
  KeepMask keep(full.vessel_count(), 0);
  const std::size_t last = std::min<std::size_t>(static_cast<std::size_t>(max_generation) + 1,
                                                 tree.generations());
  for (std::int64_t k = 0; k < tree.level_offset[last]; ++k) keep[tree.order[k]] = 1;
  return keep;
}

KeepMask prune_keeping_subtree(const Network& full, std::int64_t subtree_id, std::size_t budget,
                               std::uint64_t seed, ProfileReport* report) {
  require_budget(budget);
  const RootedTree tree = rooted_tree(full);
  const std::int64_t found = full.index_of(subtree_id);
  if (found < 0) throw InputError("no vessel has id " + std::to_string(subtree_id));
  const auto top = static_cast<std::int32_t>(found);

  // The path from the root to the subtree, with the siblings along it: forced and counted
  // against the target like any kept vessel. Its length is the subtree's generation.
  std::vector<std::uint8_t> role(full.vessel_count(), free_vessel);
  role[tree.root] = forced;
  std::size_t path_vessels = 1, top_generation = 0;
  for (std::int32_t v = top; v != tree.root; v = tree.parent[v], ++top_generation) {
    const std::int32_t p = tree.parent[v];
    const std::int32_t* d = tree.first_daughter(p);
    for (std::int64_t k = 0; k < tree.daughters(p); ++k) role[d[k]] = forced;
    path_vessels += static_cast<std::size_t>(tree.daughters(p));
  }

  // Everything below the subtree's top vessel: kept on top of the target. Its own profile,
  // by generation of the full tree, is taken out of the profile the target is rescaled from.
  const std::vector<double> profile = tree.profile();
  std::vector<double> below(profile.size(), 0.0);
  std::vector<std::int32_t> level{top}, next;
  std::size_t below_vessels = 0;
  for (std::size_t g = top_generation + 1; !level.empty(); ++g) {
    next.clear();
    for (const std::int32_t v : level) {
      const std::int32_t* d = tree.first_daughter(v);
      for (std::int64_t k = 0; k < tree.daughters(v); ++k) {
        role[d[k]] = forced_extra;
        next.push_back(d[k]);
      }
    }
    if (!next.empty()) below[g] = static_cast<double>(next.size());
    below_vessels += next.size();
    level.swap(next);
  }
  if (path_vessels + below_vessels > budget)
    throw InputError("the subtree of vessel " + std::to_string(subtree_id) + " holds " +
                     std::to_string(below_vessels + 1) + " vessels and " +
                     std::to_string(path_vessels + below_vessels) +
                     " with the path to it, more than the budget of " +
                     std::to_string(budget));

  std::vector<double> rest(profile.size());
  for (std::size_t g = 0; g < rest.size(); ++g) rest[g] = profile[g] - below[g];
  while (rest.size() > 1 && rest.back() == 0.0) rest.pop_back();
  const std::vector<double> rest_target = rescale_profile(rest, budget - below_vessels);

  UniformSource uniform(seed);
  std::vector<double> achieved;
  KeepMask keep = ProfileSelection(tree, &role, uniform).run(rest_target, achieved);
  if (report) {
    std::vector<double> target(below);
    for (std::size_t g = 0; g < rest_target.size(); ++g) target[g] += rest_target[g];
    while (target.size() > 1 && target.back() == 0.0) target.pop_back();
    *report = {profile, target, achieved};
  }
  return keep;
}

Network extract(const Network& full, const KeepMask& keep) {
  if (keep.size() != full.vessel_count())
    throw std::invalid_argument("extract: the keep mask does not match the network");
  // The blood and the metadata carry over. The inlet and the outlets do not: the outlets of
  // a pruned tree are new terminal vessels whose 0D models stand for the pruned branches,
  // and the stage that calibrates them (vprune) sets the inflow with them.
  Network out;
  out.provenance = full.provenance;
  out.extra = full.extra;
  out.blood = full.blood;

  // Nodes touched by kept vessels, in their original order.
  constexpr std::int32_t unused = -1;
  std::vector<std::int32_t> node_index(full.node_count(), unused);
  std::size_t kept = 0;
  for (std::size_t v = 0; v < full.vessel_count(); ++v) {
    if (!keep[v]) continue;
    ++kept;
    node_index[full.from[v]] = node_index[full.to[v]] = 0;
  }
  std::size_t nodes = 0;
  for (const std::int32_t i : node_index) nodes += i != unused;
  out.reserve(kept, nodes);
  const bool coordinates = full.has_coordinates();
  for (std::size_t n = 0; n < full.node_count(); ++n) {
    if (node_index[n] == unused) continue;
    node_index[n] = coordinates ? out.add_node(full.node_id[n], full.x[n], full.y[n], full.z[n])
                                : out.add_node(full.node_id[n]);
  }

  // Vessels copied field by field (not through add_vessel, which would reclassify).
  for (std::size_t v = 0; v < full.vessel_count(); ++v) {
    if (!keep[v]) continue;
    out.id.push_back(full.id[v]);
    out.from.push_back(node_index[full.from[v]]);
    out.to.push_back(node_index[full.to[v]]);
    out.length.push_back(full.length[v]);
    out.diameter.push_back(full.diameter[v]);
    out.wall_thickness.push_back(full.wall_thickness[v]);
    out.youngs_modulus.push_back(full.youngs_modulus[v]);
    out.generation.push_back(full.generation[v]);
    out.vessel_class.push_back(full.vessel_class[v]);
    if (!full.beta.empty()) out.beta.push_back(full.beta[v]);
    if (!full.reference_pressure.empty())
      out.reference_pressure.push_back(full.reference_pressure[v]);
  }
  return out;
}

}  // namespace hemotree
