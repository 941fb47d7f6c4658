// The 0D vessels of a pulsatile run cut over ranks (pulse/lumped_cut.hpp), every rank played
// here by a thread of one process, the messages carried between them in memory: each rank's
// nodes, vessels and capacitors hold the one-process run's bits step after step, a coupling
// node's prediction and impedance on the top's rank too; a step abandoned on one rank is
// refused on every rank, none left waiting.
#include <barrier>
#include <bit>
#include <cmath>
#include <cstdint>
#include <exception>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "grown_trees.hpp"

#include "partition/partition.hpp"
#include "physics/viscosity_table.hpp"
#include "pulse/lumped_cut.hpp"
#include "pulse/lumped_vessels.hpp"
#include "tests/played_ranks.hpp"
#include "steady/vessel_laws.hpp"

using namespace hemotree;
using namespace hemotree::test_networks;

namespace {

std::string words(std::exception_ptr failure) {
  try {
    std::rethrow_exception(failure);
  } catch (const std::exception& e) {
    return e.what();
  } catch (const LumpedVessels::CollapsedNode& c) {
    return "a lumen closing at vessel " + std::to_string(c.vessel);
  } catch (...) {
    return "a failure";
  }
}

// The messages between P threads, as the MPI transport carries them between P ranks: up, the
// numbers of every rank but the top's to the top's; down, the top's answers to every rank.
class PlayedLink {
 public:
  PlayedLink(int ranks, int top, std::vector<int> roots)
      : top_(top), roots_(std::move(roots)), meet_(ranks), up_(static_cast<std::size_t>(ranks)),
        failure_(static_cast<std::size_t>(ranks)) {}
  LumpedLink for_rank(int rank) {
    LumpedLink link;
    link.up = [this, rank](std::span<const double> numbers, std::exception_ptr failure, bool& failed) {
      up_[static_cast<std::size_t>(rank)].assign(numbers.begin(), numbers.end());
      if (failure) failure_[static_cast<std::size_t>(rank)] = failure;
      meet_.arrive_and_wait();
      std::vector<double> all;
      failed = false;
      if (rank != top_) return all;
      for (std::size_t r = 0; r < up_.size(); ++r) {
        failed |= failure_[r] != nullptr;
        if (static_cast<int>(r) != top_) all.insert(all.end(), up_[r].begin(), up_[r].end());
      }
      return all;
    };
    link.down = [this, rank](std::span<const double> answers, std::exception_ptr failure, std::size_t per_root) {
      if (failure) failure_[static_cast<std::size_t>(rank)] = failure;
      if (rank == top_) answers_.assign(answers.begin(), answers.end());
      meet_.arrive_and_wait();
      std::string refusal;
      for (std::size_t r = 0; r < failure_.size(); ++r)
        if (failure_[r]) refusal += "rank " + std::to_string(r) + ": " + words(failure_[r]) + "; ";
      if (!refusal.empty()) throw std::runtime_error(refusal);
      std::size_t first = 0;
      for (int r = 0; r < rank; ++r) first += per_root * static_cast<std::size_t>(roots_[static_cast<std::size_t>(r)]);
      const std::size_t count = per_root * static_cast<std::size_t>(roots_[static_cast<std::size_t>(rank)]);
      std::vector<double> mine(answers_.begin() + static_cast<std::ptrdiff_t>(first),
                               answers_.begin() + static_cast<std::ptrdiff_t>(first + count));
      meet_.arrive_and_wait();  // every rank has read its answers before the next step's
      return mine;
    };
    return link;
  }

 private:
  int top_;
  std::vector<int> roots_;
  std::barrier<> meet_;
  std::vector<std::vector<double>> up_;
  std::vector<std::exception_ptr> failure_;
  std::vector<double> answers_;
};

bool same(double a, double b) { return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b); }

