// Map families beyond the paper's presets (REQ-WORLD-011): cluttered, rooms, forest,
// multilevel; and mixed (REQ-WORLD-020), their parts at random. Each draws its obstacles and query for bounds and a resolution that the
// caller (generate_map) drew per map, so one family spans sizes and aspect ratios.
#include <algorithm>
#include <cmath>

#include "miner/core/error.hpp"
#include "miner/world/map_generator.hpp"

namespace miner::world::detail {

namespace {

/// Every family coordinate is a multiple of this (short, exact JSON decimals).
constexpr double kQuantum = 0.05;

double q(double x) { return std::round(x / kQuantum) * kQuantum; }
Eigen::Vector3d q(const Eigen::Vector3d& p) { return {q(p.x()), q(p.y()), q(p.z())}; }

Box make_box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) { return {q(lo), q(hi)}; }

/// A point drawn uniformly in the box given by fractions of `b`'s extent.
Eigen::Vector3d point_at(Rng& rng, const Box& b, const Eigen::Vector3d& lo_frac, const Eigen::Vector3d& hi_frac) {
  Eigen::Vector3d p;
  for (int k = 0; k < 3; ++k) p[k] = b.min[k] + b.extent()[k] * rng.uniform(lo_frac[k], hi_frac[k]);
  return q(p);
}

/// Keeps p at least `margin` inside the bounds (a query point must fit the robot).
Eigen::Vector3d inside(const Box& b, Eigen::Vector3d p, double margin) {
  for (int k = 0; k < 3; ++k) p[k] = std::clamp(p[k], b.min[k] + margin, b.max[k] - margin);
  return q(p);
}

bool clear_of(const Box& box, const Query& query, double keep_free) {
  const double r2 = keep_free * keep_free;
  return squared_distance(query.start, box) > r2 && squared_distance(query.goal, box) > r2;
}

/// Clips a box to the bounds; false if nothing is left.
bool clip(Box& b, const Box& bounds) {
  b.min = b.min.cwiseMax(bounds.min);
  b.max = b.max.cwiseMin(bounds.max);
  return (b.max.array() > b.min.array()).all();
}

void add_clear(std::vector<Box>& out, Box b, const Box& bounds, const Query& query, double keep_free) {
  if (clip(b, bounds) && clear_of(b, query, keep_free)) out.push_back(b);
}

/// A wall along axis `along` (0: x, 1: y) from a to b at `at` on the other axis, thickness
/// t, height [z0, z1], with door gaps [g0, g1] (full height up to door_h, lintel above).
void wall_with_gaps(std::vector<Box>& out, int along, double a, double b, double at, double t, double z0,
                    double z1, std::vector<std::pair<double, double>> gaps, double door_h) {
  std::sort(gaps.begin(), gaps.end());
  const int across = 1 - along;
  const auto piece = [&](double u0, double u1, double h0, double h1) {
    if (!(u1 > u0) || !(h1 > h0)) return;
    Eigen::Vector3d lo, hi;
    lo[along] = u0;
    hi[along] = u1;
    lo[across] = at - 0.5 * t;
    hi[across] = at + 0.5 * t;
    lo.z() = h0;
    hi.z() = h1;
    out.push_back(make_box(lo, hi));
  };
  double u = a;
  for (const auto& [g0, g1] : gaps) {
    piece(u, g0, z0, z1);
    piece(g0, g1, std::min(z0 + door_h, z1), z1);  // lintel over the door
    u = g1;
  }
  piece(u, b, z0, z1);
}

// ---------------------------------------------------------------- cluttered
FamilyDraw cluttered(const GeneratorPreset& p, Rng& rng, const Box& bounds, std::optional<int> count) {
  const Eigen::Vector3d e = bounds.extent();
  const double size = std::cbrt(e.prod());  // sides scale with the map's size
  const double margin = 2.0 * p.robot_radius;
  FamilyDraw d;
  d.query.robot_radius = p.robot_radius;
  d.query.start = inside(bounds, point_at(rng, bounds, {0.02, 0.02, 0.1}, {0.12, 0.12, 0.4}), margin);
  d.query.goal = inside(bounds, point_at(rng, bounds, {0.88, 0.88, 0.1}, {0.98, 0.98, 0.9}), margin);
  const int n = count ? *count : 50 + static_cast<int>(rng.uniform_index(61));  // 50-110 boxes
  const double keep_free = std::max(3.0 * p.robot_radius, 0.04 * size);
  for (int tries = 0; static_cast<int>(d.obstacles.size()) < n && tries < 100 * std::max(n, 1); ++tries) {
    Eigen::Vector3d side;
    for (int k = 0; k < 3; ++k) side[k] = std::min(rng.uniform(0.06, 0.22) * size, e[k]);
    Eigen::Vector3d lo;
    for (int k = 0; k < 3; ++k) lo[k] = bounds.min[k] + rng.uniform(0.0, e[k] - side[k]);
    const Box b = make_box(lo, lo + side);
    if (clear_of(b, d.query, keep_free)) d.obstacles.push_back(b);
  }
  return d;
}

// -------------------------------------------------------------------- rooms
FamilyDraw rooms(const GeneratorPreset& p, Rng& rng, const Box& bounds) {
  constexpr double kWall = 0.2;                 // wall thickness, m
  constexpr double kDoorHeight = 2.1;           // m
  constexpr double kMinRoom = 4.0, kMaxRoom = 9.0;
  constexpr double kFlightHeight = 1.2;         // start and goal height above the floor
  const Eigen::Vector3d e = bounds.extent();
  const double x0 = bounds.min.x(), y0 = bounds.min.y(), z0 = bounds.min.z(), z1 = bounds.max.z();
  const double door_h = std::min(kDoorHeight, e.z() - 0.4);
  FamilyDraw d;
  d.query.robot_radius = p.robot_radius;
  const double corridor_w = rng.uniform(1.8, 3.0);
  const double yc = y0 + q(rng.uniform(0.35, 0.65) * e.y());
  const double ys = yc - 0.5 * corridor_w, yn = yc + 0.5 * corridor_w;  // corridor walls

  // Room partitions along x, independently on the south and north side.
  struct Side {
    std::vector<double> cuts;  // partition x positions, including x0 and x_max
    double wall_y, far_y;      // corridor wall and the bound opposite it
  };
  Side sides[2];
  sides[0] = {{}, ys, y0};
  sides[1] = {{}, yn, bounds.max.y()};
  for (Side& s : sides) {
    s.cuts.push_back(x0);
    double x = x0;
    while (true) {
      const double w = rng.uniform(kMinRoom, kMaxRoom);
      if (x + w + kMinRoom > bounds.max.x()) break;
      x = q(x + w);
      s.cuts.push_back(x);
    }
    s.cuts.push_back(bounds.max.x());
  }
  // Start in the first south room, goal in the last north room.
  const auto room_centre = [&](const Side& s, std::size_t i) {
    return Eigen::Vector3d(0.5 * (s.cuts[i] + s.cuts[i + 1]), 0.5 * (s.wall_y + s.far_y), z0 + kFlightHeight);
  };
  d.query.start = q(room_centre(sides[0], 0));
  d.query.goal = q(room_centre(sides[1], sides[1].cuts.size() - 2));
  const double keep_free = 1.0;

  std::vector<Box> furniture;
  for (int si = 0; si < 2; ++si) {
    const Side& s = sides[si];
    std::vector<std::pair<double, double>> doors;
    for (std::size_t i = 0; i + 1 < s.cuts.size(); ++i) {
      const double a = s.cuts[i] + 0.5 * kWall + 0.4, b = s.cuts[i + 1] - 0.5 * kWall - 0.4;
      const double w = rng.uniform(0.9, 1.4);
      const double g0 = q(rng.uniform(a, std::max(a, b - w)));
      doors.emplace_back(g0, q(g0 + w));
    }
    wall_with_gaps(d.obstacles, 0, x0, bounds.max.x(), s.wall_y, kWall, z0, z1, doors, door_h);
    const double ylo = std::min(s.wall_y, s.far_y), yhi = std::max(s.wall_y, s.far_y);
    // Partitions between neighbouring rooms, some with a door between them.
    for (std::size_t i = 1; i + 1 < s.cuts.size(); ++i) {
      std::vector<std::pair<double, double>> gaps;
      if (rng.uniform01() < 0.4) {
        const double w = rng.uniform(0.9, 1.2);
        const double g0 = q(rng.uniform(ylo + 0.5, std::max(ylo + 0.5, yhi - 0.5 - w)));
        gaps.emplace_back(g0, q(g0 + w));
      }
      wall_with_gaps(d.obstacles, 1, ylo, yhi, s.cuts[i], kWall, z0, z1, gaps, door_h);
    }
    // Furniture: 0-3 pieces per room, against the far wall or free-standing, never in
    // front of the corridor door.
    for (std::size_t i = 0; i + 1 < s.cuts.size(); ++i) {
      const int pieces = static_cast<int>(rng.uniform_index(4));
      const Box door_zone{{doors[i].first - 0.6, s.wall_y - 1.5, z0}, {doors[i].second + 0.6, s.wall_y + 1.5, z1}};
      for (int k = 0; k < pieces; ++k) {
        const bool shelf = rng.uniform01() < 0.4;
        const Eigen::Vector3d size = shelf ? Eigen::Vector3d(rng.uniform(1.0, 2.0), rng.uniform(0.4, 0.6),
                                                             std::min(rng.uniform(1.8, 2.2), e.z() - 0.3))
                                           : Eigen::Vector3d(rng.uniform(1.2, 2.0), rng.uniform(0.6, 1.0), 0.75);
        const double xa = s.cuts[i] + 0.5 * kWall, xb = s.cuts[i + 1] - 0.5 * kWall;
        const double ya = ylo + (si == 0 ? 0.0 : 0.5 * kWall), yb = yhi - (si == 0 ? 0.5 * kWall : 0.0);
        if (xb - xa <= size.x() || yb - ya <= size.y()) continue;
        Eigen::Vector3d lo(rng.uniform(xa, xb - size.x()), rng.uniform(ya, yb - size.y()), z0);
        if (shelf) lo.y() = si == 0 ? ya : yb - size.y();  // shelves against the outer wall
        const Box b = make_box(lo, lo + size);
        if (!b.overlaps(door_zone) && clear_of(b, d.query, keep_free)) furniture.push_back(b);
      }
    }
  }
  for (const Box& b : furniture) d.obstacles.push_back(b);
  return d;
}

// ------------------------------------------------------------------- forest
FamilyDraw forest(const GeneratorPreset& p, Rng& rng, const Box& bounds, std::optional<int> count) {
  const Eigen::Vector3d e = bounds.extent();
  FamilyDraw d;
  d.query.robot_radius = p.robot_radius;
  const double margin = 2.0 * p.robot_radius;
  const Eigen::Vector3d h(0.0, 0.0, 1.0);
  d.query.start = inside(bounds, point_at(rng, bounds, {0.01, 0.01, 0.0}, {0.06, 0.06, 0.0}) + h * rng.uniform(1.0, 3.0), margin);
  d.query.goal = inside(bounds, point_at(rng, bounds, {0.94, 0.94, 0.0}, {0.99, 0.99, 0.0}) + h * rng.uniform(1.0, 3.0), margin);
  const double density = rng.uniform(3.0, 9.0);  // trunks per 100 m^2
  const int n = count ? *count : static_cast<int>(std::round(density * e.x() * e.y() / 100.0));
  const double keep_free = 1.0;
  int trunks = 0;
  for (int tries = 0; trunks < n && tries < 100 * std::max(n, 1); ++tries) {
    const double side = rng.uniform(0.2, 0.6);
    const double height = rng.uniform01() < 0.7 ? e.z() : rng.uniform(0.5, 0.9) * e.z();
    const Eigen::Vector3d lo(bounds.min.x() + rng.uniform(0.0, e.x() - side), bounds.min.y() + rng.uniform(0.0, e.y() - side),
                             bounds.min.z());
    const Box trunk = make_box(lo, lo + Eigen::Vector3d(side, side, height));
    if (!clear_of(trunk, d.query, keep_free)) continue;
    d.obstacles.push_back(trunk);
    ++trunks;
    // Branches: horizontal bars 1-3 m long from the trunk at 2 m up to 0.8 of its height.
    const int branches = static_cast<int>(rng.uniform_index(3));
    for (int b = 0; b < branches; ++b) {
      const double len = rng.uniform(1.0, 3.0), z = bounds.min.z() + rng.uniform(2.0, std::max(2.0, 0.8 * height));
      const int axis = static_cast<int>(rng.uniform_index(2));
      const double dir = rng.uniform01() < 0.5 ? -1.0 : 1.0;
      Eigen::Vector3d c = trunk.center();
      c.z() = z;
      Eigen::Vector3d lo_b = c - Eigen::Vector3d(0.075, 0.075, 0.075), hi_b = c + Eigen::Vector3d(0.075, 0.075, 0.075);
      if (dir > 0) hi_b[axis] += len;
      else lo_b[axis] -= len;
      add_clear(d.obstacles, make_box(lo_b, hi_b), bounds, d.query, keep_free);
    }
  }
  return d;
}

// --------------------------------------------------------------- multilevel
FamilyDraw multilevel(const GeneratorPreset& p, Rng& rng, const Box& bounds) {
  constexpr double kSlab = 0.3, kWall = 0.2, kDoorHeight = 2.1, kFlightHeight = 1.2;
  const Eigen::Vector3d e = bounds.extent();
  const double x0 = bounds.min.x(), y0 = bounds.min.y(), z0 = bounds.min.z();
  // Storeys of 3-4.5 m fill the height.
  const int storeys = std::max(2, static_cast<int>(std::floor(e.z() / 3.0)));
  const double storey = e.z() / storeys;
  const double tile = rng.uniform(4.0, 6.0);
  const int nx = std::max(2, static_cast<int>(e.x() / tile)), ny = std::max(2, static_cast<int>(e.y() / tile));
  const double tx = e.x() / nx, ty = e.y() / ny;
  FamilyDraw d;
  d.query.robot_radius = p.robot_radius;
  d.query.start = q(Eigen::Vector3d(x0 + 0.5 * tx, y0 + 0.5 * ty, z0 + kFlightHeight));
  d.query.goal = q(Eigen::Vector3d(bounds.max.x() - 0.5 * tx, bounds.max.y() - 0.5 * ty,
                                   z0 + (storeys - 1) * storey + std::min(kFlightHeight, 0.5 * storey)));
  const double keep_free = 1.0;
  std::vector<std::pair<int, int>> previous_openings;
  for (int s = 1; s < storeys; ++s) {
    const double zs = z0 + s * storey;
    // 1-2 openings (stairwells, atria) per slab, never straight above the last slab's
    // ones: the path must cross each storey.
    std::vector<std::pair<int, int>> openings;
    const int n_open = 1 + static_cast<int>(rng.uniform_index(2));
    for (int tries = 0; static_cast<int>(openings.size()) < n_open && tries < 64; ++tries) {
      const std::pair<int, int> t{static_cast<int>(rng.uniform_index(static_cast<std::uint64_t>(nx))),
                                  static_cast<int>(rng.uniform_index(static_cast<std::uint64_t>(ny)))};
      if (std::find(previous_openings.begin(), previous_openings.end(), t) != previous_openings.end()) continue;
      if (std::find(openings.begin(), openings.end(), t) != openings.end()) continue;
      openings.push_back(t);
    }
    for (int j = 0; j < ny; ++j) {  // the slab, one box per run of closed tiles in a row
      int i = 0;
      while (i < nx) {
        if (std::find(openings.begin(), openings.end(), std::pair<int, int>{i, j}) != openings.end()) {
          ++i;
          continue;
        }
        const int i0 = i;
        while (i < nx && std::find(openings.begin(), openings.end(), std::pair<int, int>{i, j}) == openings.end()) ++i;
        d.obstacles.push_back(make_box({x0 + i0 * tx, y0 + j * ty, zs - 0.5 * kSlab},
                                       {x0 + i * tx, y0 + (j + 1) * ty, zs + 0.5 * kSlab}));
      }
    }
    for (const auto& [i, j] : openings) {  // a bridge across half the openings
      if (rng.uniform01() >= 0.5) continue;
      const double w = rng.uniform(1.0, 1.6);
      if (rng.uniform01() < 0.5) {
        const double yb = y0 + (j + rng.uniform(0.2, 0.8)) * ty;
        d.obstacles.push_back(make_box({x0 + i * tx, yb - 0.5 * w, zs - 0.5 * kSlab}, {x0 + (i + 1) * tx, yb + 0.5 * w, zs + 0.5 * kSlab}));
      } else {
        const double xb = x0 + (i + rng.uniform(0.2, 0.8)) * tx;
        d.obstacles.push_back(make_box({xb - 0.5 * w, y0 + j * ty, zs - 0.5 * kSlab}, {xb + 0.5 * w, y0 + (j + 1) * ty, zs + 0.5 * kSlab}));
      }
    }
    previous_openings = openings;
  }
  // Per storey: partition walls with a door, overhangs under the slab above, pillars.
  const double door_h = std::min(kDoorHeight, storey - kSlab - 0.3);
  for (int s = 0; s < storeys; ++s) {
    const double zb = z0 + s * storey + (s > 0 ? 0.5 * kSlab : 0.0);
    const double zt = z0 + (s + 1) * storey - (s + 1 < storeys ? 0.5 * kSlab : 0.0);
    const int walls = 1 + static_cast<int>(rng.uniform_index(3));
    for (int w = 0; w < walls; ++w) {
      const int along = static_cast<int>(rng.uniform_index(2));
      const double len_total = along == 0 ? e.x() : e.y();
      const double a = (along == 0 ? x0 : y0) + rng.uniform(0.0, 0.4) * len_total;
      const double b = a + rng.uniform(0.3, 0.6) * len_total;
      const double at = along == 0 ? y0 + q(rng.uniform(0.2, 0.8) * e.y()) : x0 + q(rng.uniform(0.2, 0.8) * e.x());
      const double gw = rng.uniform(1.0, 1.5);
      const double g0 = q(rng.uniform(a + 0.3, std::max(a + 0.3, b - 0.3 - gw)));
      std::vector<Box> wall;
      wall_with_gaps(wall, along, q(a), q(b), at, kWall, zb, zt, {{g0, q(g0 + gw)}}, door_h);
      for (Box& piece : wall) add_clear(d.obstacles, piece, bounds, d.query, keep_free);
    }
    if (s + 1 < storeys) {
      const int hangs = 2 + static_cast<int>(rng.uniform_index(4));
      for (int k = 0; k < hangs; ++k) {
        const Eigen::Vector3d size(rng.uniform(2.0, 5.0), rng.uniform(2.0, 5.0), rng.uniform(0.8, 1.5));
        const Eigen::Vector3d lo(x0 + rng.uniform(0.0, e.x() - size.x()), y0 + rng.uniform(0.0, e.y() - size.y()), zt - size.z());
        add_clear(d.obstacles, make_box(lo, lo + size), bounds, d.query, keep_free);
      }
    }
    const int pillars = 2 + static_cast<int>(rng.uniform_index(5));
    for (int k = 0; k < pillars; ++k) {
      const Eigen::Vector3d lo(x0 + rng.uniform(0.0, e.x() - 0.4), y0 + rng.uniform(0.0, e.y() - 0.4), zb);
      add_clear(d.obstacles, make_box(lo, {lo.x() + 0.4, lo.y() + 0.4, zt}), bounds, d.query, keep_free);
    }
  }
  return d;
}

// -------------------------------------------------------------------- mixed
/// Structural primitives at random (domain randomisation, REQ-WORLD-020): slabs across any
/// axis, as thin as 0.1 m, with openings of any size from a squeeze to a gap, those across the
/// query's axis standing between start and goal; free boxes; rods (pillars, beams) along any
/// axis. No layout of a named family, only its parts, so that a network trained with it meets
/// walls with doors, floors with holes and trunks in every orientation and scale.
FamilyDraw mixed(const GeneratorPreset& p, Rng& rng, const Box& bounds) {
  constexpr double kMinSlabRoom = 6.0;  // an axis shorter than this gets no slab across it, m
  const Eigen::Vector3d e = bounds.extent();
  const double size = std::cbrt(e.prod());
  const double margin = 2.0 * p.robot_radius;
  FamilyDraw d;
  d.query.robot_radius = p.robot_radius;
  // The query's axis: the longest one half the time, any other with room for slabs otherwise.
  int axis_q = 0;
  e.maxCoeff(&axis_q);
  if (rng.uniform01() < 0.5) {
    const int k = static_cast<int>(rng.uniform_index(3));
    if (e[k] >= kMinSlabRoom) axis_q = k;
  }
  Eigen::Vector3d lo_frac(0.1, 0.1, 0.1), hi_frac(0.9, 0.9, 0.9);
  lo_frac[axis_q] = 0.03;
  hi_frac[axis_q] = 0.1;
  d.query.start = inside(bounds, point_at(rng, bounds, lo_frac, hi_frac), margin);
  lo_frac[axis_q] = 0.9;
  hi_frac[axis_q] = 0.97;
  d.query.goal = inside(bounds, point_at(rng, bounds, lo_frac, hi_frac), margin);
  const double keep_free = std::max(2.0 * p.robot_radius, 0.5);

  const int slabs = static_cast<int>(rng.uniform_index(5));  // 0-4
  for (int s = 0; s < slabs; ++s) {
    int axis = rng.uniform01() < 0.6 ? axis_q : static_cast<int>(rng.uniform_index(3));
    if (e[axis] < kMinSlabRoom) axis = axis_q;
    if (e[axis] < kMinSlabRoom) continue;
    const int ua = (axis + 1) % 3, va = (axis + 2) % 3;
    const double t = rng.uniform(0.1, 0.6);
    const double w = bounds.min[axis] + q(rng.uniform(0.2, 0.8) * e[axis]);
    // The slab spans the whole plane, or (a partition, an overhang) part of it.
    double u0 = bounds.min[ua], u1 = bounds.max[ua], v0 = bounds.min[va], v1 = bounds.max[va];
    if (rng.uniform01() < 0.3) {  // from one end of the plane
      const double len = q(rng.uniform(0.3, 1.0) * e[ua]);
      if (rng.uniform01() < 0.5) u1 = u0 + len; else u0 = u1 - len;
    }
    const std::vector<Box> openings = slab_openings(p, rng, bounds, axis, w, t);
    std::vector<Box> pieces;
    slab_with_openings(pieces, axis, w - 0.5 * t, w + 0.5 * t, u0, u1, v0, v1, openings);
    for (Box& piece : pieces) add_clear(d.obstacles, piece, bounds, d.query, keep_free);
  }
  const int boxes = static_cast<int>(rng.uniform_index(31));  // 0-30 free boxes
  for (int b = 0; b < boxes; ++b) {
    Eigen::Vector3d side, lo;
    for (int k = 0; k < 3; ++k) side[k] = std::min(rng.uniform(0.04, 0.2) * size, e[k]);
    for (int k = 0; k < 3; ++k) lo[k] = bounds.min[k] + rng.uniform(0.0, e[k] - side[k]);
    add_clear(d.obstacles, make_box(lo, lo + side), bounds, d.query, keep_free);
  }
  const int rods = static_cast<int>(rng.uniform_index(41));  // 0-40 pillars and beams
  for (int r = 0; r < rods; ++r) {
    const int along = rng.uniform01() < 0.5 ? 2 : static_cast<int>(rng.uniform_index(3));
    const double t = rng.uniform(0.15, 0.6);
    Eigen::Vector3d lo, hi;
    for (int k = 0; k < 3; ++k) {
      if (k == along) {
        const double len = rng.uniform(0.4, 1.0) * e[k];
        lo[k] = bounds.min[k] + rng.uniform(0.0, e[k] - len);
        hi[k] = lo[k] + len;
      } else {
        lo[k] = bounds.min[k] + rng.uniform(0.0, std::max(0.0, e[k] - t));
        hi[k] = lo[k] + t;
      }
    }
    add_clear(d.obstacles, make_box(lo, hi), bounds, d.query, keep_free);
  }
  return d;
}

}  // namespace

