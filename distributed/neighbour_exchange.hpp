// Numbers out to each neighbouring rank and in from it at once (MPI_Isend and MPI_Irecv with
// every neighbour, then one wait): the exchange of a cut whose sides each know what the other
// sends (the 1D vessels' traces at junctions, a transport's links). The count of its messages,
// bytes sent and seconds inside it (waiting for the neighbours included) is the caller's.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

namespace hemotree {

struct NeighbourTraffic {
  std::size_t messages = 0, bytes = 0;
  double seconds = 0;
};

// send[i] to neighbours[i], receive[i] (sized by the caller) from it, on MPI_COMM_WORLD with
// `tag`. Collective among the neighbours; nothing where there are none.
void exchange_with_neighbours(std::span<const int> neighbours, const std::vector<std::vector<double>>& send,
                              std::vector<std::vector<double>>& receive, int tag, NeighbourTraffic& traffic);

}  // namespace hemotree
