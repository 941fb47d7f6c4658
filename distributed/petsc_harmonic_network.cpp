#include "distributed/petsc_harmonic_network.hpp"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>

#include <mpi.h>
#include <petscksp.h>

#include "core/errors.hpp"
#include "distributed/petsc_session.hpp"
#include "mpi/session.hpp"

namespace hemotree {

namespace {
std::string scientific(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", x);
  return text;
}
}  // namespace

PetscHarmonicNetwork::PetscHarmonicNetwork(std::size_t nodes, std::span<const std::int32_t> a,
                                           std::span<const std::int32_t> b, std::span<const std::int32_t> node_owner,
                                           std::span<const std::int32_t> edge_owner, std::span<const std::int64_t> node_name)
    : nodes_(nodes), a_(a.begin(), a.end()), b_(b.begin(), b.end()), node_owner_(node_owner.begin(), node_owner.end()),
      edge_owner_(edge_owner.begin(), edge_owner.end()), node_name_(node_name.begin(), node_name.end()) {
  if (a.size() != b.size() || edge_owner.size() != a.size() || node_owner.size() != nodes ||
      (!node_name.empty() && node_name.size() != nodes))
    throw std::invalid_argument("PetscHarmonicNetwork: two nodes and an owner per edge, an owner per node");
  if (2 * nodes > static_cast<std::size_t>(std::numeric_limits<PetscInt>::max()))
    throw std::invalid_argument("PetscHarmonicNetwork: more rows than PETSc's indices hold");
  const int ranks = world_size(), rank = world_rank();
  for (const std::span<const std::int32_t> owner : {node_owner, edge_owner})
    for (const std::int32_t r : owner)
      if (r < 0 || r >= ranks) throw std::invalid_argument("PetscHarmonicNetwork: an owner outside the session's ranks");
  for (std::size_t e = 0; e < a.size(); ++e)
    if (a[e] < 0 || b[e] < 0 || static_cast<std::size_t>(a[e]) >= nodes || static_cast<std::size_t>(b[e]) >= nodes)
      throw std::invalid_argument("PetscHarmonicNetwork: edge " + std::to_string(e) + " leaves the graph");
  start_petsc();
  // Two rows a node, the nodes numbered rank by rank, each rank's in the order of the nodes.
  PetscRows rows = petsc_rows(node_owner_, {}, 2);
  row_ = std::move(rows.row);
  first_row_ = rows.first;
  rows_ = rows.count;
  all_rows_ = rows.all;
  // Each own row: its node's block and two columns for each edge there (parallel edges
  // counted apart: a little over), split by whether the node across is this rank's.
  in_block_.assign(static_cast<std::size_t>(rows_), 2);
  off_block_.assign(static_cast<std::size_t>(rows_), 0);
  for (std::size_t e = 0; e < a_.size(); ++e)
    for (const bool at_a : {true, false}) {
      const auto i = static_cast<std::size_t>(at_a ? a_[e] : b_[e]), j = static_cast<std::size_t>(at_a ? b_[e] : a_[e]);
      if (node_owner_[i] != rank) continue;
      const auto k = static_cast<std::size_t>(row_[i] - first_row_);
      std::vector<std::int32_t>& block = node_owner_[j] == rank ? in_block_ : off_block_;
      block[k] += 2;
      block[k + 1] += 2;
    }
}

PetscHarmonicNetwork::~PetscHarmonicNetwork() = default;

void PetscHarmonicNetwork::refuse_ungrounded(std::span<const TwoPort> edge, std::span<const Complex> shunt) const {
  // A node is grounded where its shunt is not zero or an edge there leaks current (its
  // two-port's row at that end does not sum to zero: a line's shunt admittance); each rank
  // marks what it owns, and every rank then sees every mark.
  const int rank = world_rank();
  std::vector<unsigned char> grounded(nodes_, 0);
  for (std::size_t i = 0; i < nodes_; ++i)
    if (node_owner_[i] == rank && shunt[i] != Complex{}) grounded[i] = 1;
  for (std::size_t e = 0; e < a_.size(); ++e)
    if (edge_owner_[e] == rank) {
      if (edge[e].aa + edge[e].ab != Complex{}) grounded[static_cast<std::size_t>(a_[e])] = 1;
      if (edge[e].ba + edge[e].bb != Complex{}) grounded[static_cast<std::size_t>(b_[e])] = 1;
    }
  if (world_size() > 1)
    MPI_Allreduce(MPI_IN_PLACE, grounded.data(), static_cast<int>(nodes_), MPI_UNSIGNED_CHAR, MPI_MAX, MPI_COMM_WORLD);
  // Each connected part's lowest node, by union-find; a part none of whose nodes is grounded
  // makes the system singular.
  std::vector<std::int32_t> part(nodes_);
  for (std::size_t i = 0; i < nodes_; ++i) part[i] = static_cast<std::int32_t>(i);
  auto root = [&](std::int32_t i) {
    while (part[static_cast<std::size_t>(i)] != i) i = part[static_cast<std::size_t>(i)] = part[static_cast<std::size_t>(part[static_cast<std::size_t>(i)])];
    return i;
  };
  for (std::size_t e = 0; e < a_.size(); ++e) {
    const std::int32_t x = root(a_[e]), y = root(b_[e]);
    part[static_cast<std::size_t>(std::max(x, y))] = std::min(x, y);
  }
  std::vector<unsigned char> part_grounded(nodes_, 0);
  for (std::size_t i = 0; i < nodes_; ++i)
    if (grounded[i]) part_grounded[static_cast<std::size_t>(root(static_cast<std::int32_t>(i)))] = 1;
  for (std::size_t i = 0; i < nodes_; ++i)
    if (root(static_cast<std::int32_t>(i)) == static_cast<std::int32_t>(i) && !part_grounded[i])
      throw Collective<InputError>("a harmonic's distributed solve: the part of the network that holds node " +
                                   (node_name_.empty() ? "index " + std::to_string(i) : std::to_string(node_name_[i])) +
                                   " has no path to an outlet or a pressure");
}

void PetscHarmonicNetwork::solve(std::span<const TwoPort> edge, std::span<const Complex> shunt,
                                 std::span<const Complex> current, std::span<Complex> potential) {
  if (edge.size() != a_.size() || shunt.size() != nodes_ || current.size() != nodes_ || potential.size() != nodes_)
    throw std::invalid_argument("PetscHarmonicNetwork::solve: a two-port per edge, a shunt, a current and a potential per node");
  const int rank = world_rank();
  refuse_ungrounded(edge, shunt);
  const bool first = !held_;
  if (first) held_ = std::make_unique<PetscObjects>();
  PetscObjects& o = *held_;
  PetscOutcome outcome;
  // z as its real 2 x 2 block at the rows of node i and the columns of node j.
  auto add = [&](std::size_t i, std::size_t j, Complex z) {
    const PetscInt rows[2] = {static_cast<PetscInt>(row_[i]), static_cast<PetscInt>(row_[i] + 1)};
    const PetscInt columns[2] = {static_cast<PetscInt>(row_[j]), static_cast<PetscInt>(row_[j] + 1)};
    const PetscScalar block[4] = {z.real(), -z.imag(), z.imag(), z.real()};
    petsc_check(MatSetValues(o.matrix, 2, rows, 2, columns, block, ADD_VALUES), "MatSetValues");
  };
  // PETSc's calls are collective: a failure there is every rank's alike (on_every_rank),
  // and so is starting afresh after one.
  struct Afresh {
    std::unique_ptr<PetscObjects>& held;
    bool solved = false;
    ~Afresh() {
      if (!solved) held.reset();
    }
  } afresh{held_};
  on_every_rank([&] {
    if (first) {
      o.matrix = petsc_matrix(static_cast<PetscInt>(rows_), static_cast<PetscInt>(all_rows_),
                              std::vector<PetscInt>(in_block_.begin(), in_block_.end()),
                              std::vector<PetscInt>(off_block_.begin(), off_block_.end()));
      petsc_check(MatSetOption(o.matrix, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE), "MatSetOption");
    } else {
      // The same entries as the first solve's (every block is set, zeros too): its pattern.
      petsc_check(MatZeroEntries(o.matrix), "MatZeroEntries");
    }
    for (std::size_t i = 0; i < nodes_; ++i)
      if (node_owner_[i] == rank) add(i, i, shunt[i]);
    for (std::size_t e = 0; e < a_.size(); ++e) {
      if (edge_owner_[e] != rank) continue;
      const auto ea = static_cast<std::size_t>(a_[e]), eb = static_cast<std::size_t>(b_[e]);
      add(ea, ea, edge[e].aa);
      add(ea, eb, edge[e].ab);
      add(eb, ea, edge[e].ba);
      add(eb, eb, edge[e].bb);
    }
    std::vector<double> rhs(static_cast<std::size_t>(rows_));
    for (std::size_t i = 0; i < nodes_; ++i)
      if (node_owner_[i] == rank) {
        const auto k = static_cast<std::size_t>(row_[i] - first_row_);
        rhs[k] = current[i].real();
        rhs[k + 1] = current[i].imag();
      }
    if (first) {
      const PC preconditioner = petsc_prepare(o, rhs, KSPPREONLY);
      petsc_check(PCSetType(preconditioner, PCLU), "PCSetType");
      petsc_check(PCFactorSetMatSolverType(preconditioner, MATSOLVERMUMPS), "PCFactorSetMatSolverType");
      petsc_check(KSPSetErrorIfNotConverged(o.solver, PETSC_FALSE), "KSPSetErrorIfNotConverged");
    } else {
      petsc_refill(o, rhs);
    }
    outcome = petsc_solve(o);  // a singular system's failed factorisation: refused below
  });
  iterations_ = outcome.iterations;
  method_ = outcome.method;
  const double relative = outcome.relative;
  if (outcome.reason < 0 || !(relative <= 1e-10))
    throw Collective<InputError>("a harmonic's distributed solve (PETSc's " + method_ + ") left a relative residual of " +
                                 scientific(relative) + " (PETSc's reason " + std::to_string(outcome.reason) +
                                 "; 1e-10 is needed): a part of the network with no path to an outlet or a pressure, "
                                 "or PETSC_OPTIONS that ask too little");
  on_every_rank([&] {
    petsc_read_everywhere(o, [&](const PetscScalar* x) {
      for (std::size_t i = 0; i < nodes_; ++i) potential[i] = {x[row_[i]], x[row_[i] + 1]};
    });
  });
  afresh.solved = true;
}

}  // namespace hemotree