/// The 1-3 openings of one "mixed" slab across `axis` at w, t thick (REQ-WORLD-020): the
/// first at least 2 r + 0.3 m on each side before rounding, the others at least 0.2 m.
std::vector<Box> slab_openings(const GeneratorPreset& p, Rng& rng, const Box& bounds, int axis, double w, double t) {
  const Eigen::Vector3d e = bounds.extent();
  const int ua = (axis + 1) % 3, va = (axis + 2) % 3;
  const double passage = 2.0 * p.robot_radius + 0.3;  // the narrowest opening a slab is sure to have, m
  std::vector<Box> openings;
  const int n_open = 1 + static_cast<int>(rng.uniform_index(3));  // 1-3
  for (int o = 0; o < n_open; ++o) {
    // The first opening lets the robot through; the others may be narrower than it.
    const double lo_side = o == 0 ? passage : 0.2;
    Eigen::Vector3d side, c;
    side[axis] = 2.0 * t;
    c[axis] = w;
    for (int k : {ua, va}) {
      side[k] = std::min(e[k], rng.uniform(lo_side, std::max(lo_side, 0.35 * e[k])));
      c[k] = bounds.min[k] + rng.uniform(0.5 * side[k], e[k] - 0.5 * side[k]);
    }
    openings.push_back(make_box(c - 0.5 * side, c + 0.5 * side));
  }
  return openings;
}

