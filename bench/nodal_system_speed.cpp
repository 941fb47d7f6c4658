// Speed of the nodal system (network_flow/nodal_system.hpp) on a random binary tree of N
// nodes: the weighted Laplacian of vessel-like conductances plus a C/dt shunt at every node
// (an implicit step of compliant 0D vessels). Times, medians of 5: the analysis (once per
// graph: the elimination order, or the pattern, AMD ordering and symbolic factorisation),
// factorize and solve, for the tree elimination and the sparse Cholesky, and the largest
// difference between their solutions relative to the largest potential. Then the diagonal
// of the inverse (inverse_diagonal): of every node (the elimination only), of 10,000 nodes
// drawn at random and of 100 of them (both), and the largest relative difference between the
// methods over the 10,000.
// usage: nodal_system_speed [N (3800000)] [--shuffled]
//   The nodes are numbered breadth first from the root, as vgen numbers its trees (every
//   sweep of the elimination then streams through memory); --shuffled: at random (the
//   elimination peels leaves to find its order, and every sweep gathers).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <numeric>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "network_flow/nodal_system.hpp"

using namespace hemotree;
using Method = NodalSystem::Method;

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

template <class F>
double median_of_5(F&& f) {
  std::vector<double> t;
  for (int run = 0; run < 5; ++run) {
    const auto start = std::chrono::steady_clock::now();
    f();
    t.push_back(seconds_since(start));
  }
  std::sort(t.begin(), t.end());
  return t[2];
}

}  // namespace

