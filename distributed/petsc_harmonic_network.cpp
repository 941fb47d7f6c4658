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
                                           std::span<const std::int32_t> edge_owner)
    : nodes_(nodes), a_(a.begin(), a.end()), b_(b.begin(), b.end()), node_owner_(node_owner.begin(), node_owner.end()),
      edge_owner_(edge_owner.begin(), edge_owner.end()) {
  if (a.size() != b.size() || edge_owner.size() != a.size() || node_owner.size() != nodes)
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
  std::vector<std::int64_t> count(static_cast<std::size_t>(ranks) + 1, 0);
  for (std::size_t i = 0; i < nodes; ++i) count[static_cast<std::size_t>(node_owner_[i]) + 1] += 2;
  for (int r = 0; r < ranks; ++r) count[static_cast<std::size_t>(r) + 1] += count[static_cast<std::size_t>(r)];
  first_row_ = count[static_cast<std::size_t>(rank)];
  rows_ = count[static_cast<std::size_t>(rank) + 1] - first_row_;
  all_rows_ = count.back();
  row_.assign(nodes, -1);
  std::vector<std::int64_t> next(count.begin(), count.end() - 1);
  for (std::size_t i = 0; i < nodes; ++i) {
    row_[i] = next[static_cast<std::size_t>(node_owner_[i])];
    next[static_cast<std::size_t>(node_owner_[i])] += 2;
  }
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
  const auto n = static_cast<std::int32_t>(rows_), others = static_cast<std::int32_t>(all_rows_ - rows_);
  for (std::size_t k = 0; k < in_block_.size(); ++k) {
    in_block_[k] = std::min(in_block_[k], n);
    off_block_[k] = std::min(off_block_[k], others);
  }
}

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
      throw Collective<InputError>("a harmonic's distributed solve: the part of the network that holds node index " +
                                   std::to_string(i) + " has no path to an outlet or a pressure");
}