// A grown tree (about 16,500 vessels) fed at its root, every vessel 0D and one pi section,
// leaves to RCR outlets.
struct CutTree {
  Network net = test_networks::fed_tree(BoundaryType::rcr, Waveform::constant_value(1e-9 / 60));
  Blood blood = net.blood.value_or(Blood{});
  std::vector<TubeLaw> laws = vessel_laws(net, blood, 0.0, 0.1);
  ViscosityTable viscosity{blood};
  std::vector<bool> all = std::vector<bool>(net.vessel_count(), true);
  LumpedOrder whole_order = subtree_lumped_order(net, all);
  std::vector<std::int32_t> vessel_rank(const Partition& p) const {
    std::vector<std::int32_t> rank(p.rank_of_vessel.begin(), p.rank_of_vessel.end());
    for (const std::int32_t v : p.top) rank[static_cast<std::size_t>(v)] = p.top_rank;
    return rank;
  }
  LumpedVessels lumped(const LumpedCut* cut = nullptr) const {
    return LumpedVessels(net, laws, viscosity, blood, all, {}, {}, {}, cut);
  }
  // The tree cut for `ranks` by subtrees, each vessel weighing 1: each vessel's rank, every
  // rank's cut.
  struct Cut {
    int top = 0;
    std::vector<std::int32_t> rank;
    std::vector<LumpedCut> cuts;
  };
  Cut cut(int ranks) const {
    const Partition p = partition_network(net, std::vector<double>(net.vessel_count(), 1.0), ranks);
    Cut c{p.top_rank, vessel_rank(p), {}};
    for (int r = 0; r < ranks; ++r) c.cuts.push_back(lumped_cut(net, whole_order, c.rank, ranks, c.top, r));
    return c;
  }
  // Every rank's 0D vessels, linked through `played`, started at the given state.
  std::vector<LumpedVessels> ranks_started(const Cut& c, PlayedLink& played, const std::vector<double>& pressure,
                                           const std::vector<double>& flow) const {
    std::vector<LumpedVessels> part;
    for (std::size_t r = 0; r < c.cuts.size(); ++r) {
      part.push_back(lumped(&c.cuts[r]));
      part.back().set_link(played.for_rank(static_cast<int>(r)));
      part.back().start(pressure, flow);
    }
    return part;
  }
};

}  // namespace

TEST(LumpedCut, RanksHoldWholeSubtreesAndTheTopTheirRootsAsGhosts) {
  const CutTree t;
  const Partition p = partition_network(t.net, std::vector<double>(t.net.vessel_count(), 1.0), 3);
  const std::vector<std::int32_t> rank = t.vessel_rank(p);
  const LumpedCut top = lumped_cut(t.net, t.whole_order, rank, 3, p.top_rank, p.top_rank);
  std::size_t roots = 0, held = 0;
  for (int r = 0; r < 3; ++r) {
    const LumpedCut cut = lumped_cut(t.net, t.whole_order, rank, 3, p.top_rank, r);
    EXPECT_EQ(cut.roots, top.roots);
    if (r == p.top_rank) {
      EXPECT_EQ(cut.roots[static_cast<std::size_t>(r)], 0);
      held += cut.order.vessels.size() - cut.root_vessels.size();
      continue;
    }
    EXPECT_EQ(cut.root_vessels.size(), static_cast<std::size_t>(cut.roots[static_cast<std::size_t>(r)]));
    EXPECT_GT(cut.root_vessels.size(), 0u);
    roots += cut.root_vessels.size();
    held += cut.order.vessels.size();
    // Each root hangs from the top's rank: its upper node is a ghost here, not below another share's.
    for (const std::int32_t v : cut.root_vessels) EXPECT_NE(rank[static_cast<std::size_t>(v)], p.top_rank);
  }
  EXPECT_EQ(held, t.net.vessel_count());
  EXPECT_EQ(top.root_vessels.size(), roots);
  // A share hanging from another share is not whole subtrees.
  std::vector<std::int32_t> wrong = rank;
  for (std::size_t v = 0; v < wrong.size(); ++v)
    if (wrong[v] != p.top_rank) wrong[v] = static_cast<std::int32_t>(v % 2 == 0 ? 0 : 1) + (p.top_rank == 0 ? 1 : 0);
  EXPECT_THROW(lumped_cut(t.net, t.whole_order, wrong, 3, p.top_rank, 0), std::invalid_argument);
  // A vessel in sections.
  std::vector<std::uint8_t> sections(t.net.vessel_count(), 1);
  sections[static_cast<std::size_t>(t.net.vessel_count() / 2)] = 2;
  EXPECT_THROW(lumped_cut(t.net, t.whole_order, rank, 3, p.top_rank, p.top_rank, sections), std::invalid_argument);
}

