#pragma once
/// \file
/// Alg. 1 line 3, H <- Filter(H), and the whole heuristic query: encode E and S for a map
/// and a query, run the sGAN, threshold, filter, hand the region to the MINER sampler.
///
/// The filter (REQ-HEUR-007), on the heuristic grid (grid.hpp):
///   1. threshold: raw H = {cells with R >= threshold}, the threshold fixed or, with the
///      weights' rule "widest" (REQ-HEUR-016), lowered to the widest start-goal chain's;
///   2. safety: drop the solid cells; add the start and goal cells (not solid for query points
///      free for the robot radius; a solid one is not added, and the report then says the
///      region is not connected);
///   3. islands: keep only the 26-connected components that hold the start or the goal cell;
///   4. bridge: if start and goal are still apart, add the cheapest chain of non-solid cells
///      joining their components (a cell already in H costs 0, any other 1 + (1 - R)), grown
///      by one cell within the non-solid cells so the planner has room to sample around it.
/// The result is safe by construction and connected whenever the non-solid cells connect
/// start and goal at all (always when A* finds a path: its cells are never solid).
///   5. (opt-in) strict bridge (strict_bridge.hpp, REQ-HEUR-014): on the continuous map, a checked
///      collision-free polyline for the robot radius from start to goal inside H, H growing
///      by the cells it has to leave H through (none when H already holds one).
/// The report says what each step changed, so the raw network's quality stays visible.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "miner/plan/heuristic_region.hpp"
#include "miner/world/box.hpp"

namespace miner {
namespace world {
class Map;
}
}  // namespace miner

namespace miner::heuristic {

class Sgan;

struct FilterReport {
  double threshold = 0.0;          ///< the threshold step 1 used (the rule's, REQ-HEUR-016)
  std::size_t raw_cells = 0;       ///< cells with R >= threshold
  bool raw_connected = false;      ///< REQ-HEUR-004 on the raw cells
  bool raw_safe = false;
  std::size_t solid_dropped = 0;   ///< step 2
  std::size_t island_dropped = 0;  ///< step 3
  std::size_t bridge_cells = 0;    ///< step 4 (0: no bridge was needed or none exists)
  std::size_t cells = 0;           ///< cells in the filtered region
  bool connected = false;          ///< REQ-HEUR-004 on the filtered region
  bool safe = false;
  bool strict_searched = false;    ///< step 5 ran
  bool strict_connected = false;   ///< step 5 found and checked a polyline inside H
  std::size_t strict_cells = 0;    ///< step 5: cells added
  std::size_t strict_expansions = 0;
  bool strict_budget_exhausted = false;
};

struct FilteredRegion {
  std::vector<std::uint8_t> mask;  ///< 1 = in H, x fastest
  FilterReport report;
};

/// Throws miner::Error for grids of different sizes, a cell outside the grid, an E level above
/// 2, a probability outside [0, 1] or a NaN threshold.
FilteredRegion filter_region(const std::vector<float>& probabilities, const std::vector<std::uint8_t>& environment,
                             const Eigen::Vector3i& dims, const Eigen::Vector3i& start_cell,
                             const Eigen::Vector3i& goal_cell, double threshold);

/// The widest-path threshold (REQ-HEUR-016): the largest t such that the non-solid cells with
/// R >= t join the start cell to the goal cell (26-connected), i.e. the maximum over chains of
/// non-solid cells from start to goal of the smallest R on the chain (both ends included).
/// nullopt when no chain of non-solid cells joins them (or an end is solid). With channel P
/// (`passability` not empty, grid.hpp) a step that moves along axis a needs bit a in both of
/// its cells, so the chain does not cross a wall cell where its free space does not.
/// A modified Dijkstra (each cell settled once, at its best bottleneck): O(n log n).
std::optional<float> widest_threshold(const std::vector<float>& probabilities, const std::vector<std::uint8_t>& environment,
                                      const Eigen::Vector3i& dims, const Eigen::Vector3i& start_cell,
                                      const Eigen::Vector3i& goal_cell,
                                      const std::vector<std::uint8_t>& passability = {});

/// The lowest threshold the widest rule sets: a chain rated below 1e-4 somewhere is no
/// evidence of a way through (the sigmoid's tail, down to exactly 0, which no threshold may be).
inline constexpr double kWidestFloor = 1e-4;

/// Step 1's threshold for the architecture's rule: the fixed threshold t0, or with the rule
/// "widest" min(t0, max(widest_threshold, kWidestFloor)) (t0 when no chain exists), so the raw
/// region joins start and goal on the grid whenever the non-solid cells do through cells rated
/// at least kWidestFloor, and is the fixed rule's when that already does.
double region_threshold(const std::vector<float>& probabilities, const std::vector<std::uint8_t>& environment,
                        const Eigen::Vector3i& dims, const Eigen::Vector3i& start_cell, const Eigen::Vector3i& goal_cell,
                        double threshold, bool widest, const std::vector<std::uint8_t>& passability = {});

/// One heuristic query (Alg. 1 lines 2-3) for `map` and a start and goal.
struct HeuristicQuery {
  plan::HeuristicRegion region;            ///< filtered (source "sgan-filtered") or raw ("sgan-raw")
  std::vector<float> probabilities;        ///< R, the network output
  std::vector<std::uint8_t> environment;   ///< E levels
  FilterReport report;
  std::vector<Eigen::Vector3d> strict_witness;  ///< step 5's polyline, start to goal (empty if none)
  double encode_ms = 0.0, inference_ms = 0.0, filter_ms = 0.0;
};

/// Encodes E (obstacles grown by robot_radius) and S on the network's grid over the map
/// bounds, runs the generator with noise from Rng(seed, stream 0x5347414e) and filters
/// (or, with filter = false, only thresholds) the output; step 5 runs only with strict = true
/// (opt-in: it costs 0.2-5 ms a query, docs/heuristic.md). Throws miner::Error unless the
/// query is a planner's: start and goal finite, in the bounds and free at robot_radius, the
/// radius in [0, kMaxRobotRadius].
HeuristicQuery query_region(const Sgan& sgan, const world::Map& map, const Eigen::Vector3d& start,
                            const Eigen::Vector3d& goal, double robot_radius, std::uint64_t seed, bool filter = true,
                            bool strict = false);

}  // namespace miner::heuristic