/// Boxes covering the rectangle [u0, u1] x [v0, v1] of the plane across `axis` (thickness
/// [w0, w1] along it) less the given openings (rectangles in the same plane): the plane is cut
/// at every opening edge and each piece outside every opening becomes one box.
void slab_with_openings(std::vector<Box>& out, int axis, double w0, double w1, double u0, double u1, double v0,
                        double v1, const std::vector<Box>& openings) {
  const int ua = (axis + 1) % 3, va = (axis + 2) % 3;
  std::vector<double> us{u0, u1}, vs{v0, v1};
  for (const Box& o : openings) {
    us.insert(us.end(), {std::clamp(o.min[ua], u0, u1), std::clamp(o.max[ua], u0, u1)});
    vs.insert(vs.end(), {std::clamp(o.min[va], v0, v1), std::clamp(o.max[va], v0, v1)});
  }
  std::sort(us.begin(), us.end());
  us.erase(std::unique(us.begin(), us.end()), us.end());
  std::sort(vs.begin(), vs.end());
  vs.erase(std::unique(vs.begin(), vs.end()), vs.end());
  for (std::size_t j = 0; j + 1 < vs.size(); ++j) {
    std::size_t i = 0;
    while (i + 1 < us.size()) {  // one box per run of pieces outside every opening
      const auto open = [&](std::size_t k) {
        const double uc = 0.5 * (us[k] + us[k + 1]), vc = 0.5 * (vs[j] + vs[j + 1]);
        return std::any_of(openings.begin(), openings.end(), [&](const Box& o) {
          return uc > o.min[ua] && uc < o.max[ua] && vc > o.min[va] && vc < o.max[va];
        });
      };
      if (open(i)) {
        ++i;
        continue;
      }
      const std::size_t i0 = i;
      while (i + 1 < us.size() && !open(i)) ++i;
      Eigen::Vector3d lo, hi;
      lo[axis] = w0;
      hi[axis] = w1;
      lo[ua] = us[i0];
      hi[ua] = us[i];
      lo[va] = vs[j];
      hi[va] = vs[j + 1];
      out.push_back(make_box(lo, hi));
    }
  }
}

FamilyDraw draw_family(const GeneratorPreset& preset, Rng& rng, const Box& bounds, std::optional<int> obstacles) {
  if (preset.name == "cluttered") return cluttered(preset, rng, bounds, obstacles);
  if (preset.name == "forest") return forest(preset, rng, bounds, obstacles);
  if (obstacles) throw Error("obstacles: preset \"" + preset.name + "\" has no obstacle count to override");
  if (preset.name == "rooms") return rooms(preset, rng, bounds);
  if (preset.name == "multilevel") return multilevel(preset, rng, bounds);
  if (preset.name == "mixed") return mixed(preset, rng, bounds);
  throw Error("preset: \"" + preset.name + "\" is not a map family");
}

}  // namespace miner::world::detail