// Steps of the whole and of every rank side by side: a pulsatile inflow at the root, a coupling
// node on the top (a 1D end's inflow and volume made up here, the same for both), and after
// every step each rank's numbers against the whole's, bit for bit.
TEST(LumpedCut, EveryRankStepsToTheWholeRunsBits) {
  const CutTree t;
  for (const int ranks : {2, 3, 5}) {
    const CutTree::Cut c = t.cut(ranks);
    const std::vector<std::int32_t>& rank = c.rank;
    const int top = c.top;
    std::vector<double> pressure(t.net.node_count()), flow(t.net.vessel_count(), 0.0);
    for (std::size_t i = 0; i < pressure.size(); ++i) pressure[i] = 4000.0 - 1.3 * static_cast<double>(i % 997);
    // The coupling node: the root vessel's distal node, on the top's rank.
    const std::int32_t coupled = t.net.to[0];
    ASSERT_EQ(rank[0], top);
    LumpedVessels whole = t.lumped();
    whole.start(pressure, flow);
    whole.set_coupling_nodes({whole.node_of(coupled)});
    PlayedLink played(ranks, top, c.cuts[0].roots);
    std::vector<LumpedVessels> part = t.ranks_started(c, played, pressure, flow);
    part[static_cast<std::size_t>(top)].set_coupling_nodes({part[static_cast<std::size_t>(top)].node_of(coupled)});
    const double dt = 2e-4;
    std::size_t compared = 0, differ = 0;
    auto step_inputs = [&](int n, double& inlet, double& coupled_in, double& coupled_volume) {
      const double time = dt * (n + 1);
      inlet = 1e-10 * (1 + 0.5 * std::sin(2 * M_PI * time / 0.01));
      coupled_in = 2e-11 * (1 + std::cos(2 * M_PI * time / 0.013));
      coupled_volume = 0.97 * dt * coupled_in;
    };
    for (int n = 0; n < 40; ++n) {
      double inlet, coupled_in, coupled_volume;
      step_inputs(n, inlet, coupled_in, coupled_volume);
      whole.predict(dt, std::vector<double>{coupled_in}, std::vector<double>{inlet}, {});
      const double predicted = whole.pressure_during_step(0, 1.0), impedance = whole.impedance(0);
      whole.complete(std::vector<double>{coupled_volume});
      std::vector<double> top_predicted(2, 0.0);
      const std::vector<std::string> failed = on_every_played_rank(part, [&](int r, LumpedVessels& mine) {
        const bool is_top = r == top;
        const std::vector<double> coupling_in = is_top ? std::vector<double>{coupled_in} : std::vector<double>{};
        const std::vector<double> inflow(mine.inflow_boundaries().size(), inlet);
        mine.predict(dt, coupling_in, inflow, {});
        if (is_top) top_predicted = {mine.pressure_during_step(0, 1.0), mine.impedance(0)};
        mine.complete(is_top ? std::vector<double>{coupled_volume} : std::vector<double>{});
      });
      for (int r = 0; r < ranks; ++r) ASSERT_EQ(failed[static_cast<std::size_t>(r)], "") << "rank " << r << " of " << ranks;
      differ += !same(top_predicted[0], predicted) + !same(top_predicted[1], impedance);
      compared = 0;
      for (int r = 0; r < ranks; ++r) {
        const LumpedVessels& mine = part[static_cast<std::size_t>(r)];
        for (std::size_t node = 0; node < t.net.node_count(); ++node) {
          const std::int32_t k = mine.node_of(static_cast<std::int64_t>(node));
          if (k < 0 || mine.ghost_node(k)) continue;
          ++compared;
          differ += !same(mine.node_pressure(k), whole.node_pressure(whole.node_of(static_cast<std::int64_t>(node))));
        }
        for (std::size_t v = 0; v < t.net.vessel_count(); ++v) {
          const std::int32_t i = mine.vessel_index(v);
          if (i < 0 || mine.ghost_vessel(i)) continue;
          ++compared;
          differ += !same(mine.flow(i), whole.flow(whole.vessel_index(v)));
        }
        for (std::size_t o = 0; o < t.net.outlets.size(); ++o)
          if (rank[static_cast<std::size_t>(t.net.outlets[o].vessel)] == r) {
            ++compared;
            differ += !same(mine.capacitor_pressure(o), whole.capacitor_pressure(o));
          }
      }
      ASSERT_EQ(differ, 0u) << ranks << " ranks, step " << n;
    }
    EXPECT_EQ(compared, t.net.node_count() + t.net.vessel_count() + t.net.outlets.size()) << ranks << " ranks";
    // The pressures moved: the inflow's pulse reached the leaves.
    EXPECT_NE(whole.node_pressure(whole.node_of(coupled)), pressure[static_cast<std::size_t>(coupled)]);
  }
}

