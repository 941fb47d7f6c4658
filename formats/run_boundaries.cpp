#include "formats/run_boundaries.hpp"

namespace hemotree {

const Waveform RunBoundaries::no_waveform_{};

RunBoundaries::RunBoundaries(const Network& net)
    : net_(&net), tree_outlets_(net.outlets.size()), given_count_(net.boundaries.size()), has_inlet_(net.inlet.has_value()) {
  check_one_boundary_per_node(net);
  if (has_inlet_) inlet_ = as_node_boundary(net, *net.inlet);
}

NodeBoundary RunBoundaries::operator[](std::size_t i) const {
  if (i < tree_outlets_) return as_node_boundary(*net_, net_->outlets[i]);
  return given(i);
}

}  // namespace hemotree
