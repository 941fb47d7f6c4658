// A 0D system with loops spread over ranks (pulse/lumped_halo.hpp), every rank played here by
// a thread of one process: which vessels and nodes each rank holds, and that its arithmetic is
// the one-process run's. The played link solves every rank's rows gathered into the whole
// run's system with the whole run's own NodalSystem, so each rank's node pressures, vessel
// flows and capacitors must be the one-process run's bits step after step (over MPI the solve
// is PETSc's, to 1e-10: tests/cli/mpi.sh); a lumen closing on one rank is said on every rank.
#include <algorithm>
#include <array>
#include <barrier>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "network_flow/nodal_system.hpp"
#include "partition/partition.hpp"
#include "physics/viscosity_table.hpp"
#include "pulse/lumped_halo.hpp"
#include "pulse/lumped_vessels.hpp"
#include "tests/played_ranks.hpp"
#include "pulse/network_boundaries.hpp"
#include "steady/vessel_laws.hpp"
#include "tests/network_builders.hpp"

using namespace hemotree;
using namespace hemotree::test_networks;

namespace {

bool same(double a, double b) { return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b); }

// A mesh of side x side nodes joined by 0D vessels (200 um, 20 um across), fed at one corner
// through a lead vessel by a pulsatile flow, drained through lead vessels from the other
// corners to a held pressure, an RCR outlet and a resistance.
struct Mesh {
  Network net;
  Blood blood;
  std::vector<TubeLaw> laws;
  ViscosityTable viscosity;
  std::vector<bool> all;
  LumpedOrder whole_order;
  static Network build(int side) {
    Network net;
    for (int k = 0; k < side * side + 4; ++k) net.add_node(k);
    auto add = [&](int a, int b) {
      net.add_vessel(static_cast<std::int64_t>(net.vessel_count()), a, b, 2e-4, 20e-6, 2e-6, 1e6, 0);
    };
    for (int j = 0; j < side; ++j)
      for (int i = 0; i < side; ++i) {
        const int k = j * side + i;
        if (i + 1 < side) add(k, k + 1);
        if (j + 1 < side) add(k, k + side);
      }
    const int n = side * side;
    add(n, 0);                      // the inflow's lead
    add(side - 1, n + 1);           // to the held pressure
    add(n - 1, n + 2);              // to the RCR outlet
    add(n - side, n + 3);           // to the resistance
    const double t = 0.05;
    net.boundaries = {flow_boundary(n, tabulate([&](double s) { return 2e-10 * (1 + 0.5 * std::sin(2 * M_PI * s / t)); }, t, 41, t)),
                      pressure_boundary(n + 1, 1500.0), outlet_boundary(n + 2, rcr_outlet(-1, 2e11, 1e-15, 6e11, 1300.0)),
                      outlet_boundary(n + 3, resistance_outlet(-1, 8e11, 1200.0))};
    net.blood = newtonian(3.5e-3);
    return net;
  }
  explicit Mesh(int side)
      : net(build(side)), blood(*net.blood), laws(vessel_laws(net, blood, 0.0, 0.1)), viscosity(blood),
        all(net.vessel_count(), true), whole_order(subtree_lumped_order(net, all)) {}
  LumpedVessels lumped(const LumpedHalo* halo = nullptr) const {
    return LumpedVessels(net, laws, viscosity, blood, all, {}, {}, {}, nullptr, halo);
  }
};

