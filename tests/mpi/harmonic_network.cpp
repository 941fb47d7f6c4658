// Under mpirun (ctest label mpi, 1 to 4 ranks): one harmonic's nodal system of a grid with
// loops everywhere (distributed/petsc_harmonic_network.hpp: the complex system as real 2 x 2
// blocks, LU by MUMPS) gives on every rank the one-process HarmonicSystem's potentials to
// 1e-10 relative (the figure for looped networks): each edge a line's two-port (a
// series admittance and half a shunt admittance at each end, some with a flow's asymmetry,
// ab != ba), admittances to ground at a few nodes, currents at others; the nodes in stripes of
// ranks, the edges dealt round the ranks (so that most land on another rank's rows). A grid
// with a part that has no path to ground is refused on every rank alike. Exit 0 when every
// rank agrees.
#include <cmath>
#include <complex>
#include <cstdint>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include <mpi.h>

#include "core/errors.hpp"
#include "distributed/petsc_harmonic_network.hpp"
#include "mpi/session.hpp"
#include "network_flow/harmonic_system.hpp"
#include "tests/mpi/rank_checks.hpp"

using namespace hemotree;
using rank_checks::check;

namespace {

struct Grid {
  std::size_t nodes = 0;
  std::vector<std::int32_t> a, b;
};

// side x side nodes, each joined to its right and lower neighbours; a second grid beside it
// where `twice`.
Grid grid(int side, bool twice) {
  Grid g;
  const int copies = twice ? 2 : 1;
  g.nodes = static_cast<std::size_t>(copies * side * side);
  for (int copy = 0; copy < copies; ++copy)
    for (int r = 0; r < side; ++r)
      for (int c = 0; c < side; ++c) {
        const int k = copy * side * side + r * side + c;
        if (c + 1 < side) g.a.push_back(k), g.b.push_back(k + 1);
        if (r + 1 < side) g.a.push_back(k), g.b.push_back(k + side);
      }
  return g;
}

}  // namespace

