#include "miner/heuristic/region_filter.hpp"

#include <chrono>
#include <functional>
#include <limits>
#include <queue>

#include "miner/core/error.hpp"
#include "miner/core/rng.hpp"
#include "miner/core/stopwatch.hpp"
#include "miner/heuristic/grid.hpp"
#include "miner/heuristic/sgan.hpp"
#include "miner/heuristic/strict_bridge.hpp"
#include "miner/world/map.hpp"

namespace miner::heuristic {

namespace {

/// RNG stream of the generator's noise ("SGAN"), apart from the planners' streams.
constexpr std::uint64_t kNoiseStream = streams::kSganNoise;

template <typename F>
void for_neighbours(const Eigen::Vector3i& dims, const Eigen::Vector3i& c, F&& f) {
  for (int dk = -1; dk <= 1; ++dk)
    for (int dj = -1; dj <= 1; ++dj)
      for (int di = -1; di <= 1; ++di) {
        if (!di && !dj && !dk) continue;
        const Eigen::Vector3i n = c + Eigen::Vector3i(di, dj, dk);
        if ((n.array() < 0).any() || (n.array() >= dims.array()).any()) continue;
        f(n, cell_index(dims, n.x(), n.y(), n.z()));
      }
}

/// Throws unless R, E and (when given) P each hold one value per cell of the grid.
void require_one_grid(const std::vector<float>& p, const std::vector<std::uint8_t>& env,
                      const std::vector<std::uint8_t>& passability, const Eigen::Vector3i& dims,
                      const Eigen::Vector3i& start_cell, const Eigen::Vector3i& goal_cell) {
  if ((dims.array() < 1).any()) throw Error("region filter: every grid dimension must be at least 1");
  const auto n = static_cast<std::size_t>(dims.x()) * static_cast<std::size_t>(dims.y()) * static_cast<std::size_t>(dims.z());
  if (p.size() != n || env.size() != n || (!passability.empty() && passability.size() != n))
    throw Error("region filter: grids of different sizes");
  // Fourteenth campaign L5: E level 9 and NaN probabilities were taken silently.
  require_levels(env, kSolid, "region filter: E");
  require_levels(passability, kPassAll, "region filter: P");
  if (const std::size_t i = first_non_probability(p); i != n)
    throw Error("region filter: R cell " + std::to_string(i) + " is " + std::to_string(p[i]) + ", not a probability");
  // Tenth campaign L4: a cell outside the grid corrupted the heap (filter_region) or read
  // outside it (widest_threshold).
  require_cell_in_grid(start_cell, dims, "region filter: the start cell");
  require_cell_in_grid(goal_cell, dims, "region filter: the goal cell");
}

/// A chain's step from cell u to its neighbour v: v not solid and, with channel P, every axis
/// the step moves along passable in both cells.
bool step_allowed(const std::vector<std::uint8_t>& env, const std::vector<std::uint8_t>& passability,
                  const Eigen::Vector3i& cu, std::size_t u, const Eigen::Vector3i& cv, std::size_t v) {
  if (env[v] == kSolid) return false;
  if (passability.empty()) return true;
  std::uint8_t along = 0;
  for (int a = 0; a < 3; ++a)
    if (cv[a] != cu[a]) along |= static_cast<std::uint8_t>(1u << a);
  return (passability[u] & along) == along && (passability[v] & along) == along;
}

/// Whether a chain of allowed steps through cells with R >= t joins start and goal (both
/// ends with R >= t): a breadth-first search over those cells alone.
bool chain_at(const std::vector<float>& p, const std::vector<std::uint8_t>& env,
              const std::vector<std::uint8_t>& passability, const Eigen::Vector3i& dims, std::size_t is, std::size_t ig,
              double t) {
  if (!(p[is] >= t) || !(p[ig] >= t)) return false;
  std::vector<std::uint8_t> seen(p.size(), 0);
  std::vector<std::size_t> queue{is};
  seen[is] = 1;
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const std::size_t u = queue[head];
    if (u == ig) return true;
    const Eigen::Vector3i cu = cell_coords(dims, u);
    for_neighbours(dims, cu, [&](const Eigen::Vector3i& cv, std::size_t v) {
      if (!seen[v] && p[v] >= t && step_allowed(env, passability, cu, u, cv, v)) {
        seen[v] = 1;
        queue.push_back(v);
      }
    });
  }
  return false;
}

/// widest_threshold() on inputs require_one_grid() has checked (region_threshold() checks once
/// and may search twice).
std::optional<float> widest_chain(const std::vector<float>& p, const std::vector<std::uint8_t>& env,
                                  const Eigen::Vector3i& dims, const Eigen::Vector3i& start_cell,
                                  const Eigen::Vector3i& goal_cell, const std::vector<std::uint8_t>& passability) {
  const auto n = static_cast<std::size_t>(dims.prod());
  const std::size_t is = cell_index(dims, start_cell.x(), start_cell.y(), start_cell.z());
  const std::size_t ig = cell_index(dims, goal_cell.x(), goal_cell.y(), goal_cell.z());
  if (env[is] == kSolid || env[ig] == kSolid) return std::nullopt;
  // best[v]: the largest bottleneck of a chain from the start to v found so far; a max-heap
  // settles cells in decreasing bottleneck, so the goal's first pop is its widest chain.
  std::vector<float> best(n, -1.0f);
  std::vector<std::uint8_t> settled(n, 0);
  using Item = std::pair<float, std::size_t>;
  std::priority_queue<Item> open;
  best[is] = p[is];
  open.emplace(p[is], is);
  while (!open.empty()) {
    const float b = open.top().first;
    const std::size_t u = open.top().second;
    open.pop();
    if (settled[u]) continue;
    settled[u] = 1;
    if (u == ig) return b;
    const Eigen::Vector3i cu = cell_coords(dims, u);
    for_neighbours(dims, cu, [&](const Eigen::Vector3i& cv, std::size_t v) {
      if (settled[v] || !step_allowed(env, passability, cu, u, cv, v)) return;
      const float w = std::min(b, p[v]);
      if (w > best[v]) {
        best[v] = w;
        open.emplace(w, v);
      }
    });
  }
  return std::nullopt;
}

}  // namespace