// The link between P played ranks: every rank's rows into the whole run's system, solved as
// the whole run solves its own (the same NodalSystem, factorisation and halves).
class PlayedHalo {
 public:
  PlayedHalo(const Network& net, const LumpedVessels& whole, int ranks)
      : meet_(ranks), system_(whole.node_count(), {whole.edge_a().begin(), whole.edge_a().end()},
                              {whole.edge_b().begin(), whole.edge_b().end()}),
        key_(ranks), keys_(ranks), sums_(ranks), conductance_(whole.edge_a().size()), shunt_(whole.node_count()),
        rhs_(whole.node_count()),
        x_(whole.node_count()), values_(whole.node_count()) {
    // The whole's node of each key: a network node's, then each outlet's capacitor.
    for (std::size_t n = 0; n < net.node_count(); ++n) whole_node_[static_cast<std::int64_t>(n)] = whole.node_of(static_cast<std::int64_t>(n));
    std::int32_t capacitor = 0;
    const RunBoundaries run(net);
    std::int64_t outlet = 0;
    for (std::size_t i = 0; i < run.size(); ++i) {
      if (!run.is_outlet(i)) continue;
      if (!std::isnan(whole.capacitor_pressure(static_cast<std::size_t>(outlet))))
        whole_node_[static_cast<std::int64_t>(net.node_count()) + outlet] = static_cast<std::int32_t>(whole.network_node_count()) + capacitor++;
      ++outlet;
    }
    for (std::size_t e = 0; e < whole.edge_a().size(); ++e)
      whole_edge_[std::minmax(whole.edge_a()[e], whole.edge_b()[e])] = static_cast<std::int32_t>(e);
  }
  LumpedHaloLink for_rank(int rank, const LumpedHaloSystem& s) {
    keys_[static_cast<std::size_t>(rank)] = s;
    LumpedHaloLink link;
    link.least = [this, rank](std::int64_t key) {
      key_[static_cast<std::size_t>(rank)] = key;
      meet_.arrive_and_wait();
      const std::int64_t least = *std::min_element(key_.begin(), key_.end());
      meet_.arrive_and_wait();
      return least;
    };
    link.solve = [this, rank](std::span<const double> conductance, std::span<const double> shunt,
                              std::span<const double> rhs, std::span<double> x) {
      const LumpedHaloSystem& s = keys_[static_cast<std::size_t>(rank)];
      for (std::size_t k = 0; k < s.node_key.size(); ++k)
        if (owns(rank, s, k)) {
          shunt_[node(s, k)] = shunt[k];
          rhs_[node(s, k)] = rhs[k];
        }
      for (std::size_t e = 0; e < s.a.size(); ++e)  // each edge by the owner of its lower key's end
        if (const std::size_t k = static_cast<std::size_t>(s.node_key[s.a[e]] < s.node_key[s.b[e]] ? s.a[e] : s.b[e]); owns(rank, s, k))
          conductance_[edge(s, e)] = conductance[e];
      meet_.arrive_and_wait();
      if (rank == 0) {  // the system's workspace is its own (made at first use): one thread's
        std::copy(shunt_.begin(), shunt_.end(), system_.shunt_workspace().begin());
        x_ = rhs_;
        ASSERT_LT(system_.factorize_forward_in_place(conductance_, x_), 0);
        system_.backward(x_, x_);
      }
      meet_.arrive_and_wait();
      for (std::size_t k = 0; k < s.node_key.size(); ++k) x[k] = x_[node(s, k)];
      meet_.arrive_and_wait();
    };
    link.solve_again = [this, rank](std::span<const double> rhs, std::span<double> x) {
      const LumpedHaloSystem& s = keys_[static_cast<std::size_t>(rank)];
      for (std::size_t k = 0; k < s.node_key.size(); ++k)
        if (owns(rank, s, k)) rhs_[node(s, k)] = rhs[k];
      meet_.arrive_and_wait();
      if (rank == 0) system_.solve(rhs_, x_);
      meet_.arrive_and_wait();
      for (std::size_t k = 0; k < s.node_key.size(); ++k) x[k] = x_[node(s, k)];
      meet_.arrive_and_wait();
    };
    link.sum = [this, rank](std::span<double> values) {
      sums_[static_cast<std::size_t>(rank)].assign(values.begin(), values.end());
      meet_.arrive_and_wait();
      for (std::size_t i = 0; i < values.size(); ++i) {
        values[i] = 0;
        for (const auto& one : sums_) values[i] += one[i];
      }
      meet_.arrive_and_wait();
    };
    link.fill_ghosts = [this, rank](std::span<double> values) {
      const LumpedHaloSystem& s = keys_[static_cast<std::size_t>(rank)];
      for (std::size_t k = 0; k < s.node_key.size(); ++k)
        if (owns(rank, s, k)) values_[node(s, k)] = values[k];
      meet_.arrive_and_wait();
      for (std::size_t k = 0; k < s.node_key.size(); ++k)
        if (!owns(rank, s, k)) values[k] = values_[node(s, k)];
      meet_.arrive_and_wait();
    };
    return link;
  }

