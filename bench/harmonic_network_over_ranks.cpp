// One harmonic's nodal system of a looped network over MPI ranks (issue 24: a distributed
// solver for graphs with loops, chosen by measurement): a side x side mesh of lines, each a
// capillary's two-port at a harmonic (series 1 / (R + i w L), half of i w C at each end),
// outlets' admittances to ground along one edge of the mesh, a current into one corner.
// Rank 0 prints the method (PETSC_OPTIONS may choose another), the seconds of the distributed
// solve (median of 5, set-up included, as each harmonic of a run pays it), the one-process
// sparse solve's seconds (network_flow/harmonic_system), and how far apart they are.
//
// usage: mpirun -np P build/bench/harmonic_network_over_ranks SIDE [HARMONIC]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>

#include <mpi.h>

#include "distributed/petsc_harmonic_network.hpp"
#include "mpi/session.hpp"
#include "network_flow/harmonic_system.hpp"

using namespace hemotree;

namespace {
double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}
double median(std::vector<double> x) {
  std::sort(x.begin(), x.end());
  return x[x.size() / 2];
}
}  // namespace

int main(int argc, char** argv) {
  MpiSession session(argc, argv);
  if (argc < 2) {
    if (world_rank() == 0) std::fprintf(stderr, "usage: mpirun -np P harmonic_network_over_ranks SIDE [HARMONIC]\n");
    return 2;
  }
  const int side = std::atoi(argv[1]), harmonic = argc > 2 ? std::atoi(argv[2]) : 1;
  const int ranks = world_size(), rank = world_rank();
  const std::size_t nodes = static_cast<std::size_t>(side) * static_cast<std::size_t>(side);
  std::vector<std::int32_t> a, b;
  for (int r = 0; r < side; ++r)
    for (int c = 0; c < side; ++c) {
      const int k = r * side + c;
      if (c + 1 < side) a.push_back(k), b.push_back(k + 1);
      if (r + 1 < side) a.push_back(k), b.push_back(k + side);
    }
  std::mt19937_64 random(11);
  std::uniform_real_distribution<double> unit(0, 1);
  const double w = 2 * M_PI * harmonic;  // a 1 s period
  std::vector<TwoPort> edge(a.size());
  for (TwoPort& e : edge) {
    // A capillary of 5 to 10 um and 0.5 mm: R ~ 1e13 to 1e14 Pa s/m^3, C ~ 1e-19 m^3/Pa.
    const double r = 1e13 * (1 + 9 * unit(random)), l = 1e6 * unit(random), c = 1e-19 * (1 + unit(random));
    const Complex y = 1.0 / Complex(r, w * l), half = Complex(0, 0.5 * w * c);
    e = {y + half, -y, -y, y + half};
  }
  std::vector<Complex> shunt(nodes, Complex{}), current(nodes, Complex{});
  for (int c = 0; c < side; ++c) shunt[static_cast<std::size_t>((side - 1) * side + c)] = 1.0 / Complex(1e12, 0);
  current[0] = Complex(1e-12, 0);
  std::vector<std::int32_t> node_owner(nodes), edge_owner(a.size());
  for (std::size_t i = 0; i < nodes; ++i) node_owner[i] = static_cast<std::int32_t>((i / static_cast<std::size_t>(side)) * static_cast<std::size_t>(ranks) / static_cast<std::size_t>(side));
  for (std::size_t e = 0; e < a.size(); ++e) edge_owner[e] = node_owner[static_cast<std::size_t>(a[e])];

  PetscHarmonicNetwork system(nodes, a, b, node_owner, edge_owner);
  std::vector<Complex> got(nodes);
  std::vector<double> times;
  for (int k = 0; k < 5; ++k) {
    MPI_Barrier(MPI_COMM_WORLD);
    const auto t = std::chrono::steady_clock::now();
    system.solve(edge, shunt, current, got);
    times.push_back(seconds_since(t));
  }
  if (rank == 0) {
    const HarmonicSystem whole(nodes, a, b);
    std::vector<double> alone;
    std::vector<Complex> expected;
    for (int k = 0; k < 3; ++k) {
      const auto t = std::chrono::steady_clock::now();
      expected = whole.solve(edge, shunt, current);
      alone.push_back(seconds_since(t));
    }
    double worst = 0, scale = 0;
    for (const Complex& x : expected) scale = std::max(scale, std::abs(x));
    for (std::size_t i = 0; i < nodes; ++i) worst = std::max(worst, std::abs(got[i] - expected[i]) / scale);
    std::printf("%zu nodes, harmonic %d, %d ranks, %s: %.4f s (%d iterations); one process, sparse LDLT: %.4f s; apart %.2g\n",
                nodes, harmonic, ranks, system.method().c_str(), median(times), system.iterations(), median(alone), worst);
  }
  return 0;
}