std::optional<float> widest_threshold(const std::vector<float>& p, const std::vector<std::uint8_t>& env,
                                      const Eigen::Vector3i& dims, const Eigen::Vector3i& start_cell,
                                      const Eigen::Vector3i& goal_cell, const std::vector<std::uint8_t>& passability) {
  require_one_grid(p, env, passability, dims, start_cell, goal_cell);
  return widest_chain(p, env, dims, start_cell, goal_cell, passability);
}

namespace {

/// region_threshold() on inputs require_one_grid() has checked, with the widest-chain rule.
double widest_rule_threshold(const std::vector<float>& p, const std::vector<std::uint8_t>& env,
                             const Eigen::Vector3i& dims, const Eigen::Vector3i& start_cell,
                             const Eigen::Vector3i& goal_cell, double threshold,
                             const std::vector<std::uint8_t>& passability) {
  const std::size_t is = cell_index(dims, start_cell.x(), start_cell.y(), start_cell.z());
  const std::size_t ig = cell_index(dims, goal_cell.x(), goal_cell.y(), goal_cell.z());
  // Most queries: the fixed threshold's cells already hold a chain (a search of those alone).
  if (env[is] != kSolid && env[ig] != kSolid && chain_at(p, env, passability, dims, is, ig, threshold)) return threshold;
  std::optional<float> w = widest_chain(p, env, dims, start_cell, goal_cell, passability);
  // P is decided on sub-cells: a door narrower than one may leave no chain through it; then
  // the chain is sought without P.
  if (!w && !passability.empty()) w = widest_chain(p, env, dims, start_cell, goal_cell, {});
  if (!w) return threshold;
  // A chain whose weakest cell the network rates below kWidestFloor is no evidence (the
  // sigmoid's saturated tail, down to exactly 0, which no region threshold may be): the
  // threshold stops there and the filter's bridge (step 4) joins what it leaves apart.
  return std::min(threshold, std::max(static_cast<double>(*w), kWidestFloor));
}

/// filter_region() on inputs require_one_grid() has checked and a threshold that is a number.
FilteredRegion filter_checked(const std::vector<float>& p, const std::vector<std::uint8_t>& env,
                              const Eigen::Vector3i& dims, const Eigen::Vector3i& start_cell,
                              const Eigen::Vector3i& goal_cell, double threshold) {
  const auto n = static_cast<std::size_t>(dims.prod());
  FilteredRegion out;
  FilterReport& r = out.report;
  std::vector<std::uint8_t> mask(n, 0);
  for (std::size_t i = 0; i < n; ++i) mask[i] = p[i] >= threshold ? 1 : 0;
  r.threshold = threshold;
  r.raw_cells = static_cast<std::size_t>(std::count(mask.begin(), mask.end(), 1));
  r.raw_safe = solid_cells_in(mask, env) == 0;
  const std::size_t is = cell_index(dims, start_cell.x(), start_cell.y(), start_cell.z());
  const std::size_t ig = cell_index(dims, goal_cell.x(), goal_cell.y(), goal_cell.z());
  // Steps 2-3 usually change nothing (a safe raw region holding start and goal); then the raw
  // connectivity is read off step 3's search instead of a search of its own.
  const bool raw_kept = r.raw_safe && mask[is] && mask[ig];
  if (!raw_kept) r.raw_connected = connects(mask, dims, start_cell, goal_cell);
  // 2. safety
  for (std::size_t i = 0; i < n; ++i)
    if (mask[i] && env[i] == kSolid) {
      mask[i] = 0;
      ++r.solid_dropped;
    }
  for (std::size_t i : {is, ig})
    if (env[i] != kSolid) mask[i] = 1;
  // 3. islands: only the components of start and goal stay.
  const std::vector<std::uint8_t> from_start = component_of(mask, dims, is);
  // Connected now iff the goal is in the start's component; the bridge below joins them.
  bool joined = from_start[ig] != 0;
  if (raw_kept) r.raw_connected = joined;
  const std::vector<std::uint8_t> from_goal = joined ? from_start : component_of(mask, dims, ig);
  for (std::size_t i = 0; i < n; ++i)
    if (mask[i] && !from_start[i] && !from_goal[i]) {
      mask[i] = 0;
      ++r.island_dropped;
    }
  // 4. bridge: Dijkstra over non-solid cells from the start's component to the goal's.
  if (mask[is] && mask[ig] && !joined) {
    const double inf = std::numeric_limits<double>::infinity();
    std::vector<double> dist(n, inf);
    std::vector<std::size_t> parent(n, n);
    using Item = std::pair<double, std::size_t>;
    std::priority_queue<Item, std::vector<Item>, std::greater<>> open;
    for (std::size_t i = 0; i < n; ++i)
      if (from_start[i]) {
        dist[i] = 0.0;
        open.emplace(0.0, i);
      }
    std::size_t reached = n;
    while (!open.empty()) {
      // Named copies, not a structured binding: the lambda below captures them (C++17 does
      // not allow capturing a binding; g++ accepts it, clang does not).
      const double d = open.top().first;
      const std::size_t u = open.top().second;
      open.pop();
      if (d > dist[u]) continue;
      if (from_goal[u]) {
        reached = u;
        break;
      }
      for_neighbours(dims, cell_coords(dims, u), [&](const Eigen::Vector3i&, std::size_t v) {
        if (env[v] == kSolid) return;
        const double step = mask[v] ? 0.0 : 1.0 + (1.0 - static_cast<double>(p[v]));
        if (d + step < dist[v]) {
          dist[v] = d + step;
          parent[v] = u;
          open.emplace(dist[v], v);
        }
      });
    }
    if (reached != n) {
      joined = true;
      std::vector<std::size_t> chain;
      for (std::size_t c = reached; c != n; c = parent[c])
        if (!mask[c]) chain.push_back(c);
      for (std::size_t c : chain) {
        if (!mask[c]) {
          mask[c] = 1;
          ++r.bridge_cells;
        }
        for_neighbours(dims, cell_coords(dims, c), [&](const Eigen::Vector3i&, std::size_t v) {
          if (!mask[v] && env[v] != kSolid) {
            mask[v] = 1;
            ++r.bridge_cells;
          }
        });
      }
    }
  }
  r.cells = static_cast<std::size_t>(std::count(mask.begin(), mask.end(), 1));
  r.connected = joined;  // equals connects(mask, ...): the filter tests check both
  r.safe = solid_cells_in(mask, env) == 0;
  out.mask = std::move(mask);
  return out;
}

/// Fourteenth campaign L5: a NaN threshold came back as the threshold (region_threshold) or
/// kept no cell (filter_region).
void require_threshold(double threshold) {
  if (std::isnan(threshold)) throw Error("region filter: threshold must be a number, got nan");
}

}  // namespace