 private:
  std::barrier<> meet_;
  NodalSystem system_;
  std::vector<std::int64_t> key_;
  std::vector<LumpedHaloSystem> keys_;
  std::vector<std::vector<double>> sums_;
  std::map<std::int64_t, std::int32_t> whole_node_;
  std::map<std::pair<std::int32_t, std::int32_t>, std::int32_t> whole_edge_;
  std::vector<double> conductance_, shunt_, rhs_, x_, values_;
  static bool owns(int rank, const LumpedHaloSystem& s, std::size_t k) {
    return s.key_rank[static_cast<std::size_t>(s.node_key[k])] == rank;
  }
  std::size_t node(const LumpedHaloSystem& s, std::size_t k) const {
    return static_cast<std::size_t>(whole_node_.at(s.node_key[k]));
  }
  std::size_t edge(const LumpedHaloSystem& s, std::size_t e) const {
    const auto a = static_cast<std::int32_t>(node(s, static_cast<std::size_t>(s.a[e])));
    const auto b = static_cast<std::int32_t>(node(s, static_cast<std::size_t>(s.b[e])));
    return static_cast<std::size_t>(whole_edge_.at(std::minmax(a, b)));
  }
};

std::vector<std::int32_t> ranks_by_metis(const Network& net, int ranks) {
  const Partition p = partition_network(net, std::vector<double>(net.vessel_count(), 1.0), ranks);
  EXPECT_EQ(p.method, Partition::Method::metis);
  return {p.rank_of_vessel.begin(), p.rank_of_vessel.end()};
}

// Every played rank's vessels by METIS, linked through `played`, started at the given state.
std::vector<LumpedVessels> ranks_started(const Mesh& m, int ranks, PlayedHalo& played, const std::vector<double>& pressure,
                                         const std::vector<double>& flow) {
  const std::vector<std::int32_t> rank = ranks_by_metis(m.net, ranks);
  std::vector<LumpedVessels> part;
  for (int r = 0; r < ranks; ++r) {
    const LumpedHalo halo = lumped_halo(m.net, m.whole_order, rank, ranks, r);
    part.push_back(m.lumped(&halo));
    EXPECT_TRUE(part.back().halo());
    part.back().set_halo_link(played.for_rank(r, part.back().halo_system()));
    part.back().start(pressure, flow);
  }
  return part;
}

}  // namespace

// On a square of four vessels (0-1, 1-2, 2-3, 3-0) with ranks 0, 0, 1, 1: each node goes with
// its first vessel's rank; a rank holds the other rank's vessels at its nodes as a halo, and
// the far ends of its vessels that it does not own as ghosts.
TEST(LumpedHalo, EachRankHoldsItsVesselsAndTheOthersAtItsNodes) {
  Network net;
  for (int k = 0; k < 4; ++k) net.add_node(k);
  for (int v = 0; v < 4; ++v) net.add_vessel(v, v, (v + 1) % 4, 2e-4, 20e-6, 2e-6, 1e6, 0);
  const std::vector<bool> all(4, true);
  const LumpedOrder whole = network_lumped_order(net, all);
  const std::vector<std::int32_t> rank = {0, 0, 1, 1};
  EXPECT_EQ(lumped_node_ranks(net, whole, rank), (std::vector<std::int32_t>{0, 0, 0, 1}));  // node 2: vessel 1's first
  const LumpedHalo zero = lumped_halo(net, whole, rank, 2, 0), one = lumped_halo(net, whole, rank, 2, 1);
  // Rank 0 owns nodes 0, 1, 2: vessel 2 (2-3) and vessel 3 (3-0) reach them; node 3 is its ghost.
  EXPECT_EQ(zero.order.vessels, (std::vector<std::int32_t>{0, 1, 2, 3}));
  EXPECT_EQ(zero.halo_vessels, (std::vector<std::int32_t>{2, 3}));
  EXPECT_EQ(zero.ghost_nodes, (std::vector<std::int32_t>{3}));
  // Rank 1 owns node 3 alone: its own vessels, no halo; nodes 0 and 2 are ghosts.
  EXPECT_EQ(one.order.vessels, (std::vector<std::int32_t>{2, 3}));
  EXPECT_TRUE(one.halo_vessels.empty());
  EXPECT_EQ(one.ghost_nodes, (std::vector<std::int32_t>{0, 2}));  // in the whole's order
  EXPECT_THROW(lumped_halo(net, whole, std::vector<std::int32_t>{0, 0, 2, 1}, 2, 0), std::invalid_argument);
}

