#include "distributed/neighbour_exchange.hpp"

#include <mpi.h>

namespace hemotree {

void exchange_with_neighbours(std::span<const int> neighbours, const std::vector<std::vector<double>>& send,
                              std::vector<std::vector<double>>& receive, int tag, NeighbourTraffic& traffic) {
  if (neighbours.empty()) return;
  const double started = MPI_Wtime();
  std::vector<MPI_Request> requests(2 * neighbours.size());
  for (std::size_t i = 0; i < neighbours.size(); ++i) {
    MPI_Irecv(receive[i].data(), static_cast<int>(receive[i].size()), MPI_DOUBLE, neighbours[i], tag, MPI_COMM_WORLD,
              &requests[2 * i]);
    MPI_Isend(send[i].data(), static_cast<int>(send[i].size()), MPI_DOUBLE, neighbours[i], tag, MPI_COMM_WORLD,
              &requests[2 * i + 1]);
  }
  MPI_Waitall(static_cast<int>(requests.size()), requests.data(), MPI_STATUSES_IGNORE);
  traffic.messages += neighbours.size();
  for (const std::vector<double>& out : send) traffic.bytes += out.size() * sizeof(double);
  traffic.seconds += MPI_Wtime() - started;
}

}  // namespace hemotree
