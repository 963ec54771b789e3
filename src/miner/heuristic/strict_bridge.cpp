#include "miner/heuristic/strict_bridge.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <unordered_map>

#include "miner/heuristic/grid.hpp"
#include "miner/world/map.hpp"

namespace miner::heuristic {

namespace {

using Id = std::uint64_t;
constexpr Id kNone = std::numeric_limits<Id>::max();
constexpr Id kStart = kNone - 1;
constexpr Id kGoal = kNone - 2;

/// The search's view of the heuristic grid (see the file comment of strict_bridge.hpp).
/// Node ids: a whole kFree cell is its cell index c < n; sub-cell f (linear index on the
/// fine grid of dims x k) is n + f; kStart and kGoal are the query points.
class Graph {
 public:
  Graph(const world::Map& map, double r, const Eigen::Vector3i& dims, const std::vector<std::uint8_t>& env,
        const std::vector<std::uint8_t>& mask, const Eigen::Vector3d& start, const Eigen::Vector3d& goal)
      : map_(map), r_(r), dims_(dims), env_(env), mask_(mask), start_(start), goal_(goal),
        origin_(map.bounds().min), cell_(cell_size(map.bounds(), dims)),
        n_(static_cast<Id>(dims.prod())), box_only_(map.voxels() == nullptr), near_(env.size(), 0) {
    for (int a = 0; a < 3; ++a) {
      const double split = r > 0.0 ? std::ceil(cell_[a] / r) : kStrictMaxSplit;
      k_[a] = static_cast<int>(std::clamp(split, 1.0, static_cast<double>(kStrictMaxSplit)));
      sub_[a] = cell_[a] / k_[a];
    }
    fine_ = dims_.cwiseProduct(k_);
    penalty_ = kStrictOutsidePenalty * cell_.maxCoeff();
  }

  bool fine(Id id) const { return id >= n_ && id < kGoal; }
  Eigen::Vector3i fine_coords(Id id) const {
    const Id f = id - n_;
    const Id fx = static_cast<Id>(fine_.x()), fy = static_cast<Id>(fine_.y());
    return {static_cast<int>(f % fx), static_cast<int>((f / fx) % fy), static_cast<int>(f / (fx * fy))};
  }
  Id fine_id(const Eigen::Vector3i& f) const {
    return n_ + (static_cast<Id>(f.z()) * static_cast<Id>(fine_.y()) + static_cast<Id>(f.y())) *
                    static_cast<Id>(fine_.x()) +
           static_cast<Id>(f.x());
  }
  Eigen::Vector3i cell_of_fine(const Eigen::Vector3i& f) const {
    return {f.x() / k_.x(), f.y() / k_.y(), f.z() / k_.z()};
  }
  std::size_t index(const Eigen::Vector3i& c) const { return cell_index(dims_, c.x(), c.y(), c.z()); }
  /// The cell a node lies in (the query points: the cell holding them).
  std::size_t cell(Id id) const {
    if (id == kStart) return index(cell_of(map_.bounds(), dims_, start_));
    if (id == kGoal) return index(cell_of(map_.bounds(), dims_, goal_));
    if (!fine(id)) return static_cast<std::size_t>(id);
    return index(cell_of_fine(fine_coords(id)));
  }
  Eigen::Vector3d position(Id id) const {
    if (id == kStart) return start_;
    if (id == kGoal) return goal_;
    if (!fine(id)) {
      const Eigen::Vector3i c = cell_coords(dims_, static_cast<std::size_t>(id));
      return origin_ + (c.cast<double>().array() + 0.5).matrix().cwiseProduct(cell_);
    }
    return origin_ + (fine_coords(id).cast<double>().array() + 0.5).matrix().cwiseProduct(sub_);
  }
  /// A whole node: a kFree cell. On a box map no point of it is within the robot radius of
  /// an obstacle; a voxel layer's kFree is read from voxel centres, not exact, so there its
  /// moves are tested too (move_free).
  bool whole(std::size_t c) const { return env_[c] == kFree; }
  /// Cells the search may enter: not kSolid, within kStrictReach of H.
  bool allowed(std::size_t c) {
    if (env_[c] == kSolid) return false;
    if (near_[c] == 0) {
      near_[c] = 2;
      const Eigen::Vector3i cc = cell_coords(dims_, c);
      for (int dz = -kStrictReach; dz <= kStrictReach && near_[c] == 2; ++dz)
        for (int dy = -kStrictReach; dy <= kStrictReach && near_[c] == 2; ++dy)
          for (int dx = -kStrictReach; dx <= kStrictReach; ++dx) {
            const Eigen::Vector3i m = cc + Eigen::Vector3i(dx, dy, dz);
            if ((m.array() < 0).any() || (m.array() >= dims_.array()).any()) continue;
            if (mask_[index(m)]) {
              near_[c] = 1;
              break;
            }
          }
    }
    return near_[c] == 1;
  }
  /// The interior vertex of a move between a whole cell and a sub-cell of a neighbouring
  /// cell: the sub-cell's centre moved onto the face the two cells share. Written to
  /// `point`; false (no vertex) for any other move.
  bool via(Id u, Id v, Eigen::Vector3d& point) const {
    if (u >= kGoal || v >= kGoal || fine(u) == fine(v)) return false;
    const Id f = fine(u) ? u : v;
    const std::size_t cw = cell(fine(u) ? v : u);
    const Eigen::Vector3i fc = fine_coords(f);
    const Eigen::Vector3i wc = cell_coords(dims_, cw);
    point = position(f);
    for (int a = 0; a < 3; ++a) {
      const int wf = wc[a] * k_[a];  // the whole cell's first sub-cell along a
      if (fc[a] < wf) point[a] = origin_[a] + wc[a] * cell_[a];  // sub-cell below: the lower face
      else if (fc[a] >= wf + k_[a]) point[a] = origin_[a] + (wc[a] + 1) * cell_[a];  // above: the upper
    }
    return true;
  }
  /// Whether the move u -> v is collision-free. On a box map, moves within and between whole
  /// cells need no test (see the file comment); on a voxel map every piece is tested.
  bool move_free(Id u, Id v, std::size_t& tests) const {
    const bool wu = u < n_, wv = v < n_;
    if (wu && wv && box_only_) return true;
    Eigen::Vector3d p;
    if (via(u, v, p)) {
      const Id f = fine(u) ? u : v;
      ++tests;
      if (!map_.segment_free(p, position(f), r_)) return false;
      if (box_only_) return true;
      ++tests;
      return map_.segment_free(position(f == u ? v : u), p, r_);
    }
    ++tests;
    return map_.segment_free(position(u), position(v), r_);
  }
  double move_length(Id u, Id v) const {
    Eigen::Vector3d p;
    if (via(u, v, p)) return (position(u) - p).norm() + (p - position(v)).norm();
    return (position(u) - position(v)).norm();
  }
  /// Length plus the penalty for entering a cell outside H.
  double move_cost(Id u, Id v) const {
    const std::size_t cu = cell(u), cv = cell(v);
    return move_length(u, v) + (cu != cv && !mask_[cv] ? penalty_ : 0.0);
  }

