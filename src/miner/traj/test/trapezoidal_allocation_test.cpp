#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

#include "miner/core/error.hpp"
#include "miner/traj/baselines.hpp"
#include "miner/traj/collision_repair.hpp"
#include "miner/traj/minco.hpp"
#include "miner/traj/optimality_system.hpp"
#include "miner/traj/time_allocation.hpp"
#include "miner/traj/trapezoidal_allocation.hpp"
#include "miner/world/map.hpp"

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

TEST_CASE("Tenth campaign: the trajectory API refuses what would give NaN, garbage or unbounded work, by name",
          "[REQ-LIB-003][REQ-TRAJ-001][REQ-TRAJ-007][REQ-TRAJ-008]") {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  // L15: the trapezoid of a negative, NaN or infinite distance, or of limits whose time
  // overflows, named instead of returned as NaN / inf.
  CHECK_THROWS_WITH(trapezoidal_duration(-1.0, Limits{2, 1}), Contains("distance"));
  CHECK_THROWS_WITH(trapezoidal_duration(nan, Limits{2, 1}), Contains("distance"));
  CHECK_THROWS_WITH(trapezoidal_duration(inf, Limits{2, 1}), Contains("distance"));
  CHECK_THROWS_WITH(trapezoidal_duration(1.0, Limits{5e-324, 5e-324}), Contains("no finite time"));
  Eigen::MatrixX3d one(1, 3);
  one << 0, 0, 0;
  CHECK_THROWS_WITH(trapezoidal_allocation(one, Limits{2, 1}), Contains("at least 2 points"));
  Eigen::MatrixX3d far(2, 3);
  far << -1e300, 0, 0, 1e300, 0, 0;
  CHECK_THROWS_WITH(trapezoidal_allocation(far, Limits{2, 1}), Contains("points[0] and points[1]"));
  far(1, 0) = nan;
  CHECK_THROWS_WITH(trapezoidal_allocation(far, Limits{2, 1}), Contains("points[1]"));

  // Seventeenth campaign F16: finite coefficients and durations the constructor accepts gave a
  // NaN cost, a NaN gradient, an infinite total time and an infinite value. Each is named now.
  {
    Eigen::MatrixX3d c = Eigen::MatrixX3d::Zero(6, 3);
    c(1, 0) = 1.0;
    c(3, 0) = 1e-30;
    CHECK(std::isfinite(PolynomialTrajectory(3, {10.0}, c).cost()));
    CHECK_THROWS_WITH(PolynomialTrajectory(3, {1e100}, c).cost(), Contains("trajectory cost") && Contains("not finite"));
    CHECK_THROWS_WITH(PolynomialTrajectory(3, {1e200}, c).cost_gradient_coefficients(), Contains("not finite"));
    CHECK_THROWS_WITH(PolynomialTrajectory(3, {1e200}, c).evaluate(1e200), Contains("not finite"));
    CHECK_THROWS_WITH(PolynomialTrajectory(3, {1e308, 1e308}, Eigen::MatrixX3d::Zero(12, 3)).total_duration(),
                      Contains("sum to inf"));
  }

  Eigen::MatrixX3d pts(3, 3);
  pts << 0, 0, 0, 2, 0, 0, 2, 2, 0;
  const PolynomialTrajectory t = solve_minco(rest_to_rest(4, pts, {2.0, 2.0}));
  // L3: a segment index past either end is named (segment 99 read past the coefficients).
  CHECK_THROWS_WITH(t.evaluate_segment(99, 0.5), Contains("segment 99 does not exist"));
  CHECK_THROWS_WITH(t.evaluate_segment(-1, 0.5), Contains("segment -1 does not exist"));
  CHECK_THROWS_WITH(t.evaluate_segment(0, 0.5, -1), Contains("k: the derivative order"));
  // L4: k < 0 wrote before the row (heap corruption); n < 0 asked for 2^64 bytes.
  CHECK_THROWS_WITH(monomial_derivative_row(4, -1, 1.0), Contains("derivative order k"));
  CHECK_THROWS_WITH(monomial_derivative_row(-1, 0, 1.0), Contains("n must be"));
  // L17: the cost matrix of a negative or NaN duration, a trajectory of order 0 or NaN parts.
  CHECK_THROWS_WITH(monomial_cost_matrix(3, -1.0), Contains("duration"));
  CHECK_THROWS_WITH(monomial_cost_matrix(3, nan), Contains("duration"));
  // Eighteenth campaign F8: the free functions returned NaN, inf or a wrong value.
  CHECK_THROWS_WITH(monomial_derivative_row(8, 0, nan), Contains("t must be finite"));
  CHECK_THROWS_WITH(monomial_derivative_row(8, 0, 1e300), Contains("overflows t^7"));
  CHECK(monomial_derivative_row(8, 0, 1e40).allFinite());
  CHECK_THROWS_WITH(monomial_cost_matrix(4, 1e300), Contains("Q(T) is not finite"));
  CHECK_THROWS_WITH(falling_factorial(200, 200), Contains("overflows a double"));
  CHECK_THROWS_WITH(falling_factorial(5, -1), Contains("k must be >= 0"));
  CHECK(falling_factorial(5, 2) == 20.0);
  CHECK(falling_factorial(5, 0) == 1.0);
  CHECK_THROWS_WITH(PolynomialTrajectory(0, {1.0}, Eigen::MatrixX3d::Zero(0, 3)), Contains("order"));
  CHECK_THROWS_WITH(PolynomialTrajectory(3, {-1.0}, Eigen::MatrixX3d::Zero(6, 3)), Contains("durations[0]"));
  CHECK_THROWS_WITH(PolynomialTrajectory(3, {nan}, Eigen::MatrixX3d::Zero(6, 3)), Contains("durations[0]"));
  Eigen::MatrixX3d c = Eigen::MatrixX3d::Zero(6, 3);
  c(2, 1) = nan;
  CHECK_THROWS_WITH(PolynomialTrajectory(3, {1.0}, c), Contains("coefficients must be finite"));
  // L13: steps are bounded and checked; the exact peaks agree with a dense sampling.
  const auto [v, a] = exact_extremes(t);
  const auto [v_dense, a_dense] = trajectory_extremes(t, 1e-3);
  CHECK(v == Approx(v_dense).epsilon(1e-4));
  CHECK(a == Approx(a_dense).epsilon(1e-4));
  for (const double step : {0.0, -1.0, nan, inf, 1e-300})
    CHECK_THROWS_WITH(trajectory_extremes(t, step), Contains("step"));
  // Recheck: INT_MAX Ceres iterations were bounded only by convergence.
  AllocationOptions endless;
  endless.max_iterations = kMaxAllocationIterations + 1;
  CHECK_THROWS_WITH(optimise_allocation(rest_to_rest(4, pts, {2.0, 2.0}), endless), Contains("allocation iterations: must be in [1, 10000]"));
  endless.max_iterations = 0;
  CHECK_THROWS_WITH(optimise_allocation(rest_to_rest(4, pts, {2.0, 2.0}), endless), Contains("allocation iterations"));
  // A coefficient matrix resized through mutable_coefficients() is named, not read past its end.
  PolynomialTrajectory cut = t;
  cut.mutable_coefficients().conservativeResize(10, 3);
  CHECK_THROWS_WITH(cut.evaluate_segment(1, 0.5), Contains("segment 1 needs coefficient rows up to 16, the matrix has 10"));
  CHECK(cut.evaluate_segment(0, 0.5) == t.evaluate_segment(0, 0.5));
  // L16: the dense baselines validate their problem and bound their matrices.
  MincoProblem bad = rest_to_rest(4, pts, {2.0, 2.0});
  bad.durations[1] = nan;
  CHECK_THROWS_WITH(solve_closed_form(bad), Contains("durations"));
  CHECK_THROWS_WITH(solve_kkt_qp(bad), Contains("durations"));
  CHECK_THROWS_WITH(solve_dense_lu(bad), Contains("durations"));
  bad.durations = {2.0};
  CHECK_THROWS_WITH(optimality_system(bad), Contains("durations"));
  Eigen::MatrixX3d many(kMaxDenseSegments + 2, 3);
  for (Eigen::Index i = 0; i < many.rows(); ++i) many.row(i) << static_cast<double>(i), 0.0, 0.0;
  const MincoProblem big = rest_to_rest(3, many, std::vector<double>(static_cast<std::size_t>(many.rows() - 1), 1.0));
  CHECK_THROWS_WITH(solve_dense_lu(big), Contains("more than the " + std::to_string(kMaxDenseSegments)));
  CHECK_NOTHROW(solve_minco(big));  // MINCO takes any number
  CHECK_THROWS_WITH(relative_residual(optimality_system(rest_to_rest(4, pts, {2.0, 2.0})), Eigen::MatrixX3d::Zero(3, 3)),
                    Contains("coefficient rows"));
  // L17: scaling to infinite durations, and objectives of the wrong number of durations.
  PolynomialTrajectory scaled = t;
  CHECK_THROWS_WITH(scale_time(scaled, 1e308), Contains("infinite"));
  CHECK_THROWS_WITH(feasible_objective(rest_to_rest(4, pts, {2.0, 2.0}), {2.0}, AllocationOptions{}), Contains("durations: expected 2 values"));
  CHECK_THROWS_WITH(log_time_objective(rest_to_rest(4, pts, {2.0, 2.0}), {0.1, 0.2, 0.3}, AllocationOptions{}), Contains("durations: expected 2 values"));
  // L21: a moved-from solver is named, not dereferenced.
  MincoSolver from;
  MincoSolver to(std::move(from));
  PolynomialTrajectory out;
  CHECK_THROWS_WITH(from.solve(rest_to_rest(4, pts, {2.0, 2.0}), out), Contains("moved from"));  // NOLINT(bugprone-use-after-move)
  CHECK_NOTHROW(to.solve(rest_to_rest(4, pts, {2.0, 2.0}), out));
}

