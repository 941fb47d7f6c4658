#include "solver/lumped_link_mpi.hpp"

namespace hemotree {

LumpedLink mpi_lumped_link(RootExchange& exchange) {
  LumpedLink link;
  link.up = [&exchange](std::span<const double> numbers, std::exception_ptr failure, bool& failed) {
    return exchange.gather(numbers, failure, LumpedLink::up_per_root, failed);
  };
  link.down = [&exchange](std::span<const double> answers, std::exception_ptr failure, std::size_t per_root) {
    return exchange.scatter(answers, failure, per_root, "the 0D step");
  };
  return link;
}

}  // namespace hemotree
