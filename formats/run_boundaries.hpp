// The network's boundary conditions as the pulsatile run takes them, in one fixed order: the
// tree form's outlets (in net.outlets' order), its inlet, then net.boundaries. "Outlet k"
// everywhere in the run (capacitors, TreeLoads) is the k-th outlet of this list: for a tree,
// net.outlets[k].
//
// A view of the network, which must outlive it: a tree's outlets are read from net.outlets
// when asked for, not copied. A full tree has two million; as NodeBoundary values, each with
// the waveform an outlet never has, they held 300 MB for the whole run.
#pragma once

#include <cstddef>
#include <cstdint>
#include <iterator>

#include "formats/network.hpp"

namespace hemotree {

class RunBoundaries {
 public:
  RunBoundaries() = default;  // none
  // Throws InputError where two conditions land on one node, or for an inlet of no vessel.
  explicit RunBoundaries(const Network& net);

  std::size_t size() const { return tree_outlets_ + (has_inlet_ ? 1 : 0) + given_count_; }
  bool empty() const { return size() == 0; }

  // Boundary i's parts, without making its NodeBoundary.
  std::int32_t node(std::size_t i) const {
    return i < tree_outlets_ ? net_->to[static_cast<std::size_t>(net_->outlets[i].vessel)] : given(i).node;
  }
  BoundaryType type(std::size_t i) const { return i < tree_outlets_ ? net_->outlets[i].type : given(i).type; }
  bool is_outlet(std::size_t i) const { return is_outlet_model(type(i)); }
  // An outlet's parameters (a tree outlet's with its vessel; a node boundary's without).
  const Outlet& outlet(std::size_t i) const { return i < tree_outlets_ ? net_->outlets[i] : given(i).outlet; }
  // A flow's [m^3/s] or a pressure's [Pa]; an outlet has none (NodeBoundary's default).
  const Waveform& waveform(std::size_t i) const { return i < tree_outlets_ ? no_waveform_ : given(i).waveform; }

  // Boundary i whole, made as the caller asks (a value: copying a table waveform allocates).
  NodeBoundary operator[](std::size_t i) const;

  class Iterator {
   public:
    using iterator_category = std::input_iterator_tag;
    using value_type = NodeBoundary;
    using difference_type = std::ptrdiff_t;
    Iterator(const RunBoundaries* list, std::size_t i) : list_(list), i_(i) {}
    NodeBoundary operator*() const { return (*list_)[i_]; }
    Iterator& operator++() {
      ++i_;
      return *this;
    }
    bool operator==(const Iterator& other) const { return i_ == other.i_; }
    bool operator!=(const Iterator& other) const { return i_ != other.i_; }

   private:
    const RunBoundaries* list_;
    std::size_t i_;
  };
  Iterator begin() const { return {this, 0}; }
  Iterator end() const { return {this, size()}; }

 private:
  // Boundary i at or after the tree's outlets: its inlet, then net.boundaries.
  const NodeBoundary& given(std::size_t i) const {
    const std::size_t k = i - tree_outlets_;
    return has_inlet_ ? (k == 0 ? inlet_ : net_->boundaries[k - 1]) : net_->boundaries[k];
  }

  const Network* net_ = nullptr;
  std::size_t tree_outlets_ = 0, given_count_ = 0;
  bool has_inlet_ = false;
  NodeBoundary inlet_;  // the tree form's inlet as a flow into its vessel's `from` node
  static const Waveform no_waveform_;
};

}  // namespace hemotree
