#include "generator/tree_layout.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "formats/topology.hpp"

namespace hemotree {

double murray_branching_angle(double parent, double daughter, double sibling) {
  const double p2 = parent * parent, d2 = daughter * daughter, s2 = sibling * sibling;
  const double c = (p2 * p2 + d2 * d2 - s2 * s2) / (2 * p2 * d2);
  return std::acos(std::clamp(c, 0.0, 1.0));
}

void lay_out_tree(Network& net) {
  const std::size_t root = check_rooted_tree(net);
  const Children children = children_of(net);
  const std::size_t n = net.vessel_count();

  net.x.assign(net.node_count(), 0.0);
  net.y.assign(net.node_count(), 0.0);
  net.z.assign(net.node_count(), 0.0);
  // Per vessel: its axis, and the direction in which its own daughters spread.
  std::vector<Eigen::Vector3d> axis(n), spread(n);
  auto position = [&](std::int32_t node) {
    return Eigen::Vector3d(net.x[node], net.y[node], net.z[node]);
  };
  auto place = [&](std::size_t v) {
    const Eigen::Vector3d end = position(net.from[v]) + net.length[v] * axis[v];
    net.x[net.to[v]] = end.x();
    net.y[net.to[v]] = end.y();
    net.z[net.to[v]] = end.z();
  };

  axis[root] = Eigen::Vector3d::UnitX();
  spread[root] = Eigen::Vector3d::UnitY();
  place(root);
  // Breadth-first order from the root, so every parent is placed before its daughters.
  std::vector<std::int32_t> queue{static_cast<std::int32_t>(root)};
  queue.reserve(n);
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const auto v = static_cast<std::size_t>(queue[head]);
    const auto first = children.offset[v], last = children.offset[v + 1];
    const auto count = last - first;
    if (count == 0) continue;
    // The daughters' own plane is perpendicular to this one.
    const Eigen::Vector3d normal = axis[v].cross(spread[v]).normalized();
    for (auto k = first; k < last; ++k) {
      const auto d = static_cast<std::size_t>(children.index[k]);
      double angle = 0;
      if (count == 2) {
        const auto s = static_cast<std::size_t>(children.index[k == first ? first + 1 : first]);
        angle = murray_branching_angle(net.diameter[v], net.diameter[d], net.diameter[s]);
      } else {
        angle = std::numbers::pi / 4;  // more than two daughters: a fan
      }
      // Alternate sides; with more daughters, turn each around the parent's axis.
      const double turn = 2 * std::numbers::pi * static_cast<double>(k - first) /
                          static_cast<double>(count);
      const Eigen::Vector3d side = Eigen::AngleAxisd(turn, axis[v]) * spread[v];
      axis[d] = (std::cos(angle) * axis[v] + std::sin(angle) * side).normalized();
      // Keep the daughter's spread direction perpendicular to its axis (it already is
      // for two daughters; with a fan it needs projecting).
      Eigen::Vector3d next = normal - normal.dot(axis[d]) * axis[d];
      if (next.norm() < 1e-12) next = axis[d].unitOrthogonal();
      spread[d] = next.normalized();
      place(d);
      queue.push_back(static_cast<std::int32_t>(d));
    }
  }
}

}  // namespace hemotree
