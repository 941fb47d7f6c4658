// A check in a test program under mpirun: a failure counted and said in one line on stderr,
// naming the rank; every rank's count summed at the end (collective).
#pragma once

#include <cstdio>
#include <string>

#include <mpi.h>

namespace hemotree::rank_checks {

inline int failures = 0;
inline int rank = 0;

inline void check(bool ok, const std::string& what) {
  if (ok) return;
  ++failures;
  std::fprintf(stderr, "rank %d: %s\n", rank, what.c_str());
}

// MPI started, this process's rank kept for the lines above; returns the number of ranks.
inline int start(int* argc, char*** argv) {
  MPI_Init(argc, argv);
  int ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  return ranks;
}

inline int all_failures() {
  int total = 0;
  MPI_Allreduce(&failures, &total, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  return total;
}

}  // namespace hemotree::rank_checks