// The square with a diagonal, vessel 4 (0-2), on rank 1: rank 0 owns both its nodes (vessels 0
// and 1 come first there), so it moves to rank 0, its `from` node's owner, and no node's owner
// changes. On a third rank of its own it stays: a rank is not emptied.
TEST(LumpedHalo, AVesselGoesWhereOneOfItsNodesIsOwned) {
  Network net;
  for (int k = 0; k < 4; ++k) net.add_node(k);
  for (int v = 0; v < 4; ++v) net.add_vessel(v, v, (v + 1) % 4, 2e-4, 20e-6, 2e-6, 1e6, 0);
  net.add_vessel(4, 0, 2, 2e-4, 20e-6, 2e-6, 1e6, 0);
  const LumpedOrder whole = network_lumped_order(net, std::vector<bool>(5, true));
  std::vector<std::int32_t> rank = {0, 0, 1, 1, 1};
  const std::vector<std::int32_t> owners = lumped_node_ranks(net, whole, rank);
  EXPECT_EQ(hold_at_an_own_node(net, whole, rank, 2), 1u);
  EXPECT_EQ(rank, (std::vector<std::int32_t>{0, 0, 1, 1, 0}));
  EXPECT_EQ(lumped_node_ranks(net, whole, rank), owners);
  EXPECT_EQ(hold_at_an_own_node(net, whole, rank, 2), 0u);  // nothing left to move
  std::vector<std::int32_t> alone = {0, 0, 1, 1, 2};
  EXPECT_EQ(hold_at_an_own_node(net, whole, alone, 3), 0u);
  EXPECT_EQ(alone[4], 2);
}

