#include <catch2/catch.hpp>

#include <cmath>

#include "miner/core/error.hpp"
#include "miner/traj/trapezoidal_allocation.hpp"

using namespace miner::traj;
using Catch::Matchers::Contains;

TEST_CASE("Trapezoidal allocation: triangular below 2 d_a, cruise above", "[REQ-TRAJ-001]") {
  const Limits lim{2.0, 1.0};  // t_a = 2 s, d_a = 2 m
  CHECK(trapezoidal_duration(1.0, lim) == Approx(2.0));             // 2 sqrt(1 / 1)
  CHECK(trapezoidal_duration(4.0, lim) == Approx(4.0));             // switch point: 2 t_a
  CHECK(trapezoidal_duration(10.0, lim) == Approx(4.0 + 6.0 / 2));  // 2 t_a + (d - 2 d_a) / v
  CHECK(trapezoidal_duration(0.0, lim) == 0.0);
  Eigen::MatrixX3d pts(3, 3);
  pts << 0, 0, 0, 1, 0, 0, 1, 10, 0;
  const auto d = trapezoidal_allocation(pts, lim);
  REQUIRE(d.size() == 2);
  CHECK(d[0] == Approx(2.0));
  CHECK(d[1] == Approx(7.0));
}

TEST_CASE("Trapezoidal allocation refuses non-positive or non-finite limits", "[REQ-TRAJ-001][REQ-TRAJ-007]") {
  Eigen::MatrixX3d pts(2, 3);
  pts << 0, 0, 0, 1, 0, 0;
  CHECK_THROWS_WITH(trapezoidal_allocation(pts, Limits{0.0, 1.0}), Contains("limits.v_max: must be positive"));
  CHECK_THROWS_WITH(trapezoidal_allocation(pts, Limits{1.0, -1.0}), Contains("limits.a_max: must be positive"));
  CHECK_THROWS_WITH(trapezoidal_allocation(pts, Limits{NAN, 1.0}), Contains("limits.v_max: must be a finite"));
}