// A step that fails on the top's rank between its halves (its 1D vessels) is abandoned there:
// every rank throws, none waits for a message that will not come.
TEST(LumpedCut, AStepAbandonedOnTheTopIsRefusedOnEveryRank) {
  const CutTree t;
  const int ranks = 3;
  const CutTree::Cut c = t.cut(ranks);
  const std::vector<double> pressure(t.net.node_count(), 3000.0), flow(t.net.vessel_count(), 0.0);
  PlayedLink played(ranks, c.top, c.cuts[0].roots);
  std::vector<LumpedVessels> part = t.ranks_started(c, played, pressure, flow);
  EXPECT_THROW(part[0].set_passes(2), std::invalid_argument);
  const std::vector<std::string> said = on_every_played_rank(part, [&](int r, LumpedVessels& mine) {
    mine.predict(1e-4, {}, std::vector<double>(mine.inflow_boundaries().size(), 1e-10), {});
    if (r == c.top) mine.abandon_step(std::make_exception_ptr(std::runtime_error("the 1D vessels failed")));
    mine.complete({});
  });
  for (int r = 0; r < ranks; ++r)
    EXPECT_NE(said[static_cast<std::size_t>(r)].find("the 1D vessels failed"), std::string::npos) << "rank " << r << ": " << said[static_cast<std::size_t>(r)];
}

// A lumen closing in a share (a leaf's node at a pressure no lumen holds) is refused on every
// rank in the words the share's caller gives it (PulseSolver: the vessel's id and the time).
TEST(LumpedCut, ALumenClosingInAShareIsSaidOnEveryRank) {
  const CutTree t;
  const int ranks = 3;
  const CutTree::Cut c = t.cut(ranks);
  const std::vector<std::int32_t>& rank = c.rank;
  std::vector<double> pressure(t.net.node_count(), 3000.0), flow(t.net.vessel_count(), 0.0);
  std::size_t leaf = 0;  // an outlet's vessel on a share
  for (const Outlet& o : t.net.outlets)
    if (rank[static_cast<std::size_t>(o.vessel)] != c.top) leaf = static_cast<std::size_t>(o.vessel);
  pressure[static_cast<std::size_t>(t.net.to[leaf])] = -1e9;
  PlayedLink played(ranks, c.top, c.cuts[0].roots);
  std::vector<LumpedVessels> part = t.ranks_started(c, played, pressure, flow);
  for (LumpedVessels& mine : part)
    mine.set_failure_words([](std::exception_ptr failure) {
      try {
        std::rethrow_exception(failure);
      } catch (const LumpedVessels::CollapsedNode& c) {
        return std::make_exception_ptr(std::runtime_error("the lumen of vessel " + std::to_string(c.vessel) + " closes"));
      } catch (...) {
        return failure;
      }
    });
  const std::vector<std::string> said = on_every_played_rank(part, [&](int, LumpedVessels& mine) {
    mine.predict(1e-4, {}, std::vector<double>(mine.inflow_boundaries().size(), 1e-10), {});
    mine.complete({});
  });
  const std::string words = "rank " + std::to_string(rank[leaf]) + ": the lumen of vessel " + std::to_string(leaf) + " closes";
  for (int r = 0; r < ranks; ++r) EXPECT_NE(said[static_cast<std::size_t>(r)].find(words), std::string::npos) << said[static_cast<std::size_t>(r)];
}