// Steps of the whole and of every played rank side by side, a pulsatile inflow, a held
// pressure, an RCR and a resistance outlet: after every step each rank's own nodes, vessels and
// capacitors are the whole's bits.
TEST(LumpedHalo, EveryRankStepsToTheWholeRunsBits) {
  const Mesh m(9);
  const std::size_t n = m.net.vessel_count();
  std::vector<double> pressure(m.net.node_count()), flow(n, 0.0);
  for (std::size_t i = 0; i < pressure.size(); ++i) pressure[i] = 1600.0 - 0.7 * static_cast<double>(i % 37);
  const RunBoundaries run(m.net);
  auto inflows = [&](const LumpedVessels& l, double t) {
    std::vector<double> q;
    for (const std::int32_t b : l.inflow_boundaries()) q.push_back(run.waveform(static_cast<std::size_t>(b))(t));
    return q;
  };
  auto held = [&](const LumpedVessels& l, double t) {
    std::vector<double> p;
    for (const std::int32_t b : l.held_boundaries()) p.push_back(run.waveform(static_cast<std::size_t>(b))(t));
    return p;
  };
  for (const int ranks : {2, 3, 4}) {
    SCOPED_TRACE(std::to_string(ranks) + " ranks");
    LumpedVessels reference = m.lumped();
    reference.start(pressure, flow);
    PlayedHalo played(m.net, reference, ranks);
    std::vector<LumpedVessels> part = ranks_started(m, ranks, played, pressure, flow);
    EXPECT_THROW(part[0].set_passes(2), std::invalid_argument);
    const double dt = 1e-3 * 0.05;
    std::size_t compared = 0, differ = 0;
    for (int step = 0; step < 60; ++step) {
      const double t1 = dt * (step + 1);
      reference.predict(dt, {}, inflows(reference, t1), held(reference, t1));
      reference.complete({});
      const std::vector<std::string> said = on_every_played_rank(part, [&](int, LumpedVessels& mine) {
        mine.predict(dt, {}, inflows(mine, t1), held(mine, t1));
        mine.complete({});
      });
      for (int r = 0; r < ranks; ++r) ASSERT_EQ(said[static_cast<std::size_t>(r)], "") << "rank " << r;
      compared = 0;
      for (int r = 0; r < ranks; ++r) {
        const LumpedVessels& mine = part[static_cast<std::size_t>(r)];
        for (std::size_t node = 0; node < m.net.node_count(); ++node) {
          const std::int32_t k = mine.node_of(static_cast<std::int64_t>(node));
          if (k < 0) continue;
          // A ghost holds its owner's pressure too (its vessels' lines read it).
          differ += !same(mine.node_pressure(k), reference.node_pressure(reference.node_of(static_cast<std::int64_t>(node))));
          compared += mine.ghost_node(k) ? 0 : 1;
        }
        for (std::size_t v = 0; v < n; ++v) {
          const std::int32_t i = mine.vessel_index(v);
          if (i < 0) continue;
          differ += !same(mine.flow(i), reference.flow(reference.vessel_index(v)));
          compared += mine.ghost_vessel(i) ? 0 : 1;
        }
        for (std::size_t o = 0; o < 2; ++o)
          if (!std::isnan(mine.capacitor_pressure(o))) {
            ++compared;
            differ += !same(mine.capacitor_pressure(o), reference.capacitor_pressure(o));
          }
      }
      ASSERT_EQ(differ, 0u) << "step " << step;
    }
    // Every node, vessel and the capacitor held by exactly one rank; the pulse moved the mesh.
    EXPECT_EQ(compared, m.net.node_count() + n + 1);
    EXPECT_NE(reference.node_pressure(reference.node_of(0)), pressure[0]);
  }
}