double region_threshold(const std::vector<float>& p, const std::vector<std::uint8_t>& env, const Eigen::Vector3i& dims,
                        const Eigen::Vector3i& start_cell, const Eigen::Vector3i& goal_cell, double threshold,
                        bool widest, const std::vector<std::uint8_t>& passability) {
  require_threshold(threshold);
  if (!widest) return threshold;
  require_one_grid(p, env, passability, dims, start_cell, goal_cell);
  return widest_rule_threshold(p, env, dims, start_cell, goal_cell, threshold, passability);
}

FilteredRegion filter_region(const std::vector<float>& p, const std::vector<std::uint8_t>& env,
                             const Eigen::Vector3i& dims, const Eigen::Vector3i& start_cell,
                             const Eigen::Vector3i& goal_cell, double threshold) {
  require_one_grid(p, env, {}, dims, start_cell, goal_cell);
  require_threshold(threshold);
  return filter_checked(p, env, dims, start_cell, goal_cell, threshold);
}

HeuristicQuery query_region(const Sgan& sgan, const world::Map& map, const Eigen::Vector3d& start,
                            const Eigen::Vector3d& goal, double robot_radius, std::uint64_t seed, bool filter,
                            bool strict) {
  // The query is one a planner would take (issue 20, ninth campaign P2, P3: a NaN start crashed
  // the cell lookup, a start inside an obstacle or outside the map got a region).
  world::check_robot_radius(robot_radius, "robot_radius");
  map.require_free(start, robot_radius, "start");
  map.require_free(goal, robot_radius, "goal");
  const SganArchitecture& arch = sgan.architecture();
  const world::Box& b = map.bounds();
  const Eigen::Vector3i dims = arch.dims;
  auto t0 = std::chrono::steady_clock::now();
  // P only for a network that reads it (the encoding costs a flood per partial cell).
  Encoding encoded;
  if (arch.passability_channels != 0)
    encoded = encode_environment_passability(map, dims, robot_radius);
  else
    encoded.environment = encode_environment(map, dims, robot_radius);
  std::vector<std::uint8_t>& env = encoded.environment;
  // The network was trained with the dataset's 3x3x3 state cubes (dilation 1).
  const std::vector<std::uint8_t> state = encode_state(b, dims, start, goal, 1);
  const double encode_ms = elapsed_ms(t0);
  t0 = std::chrono::steady_clock::now();
  Rng rng(seed, kNoiseStream);
  std::vector<float> prob = sgan.predict(env, state, encoded.passability, b, robot_radius, rng);
  const double inference_ms = elapsed_ms(t0);
  t0 = std::chrono::steady_clock::now();
  const Eigen::Vector3i start_cell = cell_of(b, dims, start), goal_cell = cell_of(b, dims, goal);
  // One check of the grids for the two steps below (each public step checks its own inputs).
  require_one_grid(prob, env, encoded.passability, dims, start_cell, goal_cell);
  require_threshold(arch.threshold);
  const double threshold =
      arch.threshold_rule == ThresholdRule::kWidest
          ? widest_rule_threshold(prob, env, dims, start_cell, goal_cell, arch.threshold, encoded.passability)
          : arch.threshold;
  FilteredRegion f = filter_checked(prob, env, dims, start_cell, goal_cell, threshold);
  std::vector<Eigen::Vector3d> witness;
  if (filter && strict) {
    StrictBridgeReport s = strict_bridge(map, robot_radius, dims, env, f.mask, start, goal);
    FilterReport& r = f.report;
    r.strict_searched = s.searched;
    r.strict_connected = s.connected;
    r.strict_cells = s.added;
    r.strict_expansions = s.expansions;
    r.strict_budget_exhausted = s.budget_exhausted;
    r.cells += s.added;
    witness = std::move(s.polyline);
  }
  std::vector<double> probabilities(prob.size(), 0.0);
  if (filter) {
    for (std::size_t i = 0; i < prob.size(); ++i) probabilities[i] = f.mask[i] ? 1.0 : 0.0;
  } else {
    for (std::size_t i = 0; i < prob.size(); ++i) probabilities[i] = static_cast<double>(prob[i]);
  }
  const double filter_ms = elapsed_ms(t0);
  plan::HeuristicRegion region(b, dims, std::move(probabilities), filter ? 0.5 : threshold,
                               filter ? "sgan-filtered" : "sgan-raw");
  region.set_map_fingerprint(map.fingerprint());
  return {std::move(region), std::move(prob), std::move(env), f.report, std::move(witness), encode_ms, inference_ms,
          filter_ms};
}

}  // namespace miner::heuristic
