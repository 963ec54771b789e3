// Goldens of the back end: fixed problems (rest-to-rest and moving boundary states, jerk
// and snap) and their answers in the `miner traj solve` format.
#include <catch2/catch.hpp>

#include "miner/testing/golden.hpp"
#include "miner/traj/problem_io.hpp"

using namespace miner::traj;

TEST_CASE("Fixed trajectory problems keep their answers", "[REQ-TRAJ-006][REQ-TRAJ-002][REQ-HARNESS-002]") {
  Eigen::MatrixX3d pts(5, 3);
  pts << 0, 0, 1, 3, 1, 1.5, 5, 4, 2, 8, 4, 1, 10, 7, 1.2;
  nlohmann::json actual = nlohmann::json::array();
  for (int s : {3, 4}) {
    MincoProblem p = rest_to_rest(s, pts, trapezoidal_allocation(pts, Limits{2.0, 1.0}));
    actual.push_back(answer_to_json(solve_minco(p)));
    p.head.row(1) << 1.0, 0.5, 0.0;
    p.tail.row(1) << 0.0, 1.0, 0.2;
    p.tail.row(2) << 0.1, 0.0, 0.0;
    actual.push_back(answer_to_json(solve_minco(p)));
  }
  // Coefficients up to ~10 in size from an O(M) solve: 1e-10 absolute and relative covers
  // a different but equally accurate summation order (measured differences ~1e-13).
  MINER_REQUIRE_GOLDEN("traj/minco-fixed.json", actual, (miner::testing::Tolerance{1e-10, 1e-10}));
}