// A coupling node (a 1D end's: its held inflow, departure and volume made up here, the same for
// both): each rank its part of the node's response K^-1 e (in place of the whole's selected
// inversion and partial solves), the owner its prediction and impedance, every rank its
// pressures moved by the departures. Rounding apart from the whole's: within 1e-12.
TEST(LumpedHalo, ACouplingNodeStepsToTheWholeRunsNumbers) {
  const Mesh m(9);
  const std::int32_t coupled = 40;  // inside the mesh
  std::vector<double> pressure(m.net.node_count(), 1500.0), flow(m.net.vessel_count(), 0.0);
  const RunBoundaries run(m.net);
  auto values = [&](const std::vector<std::int32_t>& boundaries, double t) {
    std::vector<double> v;
    for (const std::int32_t b : boundaries) v.push_back(run.waveform(static_cast<std::size_t>(b))(t));
    return v;
  };
  for (const int ranks : {2, 3}) {
    SCOPED_TRACE(std::to_string(ranks) + " ranks");
    LumpedVessels reference = m.lumped();
    reference.start(pressure, flow);
    reference.set_coupling_nodes({reference.node_of(coupled)});
    PlayedHalo played(m.net, reference, ranks);
    std::vector<LumpedVessels> part = ranks_started(m, ranks, played, pressure, flow);
    int owner = -1;
    for (int r = 0; r < ranks; ++r) {
      LumpedVessels& mine = part[static_cast<std::size_t>(r)];
      const std::int32_t k = mine.node_of(coupled);
      const bool own = k >= 0 && !mine.ghost_node(k);
      if (own) owner = r;
      if (k >= 0 && !own) {  // a ghost: its owner's coupling node
        EXPECT_THROW(mine.set_coupling_nodes({k}), std::invalid_argument);
      }
      mine.set_coupling_nodes(own ? std::vector<std::int32_t>{k} : std::vector<std::int32_t>{});
      mine.set_halo_coupling(std::vector<std::int64_t>{coupled});
    }
    ASSERT_GE(owner, 0);
    const double dt = 5e-5;
    double worst = 0, scale = 0;
    for (int step = 0; step < 60; ++step) {
      const double t1 = dt * (step + 1);
      const double held = 3e-11 * (1 + std::sin(2 * M_PI * t1 / 0.01)), again = 1.1 * held, volume = 0.9 * dt * again;
      reference.predict(dt, std::vector<double>{held}, values(reference.inflow_boundaries(), t1),
                        values(reference.held_boundaries(), t1));
      const double impedance = reference.impedance(0);
      reference.predict_again(std::vector<double>{again});
      const double predicted = reference.pressure_during_step(0, 1.0);
      reference.complete(std::vector<double>{volume});
      std::array<double, 2> owners{};
      const std::vector<std::string> said = on_every_played_rank(part, [&](int r, LumpedVessels& mine) {
        const bool own = r == owner;
        mine.predict(dt, own ? std::vector<double>{held} : std::vector<double>{}, values(mine.inflow_boundaries(), t1),
                     values(mine.held_boundaries(), t1));
        if (own) owners[0] = mine.impedance(0);
        mine.predict_again(own ? std::vector<double>{again} : std::vector<double>{});
        if (own) owners[1] = mine.pressure_during_step(0, 1.0);
        mine.complete(own ? std::vector<double>{volume} : std::vector<double>{});
      });
      for (int r = 0; r < ranks; ++r) ASSERT_EQ(said[static_cast<std::size_t>(r)], "") << "rank " << r;
      ASSERT_NEAR(owners[0], impedance, 1e-12 * std::abs(impedance)) << "step " << step;
      ASSERT_NEAR(owners[1], predicted, 1e-12 * std::abs(predicted)) << "step " << step;
      for (int r = 0; r < ranks; ++r) {
        const LumpedVessels& mine = part[static_cast<std::size_t>(r)];
        for (std::size_t node = 0; node < m.net.node_count(); ++node) {
          const std::int32_t k = mine.node_of(static_cast<std::int64_t>(node));
          if (k < 0) continue;
          const double whole = reference.node_pressure(reference.node_of(static_cast<std::int64_t>(node)));
          worst = std::max(worst, std::abs(mine.node_pressure(k) - whole));
          scale = std::max(scale, std::abs(whole));
        }
      }
    }
    EXPECT_LE(worst, 1e-12 * scale);
    // The coupled end moved its node: its pressure is not the start's.
    EXPECT_GT(std::abs(reference.node_pressure(reference.node_of(coupled)) - 1500.0), 1e-3);
  }
}

// A lumen closing on one rank (a node at a pressure no lumen holds) is said on every rank, the
// same vessel, before the solve every rank must enter.
TEST(LumpedHalo, ALumenClosingOnOneRankIsSaidOnEveryRank) {
  const Mesh m(6);
  const int ranks = 3;
  std::vector<double> pressure(m.net.node_count(), 1500.0), flow(m.net.vessel_count(), 0.0);
  pressure[14] = -1e9;
  LumpedVessels reference = m.lumped();
  reference.start(pressure, flow);
  std::int64_t closing = -1;
  try {
    reference.predict(1e-5, {}, std::vector<double>(reference.inflow_boundaries().size(), 1e-10),
                      std::vector<double>(reference.held_boundaries().size(), 1500.0));
  } catch (const LumpedVessels::CollapsedNode& c) {
    closing = c.vessel;
  }
  ASSERT_GE(closing, 0);
  PlayedHalo played(m.net, reference, ranks);
  std::vector<LumpedVessels> part = ranks_started(m, ranks, played, pressure, flow);
  const std::vector<std::string> said = on_every_played_rank(part, [&](int, LumpedVessels& mine) {
    mine.predict(1e-5, {}, std::vector<double>(mine.inflow_boundaries().size(), 1e-10),
                 std::vector<double>(mine.held_boundaries().size(), 1500.0));
  });
  for (int r = 0; r < ranks; ++r) EXPECT_EQ(said[static_cast<std::size_t>(r)], "collapsed at vessel " + std::to_string(closing));
}
