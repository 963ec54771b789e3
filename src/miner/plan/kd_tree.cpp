#include "miner/plan/kd_tree.hpp"

#include <algorithm>
#include <limits>

#include "miner/core/error.hpp"

namespace miner::plan {

std::size_t KdTree::insert(const Eigen::Vector3d& p) {
  if (nodes_.size() >= kNone) throw Error("k-d tree: more than 2^32 - 1 points");
  const auto index = static_cast<std::uint32_t>(nodes_.size());
  Node node;
  node.p = p;
  std::size_t depth = 1;
  if (!nodes_.empty()) {
    std::uint32_t at = 0;
    for (;; ++depth) {
      Node& n = nodes_[at];
      int side = p[n.axis] < n.p[n.axis] ? 0 : 1;
      if (p[n.axis] == n.p[n.axis]) {  // equal to the split: the two sides in turn
        side = n.tie_side;
        n.tie_side ^= 1U;
      }
      if (n.child[side] == kNone) {
        n.child[side] = index;
        node.axis = (n.axis + 1) % 3;
        break;
      }
      at = n.child[side];
    }
  }
  nodes_.push_back(node);
  height_ = std::max(height_, depth + (nodes_.size() > 1 ? 1 : 0));
  return index;
}

std::size_t KdTree::nearest(const Eigen::Vector3d& q) const {
  if (nodes_.empty()) throw Error("k-d tree: nearest() on an empty tree");
  std::size_t best = 0;
  double best_d2 = std::numeric_limits<double>::infinity();
  // Depth-first, near side first; each item carries the squared distance from q to the
  // half-space its subtree lies in, so whole subtrees farther than the best are skipped.
  auto& stack = nearest_stack_;
  stack.clear();
  stack.push_back({0, 0.0});
  while (!stack.empty()) {
    const StackItem it = stack.back();
    stack.pop_back();
    if (it.bound2 > best_d2) continue;
    const Node& n = nodes_[it.node];
    const double d2 = (n.p - q).squaredNorm();
    if (d2 < best_d2 || (d2 == best_d2 && it.node < best)) {
      best_d2 = d2;
      best = it.node;
    }
    const double diff = q[n.axis] - n.p[n.axis];
    const int near_side = diff < 0.0 ? 0 : 1;
    const std::uint32_t far = n.child[1 - near_side];
    const std::uint32_t near = n.child[near_side];
    if (far != kNone) stack.push_back({far, std::max(it.bound2, diff * diff)});
    if (near != kNone) stack.push_back({near, it.bound2});
  }
  return best;
}

void KdTree::within(const Eigen::Vector3d& q, double r, std::vector<std::size_t>& out) const {
  out.clear();
  if (nodes_.empty() || !(r >= 0.0)) return;
  const double r2 = r * r;
  auto& stack = within_stack_;
  stack.clear();
  stack.push_back(0);
  while (!stack.empty()) {
    const std::uint32_t at = stack.back();
    stack.pop_back();
    const Node& n = nodes_[at];
    if ((n.p - q).squaredNorm() <= r2) out.push_back(at);
    const double diff = q[n.axis] - n.p[n.axis];
    // Left subtree holds coordinates <= split: reachable if q - r <= split.
    if (n.child[0] != kNone && diff - r <= 0.0) stack.push_back(n.child[0]);
    if (n.child[1] != kNone && diff + r >= 0.0) stack.push_back(n.child[1]);
  }
  std::sort(out.begin(), out.end());
}

}  // namespace miner::plan