  template <typename F>
  void successors(Id u, F&& emit) {
    const std::size_t goal_cell = cell(kGoal);
    if (u == kStart) {
      const std::size_t cs = cell(kStart);
      if (whole(cs)) {
        emit(static_cast<Id>(cs));
        return;
      }
      // Every sub-cell of the start's cell (a box: the segment to it stays inside), nearest
      // first by the queue's order.
      emit_block(cell_coords(dims_, cs), emit);
      return;
    }
    if (!fine(u)) {
      const std::size_t cu = static_cast<std::size_t>(u);
      if (cu == goal_cell) emit(kGoal);
      const Eigen::Vector3i c = cell_coords(dims_, cu);
      for (int a = 0; a < 3; ++a)
        for (int step : {-1, 1}) {
          Eigen::Vector3i m = c;
          m[a] += step;
          if (m[a] < 0 || m[a] >= dims_[a]) continue;
          const std::size_t cm = index(m);
          if (!allowed(cm)) continue;
          if (whole(cm)) {
            emit(static_cast<Id>(cm));
            continue;
          }
          // The sub-cells of m on the face shared with c.
          const int b = (a + 1) % 3, d = (a + 2) % 3;
          Eigen::Vector3i f;
          f[a] = step > 0 ? m[a] * k_[a] : m[a] * k_[a] + k_[a] - 1;
          for (int i = 0; i < k_[b]; ++i)
            for (int j = 0; j < k_[d]; ++j) {
              f[b] = m[b] * k_[b] + i;
              f[d] = m[d] * k_[d] + j;
              emit(fine_id(f));
            }
        }
      return;
    }
    const Eigen::Vector3i f = fine_coords(u);
    const std::size_t cu = index(cell_of_fine(f));
    if (cu == goal_cell) emit(kGoal);  // inside one box: the segment stays in the cell
    for (int a = 0; a < 3; ++a)
      for (int step : {-1, 1}) {
        Eigen::Vector3i t = f;
        t[a] += step;
        if (t[a] < 0 || t[a] >= fine_[a]) continue;
        const std::size_t ct = index(cell_of_fine(t));
        if (ct == cu) {
          emit(fine_id(t));
          continue;
        }
        if (!allowed(ct)) continue;
        emit(whole(ct) ? static_cast<Id>(ct) : fine_id(t));
      }
  }