TEST_CASE("Collision checks of a trajectory take a robot radius and a positive step", "[REQ-LIB-003][REQ-TRAJ-008]") {
  // Tenth campaign L10: a NaN or negative radius answered "no colliding segment" for a
  // trajectory through a wall; a step of 0 was cast from infinity (the pipeline passed 0 and
  // checked two chords per segment).
  const miner::world::Map map(miner::world::Box{{0, 0, 0}, {10, 10, 10}}, 0.5,
                              {miner::world::Box{{4, 0, 0}, {6, 10, 10}}});
  Eigen::MatrixX3d pts(2, 3);
  pts << 1, 5, 5, 9, 5, 5;
  const PolynomialTrajectory through = solve_minco(rest_to_rest(3, pts, {4.0}));
  CHECK(colliding_segments(through, map, 0.1, 0.05) == std::vector<int>{0});
  CHECK_THROWS_WITH(colliding_segments(through, map, std::numeric_limits<double>::quiet_NaN(), 0.05), Contains("robot radius"));
  CHECK_THROWS_WITH(colliding_segments(through, map, -5.0, 0.05), Contains("robot radius"));
  CHECK_THROWS_WITH(colliding_segments(through, map, 0.1, 0.0), Contains("step"));
  CHECK_THROWS_WITH(colliding_segments(through, map, 0.1, 1e-300), Contains("step"));
  RepairOptions o;
  o.robot_radius = -1.0;
  Eigen::MatrixX3d path(2, 3);
  path << 1, 1, 1, 3, 1, 1;
  CHECK_THROWS_WITH(repair_collisions(map, path, o), Contains("robot radius"));
  o.robot_radius = 0.2;
  o.sample_step = -1.0;
  CHECK_THROWS_WITH(repair_collisions(map, path, o), Contains("sample_step"));
  // The step the pipeline and the repair share: half a cell, at most the radius.
  CHECK(collision_sample_step(map, 0.0) == 0.25);
  CHECK(collision_sample_step(map, 0.1) == 0.1);
  CHECK(collision_sample_step(map, 0.4) == 0.25);
}