int main(int argc, char** argv) {
  std::size_t n = 3'800'000;
  bool shuffled = false;
  for (int k = 1; k < argc; ++k) {
    const std::string arg = argv[k];
    if (arg == "--shuffled") shuffled = true;
    else if (const long long v = std::atoll(arg.c_str()); v >= 2) n = static_cast<std::size_t>(v);
    else {
      std::fprintf(stderr, "usage: nodal_system_speed [N >= 2] [--shuffled]\n");
      return 2;
    }
  }

  // A random binary tree grown node by node: each new node hangs from a node drawn among
  // those with fewer than two children. Then numbered breadth first from the root, as vgen
  // numbers its trees (or at random).
  std::mt19937_64 rng(1);
  std::vector<std::int32_t> parent(n, -1), open{0};
  std::vector<std::int32_t> first_child(n, -1), second_child(n, -1);
  for (std::size_t k = 1; k < n; ++k) {
    const std::size_t pick = std::uniform_int_distribution<std::size_t>(0, open.size() - 1)(rng);
    const auto p = static_cast<std::size_t>(open[pick]);
    parent[k] = static_cast<std::int32_t>(p);
    if (first_child[p] < 0) {
      first_child[p] = static_cast<std::int32_t>(k);
    } else {
      second_child[p] = static_cast<std::int32_t>(k);
      open[pick] = open.back();
      open.pop_back();
    }
    open.push_back(static_cast<std::int32_t>(k));
  }
  std::vector<std::int32_t> label(n);
  if (shuffled) {
    std::iota(label.begin(), label.end(), 0);
    std::shuffle(label.begin(), label.end(), rng);
  } else {
    std::vector<std::int32_t> queue{0};
    queue.reserve(n);
    for (std::size_t head = 0; head < queue.size(); ++head) {
      const auto i = static_cast<std::size_t>(queue[head]);
      label[i] = static_cast<std::int32_t>(head);
      for (const std::int32_t c : {first_child[i], second_child[i]})
        if (c >= 0) queue.push_back(c);
    }
  }
  // Edges in the order of their child nodes, as a network lists its vessels (vessel v ends at
  // node v + 1 in vgen's trees); under random labels, in the order they were grown.
  std::vector<std::int32_t> a(n - 1), b(n - 1);
  for (std::size_t k = 1; k < n; ++k) {
    const std::size_t e = shuffled ? k - 1 : static_cast<std::size_t>(label[k]) - 1;
    a[e] = label[static_cast<std::size_t>(parent[k])];
    b[e] = label[k];
  }
  // Conductances 1/R over four decades; shunts C/dt two to four decades below them.
  std::uniform_real_distribution<double> unit(0, 1);
  std::vector<double> g(n - 1), shunt(n), rhs(n);
  for (double& x : g) x = std::pow(10.0, 4 * unit(rng) - 2);
  for (double& x : shunt) x = std::pow(10.0, 2 * unit(rng) - 4);
  for (double& x : rhs) x = 2 * unit(rng) - 1;
  std::printf("random binary tree: %zu nodes, %s\n", n, shuffled ? "random labels" : "numbered breadth first");

  std::vector<std::int32_t> every(n), drawn(10'000);
  std::iota(every.begin(), every.end(), 0);
  for (std::int32_t& i : drawn) i = std::uniform_int_distribution<std::int32_t>(0, static_cast<std::int32_t>(n) - 1)(rng);
  std::vector<std::vector<double>> solution, drawn_diagonal;
  for (const Method method : {Method::tree_elimination, Method::sparse_cholesky}) {
    const auto start = std::chrono::steady_clock::now();
    NodalSystem system(n, a, b, method);
    const double analysis = seconds_since(start);
    std::int64_t singular = -1;
    const double factorize = median_of_5([&] { singular = system.factorize(g, shunt); });
    if (singular >= 0) {
      std::fprintf(stderr, "singular at node %lld\n", static_cast<long long>(singular));
      return 1;
    }
    std::vector<double> x(n);
    const double solve = median_of_5([&] { system.solve(rhs, x); });
    std::printf("%-17s analysis %8.3f s   factorize %8.4f s   solve %8.4f s\n",
                method == Method::tree_elimination ? "tree_elimination" : "sparse_cholesky", analysis, factorize,
                solve);
    if (method == Method::tree_elimination) {
      // The step of the 0D vessels: factorisation and forward half in one pass up, the
      // backward half down; subtrees in parallel with two threads (the same bits).
      for (const int threads : {1, 2}) {
        system.set_threads(threads);
        std::vector<double> y(n), back(n);
        const double up = median_of_5([&] {
          std::copy(rhs.begin(), rhs.end(), y.begin());
          system.factorize_forward(g, shunt, y);
        });
        const double down = median_of_5([&] { system.backward(y, back); });
        std::printf("%-17s %d thread(s): factorize_forward %8.4f s (with a copy of b)   backward %8.4f s\n", "",
                    threads, up, down);
      }
      system.set_threads(1);
    }
    solution.push_back(std::move(x));
    std::vector<double> z(drawn.size());
    const double some = median_of_5([&] { system.inverse_diagonal(drawn, z); });
    const std::span<const std::int32_t> hundred(drawn.data(), 100);
    const double few = median_of_5([&] { system.inverse_diagonal(hundred, std::span<double>(z.data(), 100)); });
    std::printf("%-17s inverse diagonal:", "");
    if (method == Method::tree_elimination) {
      std::vector<double> all(n);
      std::printf(" every node %8.4f s ", median_of_5([&] { system.inverse_diagonal(every, all); }));
    }
    std::printf("  %zu drawn nodes %8.4f s   100 of them %8.5f s\n", drawn.size(), some, few);
    drawn_diagonal.push_back(std::move(z));
  }
  double difference = 0, scale = 0;
  for (std::size_t i = 0; i < n; ++i) {
    difference = std::max(difference, std::abs(solution[0][i] - solution[1][i]));
    scale = std::max(scale, std::abs(solution[0][i]));
  }
  std::printf("max |x_tree - x_cholesky| / max |x_tree| = %.2e\n", difference / scale);
  double worst = 0;
  for (std::size_t k = 0; k < drawn.size(); ++k)
    worst = std::max(worst, std::abs(drawn_diagonal[0][k] - drawn_diagonal[1][k]) / drawn_diagonal[0][k]);
  std::printf("max |z_tree - z_cholesky| / z_tree over the drawn nodes = %.2e\n", worst);
}