  template <typename F>
  void emit_block(const Eigen::Vector3i& c, F&& emit) const {
    for (int z = 0; z < k_.z(); ++z)
      for (int y = 0; y < k_.y(); ++y)
        for (int x = 0; x < k_.x(); ++x)
          emit(fine_id(c.cwiseProduct(k_) + Eigen::Vector3i(x, y, z)));
  }

  double to_goal(Id id) const { return (position(id) - goal_).norm(); }

 private:
  const world::Map& map_;
  double r_;
  Eigen::Vector3i dims_;
  const std::vector<std::uint8_t>& env_;
  const std::vector<std::uint8_t>& mask_;
  Eigen::Vector3d start_, goal_, origin_, cell_, sub_;
  Eigen::Vector3i k_, fine_;
  Id n_;
  bool box_only_;
  double penalty_ = 0.0;
  std::vector<std::uint8_t> near_;  ///< per cell: 0 not yet known, 1 near H, 2 not
};

struct Node {
  double g = 0.0;
  Id parent = kNone;
  bool closed = false;
};

struct Candidate {
  double f, g;
  Id id, parent;
  bool operator>(const Candidate& o) const {
    if (f != o.f) return f > o.f;
    if (g != o.g) return g < o.g;  // deeper first among equals: fewer expansions
    return id > o.id;              // a total order: the same bytes on every run
  }
};

}  // namespace

StrictBridgeReport strict_bridge(const world::Map& map, double robot_radius, const Eigen::Vector3i& dims,
                                 const std::vector<std::uint8_t>& env, std::vector<std::uint8_t>& mask,
                                 const Eigen::Vector3d& start, const Eigen::Vector3d& goal) {
  StrictBridgeReport rep;
  if (!map.in_bounds(start) || !map.in_bounds(goal)) return rep;
  rep.searched = true;
  Graph graph(map, kStrictClearance * robot_radius, dims, env, mask, start, goal);
  std::unordered_map<Id, Node> nodes;
  std::priority_queue<Candidate, std::vector<Candidate>, std::greater<>> open;
  open.push({kStrictGreed * graph.to_goal(kStart), 0.0, kStart, kNone});
  bool reached = false;
  while (!open.empty()) {
    const Candidate top = open.top();
    open.pop();
    auto it = nodes.find(top.id);
    if (it != nodes.end() && it->second.closed) continue;
    // Lazy test: the move is tested when taken (the start has no move).
    if (top.parent != kNone && !graph.move_free(top.parent, top.id, rep.segment_tests)) continue;
    if (rep.expansions == kStrictMaxExpansions || rep.segment_tests >= kStrictMaxTests) {
      rep.budget_exhausted = true;
      break;
    }
    ++rep.expansions;
    Node& node = nodes[top.id];
    node = {top.g, top.parent, true};
    if (top.id == kGoal) {
      reached = true;
      break;
    }
    const Id u = top.id;
    const double gu = top.g;
    graph.successors(u, [&](Id v) {
      const auto found = nodes.find(v);
      if (found != nodes.end() && found->second.closed) return;
      const double g = gu + graph.move_cost(u, v);
      open.push({g + kStrictGreed * graph.to_goal(v), g, v, u});
    });
  }
  if (!reached) return rep;

  // The witness, start to goal, with the crossing points of whole/sub-cell moves.
  std::vector<Id> chain;
  for (Id id = kGoal; id != kNone; id = nodes.at(id).parent) chain.push_back(id);
  std::reverse(chain.begin(), chain.end());
  std::vector<Eigen::Vector3d> line{graph.position(chain.front())};
  for (std::size_t i = 1; i < chain.size(); ++i) {
    Eigen::Vector3d p;
    if (graph.via(chain[i - 1], chain[i], p)) line.push_back(p);
    line.push_back(graph.position(chain[i]));
  }
  std::vector<std::size_t> added;
  for (const Id id : chain) {
    const std::size_t c = graph.cell(id);
    if (!mask[c] && env[c] != kSolid) {
      mask[c] = 1;
      added.push_back(c);
    }
  }
  // Checked before it is returned: collision-free and inside the repaired H.
  const world::Box& b = map.bounds();
  auto in_h = [&](const Eigen::Vector3d& p) { return mask[graph.index(cell_of(b, dims, p))] != 0; };
  bool ok = in_h(line.front());
  for (std::size_t i = 1; i < line.size() && ok; ++i)
    ok = map.segment_free(line[i - 1], line[i], kStrictClearance * robot_radius) && in_h(line[i]) && in_h(0.5 * (line[i - 1] + line[i]));
  if (!ok) {
    for (const std::size_t c : added) mask[c] = 0;
    return rep;
  }
  rep.connected = true;
  rep.added = added.size();
  rep.polyline = std::move(line);
  return rep;
}

}  // namespace miner::heuristic
