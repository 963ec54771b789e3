#pragma once
/// \file
/// Incremental 3-d tree for the RRT* family's Nearest() and Near() queries
/// (REQ-PLAN-006).
///
/// Points are inserted one at a time as leaves (Bentley 1975): the split axis of a node
/// is its depth mod 3 and its split value is its own coordinate, so an insertion walks
/// one root-to-leaf path and never moves existing points. For the random insertion
/// order of a sampling planner the expected depth is O(log n), so both queries cost
/// O(log n) expected instead of the O(n) of a linear scan. A point whose coordinate equals
/// a node's split goes to the node's two sides in turn, so n equal points make a tree of
/// depth O(log n), not a chain of n (issue 20, tenth campaign L14: 10^5 duplicates took
/// over 20 s).
///
/// Answers are exact and deterministic: ties in `nearest` go to the smaller index and
/// `within` returns indices in ascending order, so the tree's shape never leaks into a
/// planner's output.

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace miner::plan {

class KdTree {
 public:
  /// Adds `p`; returns its index (0, 1, 2, ... in insertion order).
  std::size_t insert(const Eigen::Vector3d& p);
  std::size_t size() const { return nodes_.size(); }
  bool empty() const { return nodes_.empty(); }
  const Eigen::Vector3d& point(std::size_t i) const { return nodes_[i].p; }
  void reserve(std::size_t n) { nodes_.reserve(n); }
  /// Nodes on the longest root-to-leaf path (0 when empty).
  std::size_t height() const { return height_; }

  /// Index of the point closest to q (smallest index among equals). Requires !empty().
  std::size_t nearest(const Eigen::Vector3d& q) const;

  /// Indices of every point p with |p - q| <= r, ascending; `out` is overwritten.
  void within(const Eigen::Vector3d& q, double r, std::vector<std::size_t>& out) const;

 private:
  static constexpr std::uint32_t kNone = 0xffffffffu;
  struct Node {
    Eigen::Vector3d p;
    std::uint32_t child[2] = {kNone, kNone};  ///< [0]: coordinate <= split, [1]: >=
    int axis = 0;
    std::uint8_t tie_side = 1;  ///< the side the next point equal to the split goes to
  };
  struct StackItem {
    std::uint32_t node;
    double bound2;  ///< squared distance from the query to the subtree's half-space
  };
  std::vector<Node> nodes_;
  std::size_t height_ = 0;
  // Scratch stacks reused across queries (no allocation in the hot loop); a tree is
  // therefore not safe for concurrent queries from several threads.
  mutable std::vector<StackItem> nearest_stack_;
  mutable std::vector<std::uint32_t> within_stack_;
};

}  // namespace miner::plan