TEST_CASE("The dense solvers take exactly kMaxDenseSegments segments and refuse one more", "[REQ-TRAJ-009][REQ-LIB-003]") {
  // Held-out audit 9, h9-traj-05: validate_dense refused a problem of exactly kMaxDenseSegments (500)
  // segments, which the documented bound allows, with a message that contradicted itself.
  const auto straight = [](int segments) {
    Eigen::MatrixX3d points(segments + 1, 3);
    for (int i = 0; i <= segments; ++i) points.row(i) << static_cast<double>(i), 0.0, 0.0;
    return rest_to_rest(3, points, std::vector<double>(static_cast<std::size_t>(segments), 1.0));
  };
  CHECK_NOTHROW(validate_dense(straight(kMaxDenseSegments)));
  CHECK_NOTHROW(validate_dense(straight(kMaxDenseSegments - 1)));
  CHECK_THROWS_WITH(validate_dense(straight(kMaxDenseSegments + 1)),
                    Contains("durations: 501 segments, more than the 500 a dense solver takes"));
}

TEST_CASE("A trajectory changed through its mutable accessors is checked where it is read", "[REQ-TRAJ-004][REQ-LIB-003]") {
  // Twelfth campaign L7: a duration pushed without its coefficients made cost() read past the
  // matrix (NaN in Release, another number under ASan); a negative or NaN duration was
  // evaluated as if it were a time.
  Eigen::MatrixX3d pts(3, 3);
  pts << 0, 0, 0, 1, 0, 0, 1, 1, 0;
  const PolynomialTrajectory t = solve_minco(rest_to_rest(3, pts, {1.0, 1.0}));
  auto longer = t;
  longer.mutable_durations().push_back(1.0);
  CHECK_THROWS_WITH(longer.cost(), Contains("trajectory cost: the trajectory has 3 durations and 12 coefficient rows"));
  CHECK_THROWS_WITH(longer.cost_gradient_coefficients(), Contains("3 durations and 12 coefficient rows"));
  CHECK_THROWS_WITH(exact_extremes(longer), Contains("exact_extremes: the trajectory has 3 durations"));
  CHECK_THROWS_WITH(trajectory_extremes(longer, 0.01), Contains("trajectory_extremes: the trajectory has 3 durations"));
  for (const double bad : {-1.0, 0.0, std::nan("")}) {
    INFO("durations[0] = " << bad);
    auto changed = t;
    changed.mutable_durations()[0] = bad;
    CHECK_THROWS_WITH(changed.evaluate(0.5), Contains("durations[0] must be a positive finite time"));
    CHECK_THROWS_WITH(changed.cost(), Contains("durations[0]"));
    CHECK_THROWS_WITH(exact_extremes(changed), Contains("durations[0]"));
    // Sixteenth campaign F9: summed as it was (-1 gave a 1 s trajectory, NaN a NaN one).
    CHECK_THROWS_WITH(changed.total_duration(), Contains("trajectory: durations[0] must be a positive finite time"));
  }
  // F8: a local time that is not finite answered NaN, a global one +-inf was clamped to an end.
  for (const double bad : {std::nan(""), HUGE_VAL, -HUGE_VAL}) {
    INFO("time " << bad);
    CHECK_THROWS_WITH(t.evaluate_segment(0, bad), Contains("tau: must be a finite local time in s"));
    CHECK_THROWS_WITH(t.evaluate(bad), Contains("t: must be a finite time in s"));
  }
  // At an interior junction the later segment answers (held-out 13, h13-traj-05: the earlier one
  // did): a derivative of order 2s - 1 = 5 jumps there, so the two segments tell apart.
  REQUIRE((t.evaluate_segment(0, 1.0, 5) - t.evaluate_segment(1, 0.0, 5)).norm() > 1e-6);
  CHECK(t.evaluate(1.0, 5) == t.evaluate_segment(1, 0.0, 5));
  CHECK(t.evaluate(1.0) == t.evaluate_segment(1, 0.0));
  CHECK(t.evaluate(-1e300) == t.evaluate(0.0));  // finite times are clamped, as documented
  CHECK(t.evaluate(1e300) == t.evaluate(t.total_duration()));
  auto poisoned = t;
  poisoned.mutable_coefficients()(4, 1) = std::nan("");
  CHECK_THROWS_WITH(exact_extremes(poisoned), Contains("exact_extremes: the trajectory's coefficients must be finite"));
  CHECK_THROWS_WITH(trajectory_extremes(poisoned, 0.01), Contains("trajectory_extremes: the trajectory's coefficients must be finite"));
  auto reordered = t;
  CHECK_THROWS_WITH(reordered.set_order(0), Contains("order must be in [1, 4], got 0"));
  CHECK(reordered.order() == 3);
  // Changed consistently, the object is a trajectory again: scale_time's edit is such a change.
  auto slower = t;
  scale_time(slower, 2.0);
  CHECK(slower.cost() == Approx(t.cost() / 32.0));  // jerk: J scales as k^-(2s-1) = k^-5
}
