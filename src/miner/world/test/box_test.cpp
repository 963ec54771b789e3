#include <catch2/catch.hpp>

#include "miner/core/rng.hpp"
#include "miner/world/box.hpp"

using miner::world::Box;
using miner::world::squared_distance;
using V = Eigen::Vector3d;

namespace {
const Box kUnit{{0, 0, 0}, {1, 1, 1}};
// Exact-arithmetic answers below are built from small binary fractions, so they are
// compared with a tolerance of a few ulps of the values involved.
constexpr double kExact = 1e-15;
}  // namespace

TEST_CASE("Point distance: inside and on the boundary are zero, outside is Euclidean", "[REQ-WORLD-004]") {
  CHECK(squared_distance(V(0.5, 0.5, 0.5), kUnit) == 0.0);
  CHECK(squared_distance(V(1.0, 0.5, 0.0), kUnit) == 0.0);  // boundary point: in collision
  CHECK(squared_distance(V(2.0, 0.5, 0.5), kUnit) == 1.0);
  CHECK(squared_distance(V(2.0, 2.0, 2.0), kUnit) == 3.0);   // nearest point is a corner
  CHECK(squared_distance(V(-1.0, 3.0, 0.5), kUnit) == 5.0);  // nearest point is an edge
  CHECK(kUnit.contains(V(1, 1, 1)));
  CHECK_FALSE(kUnit.contains(V(1, 1, 1.0000001)));
}

TEST_CASE("Segment distance: crossing, parallel, diagonal past an edge, short of the box", "[REQ-WORLD-005]") {
  CHECK(squared_distance(V(-1, 0.5, 0.5), V(2, 0.5, 0.5), kUnit) == 0.0);
  CHECK(squared_distance(V(-1, 3, 0.5), V(2, 3, 0.5), kUnit) == Approx(4.0).margin(kExact));
  // The line x + y = 3 passes the edge x = y = 1 at distance 1/sqrt(2).
  CHECK(squared_distance(V(3, 0, 0.5), V(0, 3, 0.5), kUnit) == Approx(0.5).margin(kExact));
  CHECK(squared_distance(V(-3, 0.5, 0.5), V(-1, 0.5, 0.5), kUnit) == Approx(1.0).margin(kExact));
  // Degenerate segment = point.
  CHECK(squared_distance(V(2, 2, 2), V(2, 2, 2), kUnit) == 3.0);
  // Touching a face at one end only.
  CHECK(squared_distance(V(1, 0.5, 0.5), V(3, 0.5, 0.5), kUnit) == 0.0);
  // Passing a corner in 3D: from (2,-1,2) to (-1,2,2): closest approach to the top edge z = 1.
  CHECK(squared_distance(V(2, -1, 2), V(-1, 2, 2), kUnit) == Approx(1.0).margin(kExact));
}

TEST_CASE("A segment through a box is at distance 0 from it either way, at radius 0", "[REQ-WORLD-005][REQ-PLAN-001]") {
  // Twelfth campaign L4: the pieces of the segment were measured at their ends (on the faces, up
  // to rounding 1e-32 outside) and at interior minima of the axes outside the slabs; the piece
  // inside the box had neither, so plan at radius 0 returned a path through this box.
  const Box wall{V(2.61146183974281, 0.5419264274143618, 1.7744651457711955),
                 V(4.218703939301578, 2.7676876166023043, 2.42674625924518)};
  const V a(2.330811241807739, 1.5609067253427737, 0.3229572533558993), b(3.1712963329202033, 1.5847574829258244, 2.80061909909265);
  CHECK(squared_distance(a, b, wall) == 0.0);
  CHECK(squared_distance(b, a, wall) == 0.0);
  // Random segments whose middle lies inside a random box: 0 both ways, whatever the ends.
  miner::Rng rng(32);
  int misses = 0;
  for (int i = 0; i < 20000; ++i) {
    const V lo(rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(-5, 5));
    const Box box{lo, lo + V(rng.uniform(0.01, 3), rng.uniform(0.01, 3), rng.uniform(0.01, 3))};
    const V inside = box.min + (box.max - box.min).cwiseProduct(V(rng.uniform(0.05, 0.95), rng.uniform(0.05, 0.95), rng.uniform(0.05, 0.95)));
    const V dir(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    const double s = rng.uniform(0.5, 10.0), f = rng.uniform(0.1, 0.9);
    const V p = inside - f * s * dir, q = inside + (1.0 - f) * s * dir;
    misses += squared_distance(p, q, box) != 0.0;
    misses += squared_distance(q, p, box) != 0.0;
  }
  CHECK(misses == 0);
}

TEST_CASE("Box helpers: inflation, overlap, volume", "[REQ-WORLD-004]") {
  const Box big = kUnit.inflated(0.5);
  CHECK(big.min == V(-0.5, -0.5, -0.5));
  CHECK(big.max == V(1.5, 1.5, 1.5));
  CHECK(kUnit.overlaps(Box{{1, 1, 1}, {2, 2, 2}}));  // touching counts
  CHECK_FALSE(kUnit.overlaps(Box{{1.01, 0, 0}, {2, 1, 1}}));
  CHECK(big.volume() == 8.0);
  CHECK(kUnit.center() == V(0.5, 0.5, 0.5));
}