void PetscHarmonicNetwork::solve(std::span<const TwoPort> edge, std::span<const Complex> shunt,
                                 std::span<const Complex> current, std::span<Complex> potential) {
  if (edge.size() != a_.size() || shunt.size() != nodes_ || current.size() != nodes_ || potential.size() != nodes_)
    throw std::invalid_argument("PetscHarmonicNetwork::solve: a two-port per edge, a shunt, a current and a potential per node");
  const int rank = world_rank();
  refuse_ungrounded(edge, shunt);
  PetscObjects o;
  KSPConvergedReason reason = KSP_CONVERGED_ITERATING;
  PetscReal residual = 0, scale = 0;
  // z as its real 2 x 2 block at the rows of node i and the columns of node j.
  auto add = [&](std::size_t i, std::size_t j, Complex z) {
    const PetscInt rows[2] = {static_cast<PetscInt>(row_[i]), static_cast<PetscInt>(row_[i] + 1)};
    const PetscInt columns[2] = {static_cast<PetscInt>(row_[j]), static_cast<PetscInt>(row_[j] + 1)};
    const PetscScalar block[4] = {z.real(), -z.imag(), z.imag(), z.real()};
    petsc_check(MatSetValues(o.matrix, 2, rows, 2, columns, block, ADD_VALUES), "MatSetValues");
  };
  // PETSc's calls are collective: a failure there is every rank's alike (on_every_rank).
  on_every_rank([&] {
    const auto n = static_cast<PetscInt>(rows_), all = static_cast<PetscInt>(all_rows_);
    std::vector<PetscInt> in_block(in_block_.begin(), in_block_.end()), off_block(off_block_.begin(), off_block_.end());
    petsc_check(MatCreate(PETSC_COMM_WORLD, &o.matrix), "MatCreate");
    petsc_check(MatSetSizes(o.matrix, n, n, all, all), "MatSetSizes");
    petsc_check(MatSetType(o.matrix, MATAIJ), "MatSetType");
    petsc_check(MatSeqAIJSetPreallocation(o.matrix, 0, in_block.data()), "MatSeqAIJSetPreallocation");
    petsc_check(MatMPIAIJSetPreallocation(o.matrix, 0, in_block.data(), 0, off_block.data()), "MatMPIAIJSetPreallocation");
    petsc_check(MatSetOption(o.matrix, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE), "MatSetOption");
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
    petsc_check(MatAssemblyBegin(o.matrix, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
    petsc_check(MatAssemblyEnd(o.matrix, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");

    petsc_check(MatCreateVecs(o.matrix, &o.x, &o.rhs), "MatCreateVecs");
    PetscScalar* values = nullptr;
    petsc_check(VecGetArray(o.rhs, &values), "VecGetArray");
    for (std::size_t i = 0; i < nodes_; ++i)
      if (node_owner_[i] == rank) {
        const auto k = static_cast<std::size_t>(row_[i] - first_row_);
        values[k] = current[i].real();
        values[k + 1] = current[i].imag();
      }
    petsc_check(VecRestoreArray(o.rhs, &values), "VecRestoreArray");

    petsc_check(KSPCreate(PETSC_COMM_WORLD, &o.solver), "KSPCreate");
    petsc_check(KSPSetOperators(o.solver, o.matrix, o.matrix), "KSPSetOperators");
    petsc_check(KSPSetType(o.solver, KSPPREONLY), "KSPSetType");
    PC preconditioner = nullptr;
    petsc_check(KSPGetPC(o.solver, &preconditioner), "KSPGetPC");
    petsc_check(PCSetType(preconditioner, PCLU), "PCSetType");
    petsc_check(PCFactorSetMatSolverType(preconditioner, MATSOLVERMUMPS), "PCFactorSetMatSolverType");
    petsc_check(KSPSetErrorIfNotConverged(o.solver, PETSC_FALSE), "KSPSetErrorIfNotConverged");
    petsc_options_check(KSPSetFromOptions(o.solver));
    // A singular system (a part with no admittance to ground) fails the factorisation: PETSc
    // says so as an error or a reason; either way the residual below refuses it.
    const PetscErrorCode solved = KSPSolve(o.solver, o.rhs, o.x);
    if (solved != 0) petsc_check(VecSet(o.x, 0.0), "VecSet");
    petsc_check(KSPGetConvergedReason(o.solver, &reason), "KSPGetConvergedReason");
    PetscInt iterations = 0;
    petsc_check(KSPGetIterationNumber(o.solver, &iterations), "KSPGetIterationNumber");
    iterations_ = static_cast<int>(iterations);
    KSPType ksp_type = nullptr;
    PCType pc_type = nullptr;
    MatSolverType factor = nullptr;
    petsc_check(KSPGetType(o.solver, &ksp_type), "KSPGetType");
    petsc_check(PCGetType(preconditioner, &pc_type), "PCGetType");
    if (PCFactorGetMatSolverType(preconditioner, &factor) != 0) factor = nullptr;
    method_ = std::string(ksp_type ? ksp_type : "?") + " with " + (pc_type ? pc_type : "?") +
              (factor ? std::string(" (") + factor + ")" : std::string());
    petsc_check(VecDuplicate(o.rhs, &o.everywhere), "VecDuplicate");
    petsc_check(MatMult(o.matrix, o.x, o.everywhere), "MatMult");
    petsc_check(VecAYPX(o.everywhere, -1.0, o.rhs), "VecAYPX");
    petsc_check(VecNorm(o.everywhere, NORM_2, &residual), "VecNorm");
    petsc_check(VecNorm(o.rhs, NORM_2, &scale), "VecNorm");
    petsc_check(VecDestroy(&o.everywhere), "VecDestroy");
  });
  const double relative = scale > 0 ? residual / scale : residual;
  if (reason < 0 || !(relative <= 1e-10))
    throw Collective<InputError>("a harmonic's distributed solve (PETSc's " + method_ + ") left a relative residual of " +
                                 scientific(relative) + " (PETSc's reason " + std::to_string(reason) +
                                 "; 1e-10 is needed): a part of the network with no path to an outlet or a pressure, "
                                 "or PETSC_OPTIONS that ask too little");
  on_every_rank([&] {
    petsc_check(VecScatterCreateToAll(o.x, &o.to_all, &o.everywhere), "VecScatterCreateToAll");
    petsc_check(VecScatterBegin(o.to_all, o.x, o.everywhere, INSERT_VALUES, SCATTER_FORWARD), "VecScatterBegin");
    petsc_check(VecScatterEnd(o.to_all, o.x, o.everywhere, INSERT_VALUES, SCATTER_FORWARD), "VecScatterEnd");
    const PetscScalar* x = nullptr;
    petsc_check(VecGetArrayRead(o.everywhere, &x), "VecGetArrayRead");
    for (std::size_t i = 0; i < nodes_; ++i) potential[i] = {x[row_[i]], x[row_[i] + 1]};
    petsc_check(VecRestoreArrayRead(o.everywhere, &x), "VecRestoreArrayRead");
  });
}

}  // namespace hemotree