int main(int argc, char** argv) {
  int failures = 0;
  {
    MpiSession session(argc, argv);
    const int ranks = world_size(), rank = world_rank();
    rank_checks::rank = rank;
    constexpr int side = 40;
    const Grid g = grid(side, false);
    std::mt19937_64 random(7);
    std::uniform_real_distribution<double> unit(0, 1);
    // A vessel's line at the first harmonic: series admittance 1 / (R + i w L), shunt i w C.
    std::vector<TwoPort> edge(g.a.size());
    for (std::size_t e = 0; e < edge.size(); ++e) {
      const double r = std::pow(10.0, 8 + 3 * unit(random)), l = r * 1e-3 * unit(random), c = 1e-12 * unit(random);
      const Complex y = 1.0 / Complex(r, 2 * M_PI * l), half = Complex(0, M_PI * c);
      const double skew = e % 5 == 0 ? 0.1 * unit(random) : 0.0;  // a mean flow's asymmetry
      edge[e] = {y + half, -y * (1 + skew), -y * (1 - skew), y + half};
    }
    std::vector<Complex> shunt(g.nodes, Complex{}), current(g.nodes, Complex{});
    for (std::size_t i = 0; i < g.nodes; i += 97) shunt[i] = 1.0 / Complex(1e9 * (1 + unit(random)), 1e8 * unit(random));
    for (std::size_t i = 3; i < g.nodes; i += 31) current[i] = Complex(1e-7 * (unit(random) - 0.5), 1e-7 * (unit(random) - 0.5));
    const HarmonicSystem whole(g.nodes, g.a, g.b);
    const std::vector<Complex> expected = whole.solve(edge, shunt, current);

    std::vector<std::int32_t> node_owner(g.nodes), edge_owner(g.a.size());
    for (std::size_t i = 0; i < g.nodes; ++i) node_owner[i] = static_cast<std::int32_t>((i / side) * ranks / side);  // stripes
    for (std::size_t e = 0; e < edge_owner.size(); ++e) edge_owner[e] = static_cast<std::int32_t>(e % static_cast<std::size_t>(ranks));
    PetscHarmonicNetwork system(g.nodes, g.a, g.b, node_owner, edge_owner);
    std::vector<Complex> got(g.nodes);
    system.solve(edge, shunt, current, got);
    double worst = 0, scale = 0;
    for (const Complex& x : expected) scale = std::max(scale, std::abs(x));
    for (std::size_t i = 0; i < g.nodes; ++i) worst = std::max(worst, std::abs(got[i] - expected[i]) / scale);
    check(scale > 0 && worst <= 1e-10, "potentials off by " + std::to_string(worst) + " relative (" + system.method() + ")");
    // The same system again at the third harmonic (its pattern, MUMPS's analysis kept; other
    // values, shunts where there were none): as the one-process solve of those.
    for (TwoPort& p : edge) {
      const Complex y = -p.ab;  // as above, the series part: 1 / (R + i w L) -> 1 / (R + 3 i w L)
      const Complex y3 = 1.0 / Complex((1.0 / y).real(), 3 * (1.0 / y).imag());
      const Complex half3 = 3.0 * (p.aa - y);
      p = {y3 + half3, p.ab / y * y3, p.ba / y * y3, y3 + half3};
    }
    for (std::size_t i = 1; i < g.nodes; i += 89) shunt[i] = Complex(0, 3e-12);
    const std::vector<Complex> expected3 = whole.solve(edge, shunt, current);
    system.solve(edge, shunt, current, got);
    double worst3 = 0, scale3 = 0;
    for (const Complex& x : expected3) scale3 = std::max(scale3, std::abs(x));
    for (std::size_t i = 0; i < g.nodes; ++i) worst3 = std::max(worst3, std::abs(got[i] - expected3[i]) / scale3);
    check(scale3 > 0 && worst3 <= 1e-10, "a second solve off by " + std::to_string(worst3) + " relative");

    // A second grid beside it of series branches alone, with no admittance to ground: its
    // system is singular.
    const Grid two = grid(side, true);
    std::vector<TwoPort> edges2(two.a.size());
    for (std::size_t e = 0; e < edges2.size(); ++e)  // the second grid's: series branches alone, no path to ground
      edges2[e] = e < edge.size() ? edge[e] : TwoPort::series(-edge[e % edge.size()].ab);
    std::vector<Complex> shunt2(two.nodes, Complex{}), current2(two.nodes, Complex{}), got2(two.nodes);
    for (std::size_t i = 0; i < g.nodes; ++i) shunt2[i] = shunt[i], current2[i] = current[i];
    std::vector<std::int32_t> owner2(two.nodes), edge_owner2(two.a.size());
    for (std::size_t i = 0; i < two.nodes; ++i) owner2[i] = static_cast<std::int32_t>(i * static_cast<std::size_t>(ranks) / two.nodes);
    for (std::size_t e = 0; e < edge_owner2.size(); ++e) edge_owner2[e] = static_cast<std::int32_t>(e % static_cast<std::size_t>(ranks));
    PetscHarmonicNetwork singular(two.nodes, two.a, two.b, owner2, edge_owner2);
    bool refused = false;
    try {
      singular.solve(edges2, shunt2, current2, got2);
    } catch (const Collective<InputError>& e) {
      refused = std::string(e.what()).find("no path to an outlet") != std::string::npos;
    }
    check(refused, "a part without a path to ground not refused as an InputError on this rank");
    // After the refusal the same object starts afresh: grounded at every node, it solves.
    for (std::size_t i = 0; i < two.nodes; ++i) shunt2[i] += Complex(1e-9, 0);
    bool solved = true;
    try {
      singular.solve(edges2, shunt2, current2, got2);
    } catch (const std::exception&) {
      solved = false;
    }
    check(solved, "a system refused once did not solve when grounded");
    failures = rank_checks::all_failures();
    if (rank == 0 && failures == 0)
      std::printf("%d ranks: within %.2g of the one-process solve (%s)\n", ranks, worst, system.method().c_str());
  }
  return failures == 0 ? 0 : 1;
}
