#include <catch2/catch.hpp>

#include <cmath>

#include <Eigen/LU>

#include "miner/core/error.hpp"
#include "miner/traj/baselines.hpp"
#include "miner/traj/minco.hpp"
#include "miner/traj/optimality_system.hpp"

using namespace miner::traj;
using Catch::Matchers::Contains;

namespace {
Eigen::MatrixX3d line(std::initializer_list<double> xs) {
  Eigen::MatrixX3d m(static_cast<Eigen::Index>(xs.size()), 3);
  Eigen::Index i = 0;
  for (double x : xs) m.row(i++) << x, 0.0, 0.0;
  return m;
}
// Coefficients of order 1 built from exact small rationals: a few ulps.
constexpr double kKnownAnswer = 1e-12;
}  // namespace

TEST_CASE("One rest-to-rest segment is the classic 10t^3 - 15t^4 + 6t^5 (jerk) and 35t^4 - 84t^5 + 70t^6 - 20t^7 (snap)", "[REQ-TRAJ-002]") {
  const auto jerk = solve_minco(rest_to_rest(3, line({0, 1}), {1.0}));
  const Eigen::VectorXd cj = jerk.coefficients().col(0);
  Eigen::VectorXd ej(6);
  ej << 0, 0, 0, 10, -15, 6;
  CHECK((cj - ej).norm() < kKnownAnswer * 100);
  CHECK(jerk.cost() == Approx(720.0).epsilon(1e-12));  // int (60 - 360 t + 360 t^2)^2 dt
  const auto snap = solve_minco(rest_to_rest(4, line({0, 1}), {1.0}));
  Eigen::VectorXd es(8);
  es << 0, 0, 0, 0, 35, -84, 70, -20;
  CHECK((snap.coefficients().col(0) - es).norm() < kKnownAnswer * 1000);
}

TEST_CASE("MINCO agrees with the dense pivoted LU solve of A c = b", "[REQ-TRAJ-003]") {
  for (int s : {3, 4}) {
    Eigen::MatrixX3d pts(5, 3);
    pts << 0, 0, 0, 1, 2, 0, 3, 1, 1, 4, 4, 2, 6, 3, 1;
    MincoProblem p = rest_to_rest(s, pts, {1.0, 2.0, 0.5, 1.5});
    p.head.row(1) << 0.5, 0, 0;  // a moving start
    p.tail.row(2) << 0, 0.1, 0;
    const auto t = solve_minco(p);
    const auto sys = optimality_system(p);
    const Eigen::MatrixX3d dense = sys.A.partialPivLu().solve(sys.b);
    INFO("s = " << s);
    CHECK((t.coefficients() - dense).norm() <= 1e-9 * dense.norm());
    CHECK(relative_residual(sys, t.coefficients()) < 1e-12);  // REQ-TRAJ-003 target
  }
}

TEST_CASE("A solver object gives the same answer when reused on different sizes", "[REQ-TRAJ-002]") {
  MincoSolver solver;
  PolynomialTrajectory a, b, c;
  const auto p1 = rest_to_rest(4, line({0, 1, 3, 6}), {1, 1, 1});
  const auto p2 = rest_to_rest(3, line({0, 2}), {2});
  solver.solve(p1, a);
  solver.solve(p2, b);
  solver.solve(p1, c);
  CHECK(a.coefficients() == c.coefficients());
  CHECK(b.segments() == 1);
  CHECK(b.order() == 3);
}

TEST_CASE("Evaluation: position and derivatives at segment ends and in between", "[REQ-TRAJ-004]") {
  const auto t = solve_minco(rest_to_rest(3, line({0, 1, 3}), {1.0, 2.0}));
  CHECK(t.total_duration() == 3.0);
  CHECK(t.evaluate(0.0).x() == Approx(0.0).margin(1e-15));
  CHECK(t.evaluate(1.0).x() == Approx(1.0));
  CHECK(t.evaluate(3.0).x() == Approx(3.0));
  CHECK(t.evaluate(10.0).x() == Approx(3.0));  // clamped
  CHECK(t.evaluate(3.0, 1).norm() < 1e-12);    // at rest
  // Derivative k by central differences of derivative k - 1, up to snap.
  for (int k = 1; k <= 4; ++k) {
    const double h = 1e-5, tt = 1.7;
    const double fd = (t.evaluate(tt + h, k - 1).x() - t.evaluate(tt - h, k - 1).x()) / (2 * h);
    INFO("k = " << k);
    CHECK(t.evaluate(tt, k).x() == Approx(fd).epsilon(1e-6).margin(1e-6));
  }
  CHECK(t.evaluate(0.5, 6).norm() == 0.0);  // degree 5: the 6th derivative vanishes
}

TEST_CASE("Evaluation before t = 0 is clamped to the start state in every derivative", "[REQ-TRAJ-004]") {
  // A moving start (velocity, acceleration and, for snap, jerk nonzero), so that segment 0's
  // polynomial continued before t = 0 differs from the start state in every derivative.
  for (int s : {3, 4}) {
    Eigen::MatrixX3d pts(3, 3);
    pts << 0, 0, 0, 1, 2, 0, 3, 1, 1;
    MincoProblem p = rest_to_rest(s, pts, {1.0, 1.5});
    p.head.row(1) << 0.8, -0.5, 0.3;
    p.head.row(2) << -0.4, 0.6, 0.2;
    if (s == 4) p.head.row(3) << 0.3, 0.1, -0.7;
    const auto t = solve_minco(p);
    for (int k = 0; k <= 2 * s; ++k) {
      const Eigen::Vector3d start = t.evaluate_segment(0, 0.0, k);
      if (k < s) CHECK((start - p.head.row(k).transpose()).norm() < 1e-12);  // the documented start state
      for (double before : {-1e-9, -0.25, -1.0, -100.0}) {
        INFO("s = " << s << ", k = " << k << ", t = " << before);
        CHECK(t.evaluate(before, k) == start);
      }
    }
  }
}

TEST_CASE("Cost from the coefficients equals the solver's Hermite-form cost", "[REQ-TRAJ-005]") {
  Eigen::MatrixX3d pts(4, 3);
  pts << 0, 0, 0, 1, 2, 3, -1, 2, 0, 2, 2, 2;
  const auto p = rest_to_rest(4, pts, {0.7, 1.3, 2.1});
  MincoSolver solver;
  PolynomialTrajectory t;
  solver.solve(p, t);
  MincoGradients g;
  CHECK(solver.cost_and_gradients(p, &g) == Approx(t.cost()).epsilon(1e-12));
  CHECK(g.points.rows() == 4);
  CHECK(g.durations.size() == 3);
  CHECK_THROWS_WITH(MincoSolver().cost_and_gradients(p, nullptr), Contains("needs a solve() first"));
  // Another problem of the same size (points, a duration, an end) is not the one solved
  // (thirteenth campaign L4: it got the solved problem's cost).
  auto moved = p;
  moved.points(2, 1) += 0.5;
  CHECK_THROWS_WITH(solver.cost_and_gradients(moved, nullptr), Contains("for the problem the last solve() solved"));
  auto longer = p;
  longer.durations[1] = 1.4;
  CHECK_THROWS_WITH(solver.cost_and_gradients(longer, nullptr), Contains("another"));
  // Problems that differ only at an end, in a derivative (held-out audit 11: the tail was not
  // compared, and a different end velocity got the solved problem's cost).
  for (const bool at_head : {true, false}) {
    auto other_end = p;
    (at_head ? other_end.head : other_end.tail)(1, 2) = 0.3;
    INFO((at_head ? "head" : "tail") << " velocity changed");
    CHECK_THROWS_WITH(solver.cost_and_gradients(other_end, nullptr), Contains("another"));
  }
  solver.solve(longer, t);
  CHECK(solver.cost_and_gradients(longer, nullptr) == Approx(t.cost()).epsilon(1e-12));
  CHECK_THROWS_WITH(solver.cost_and_gradients(p, nullptr), Contains("another"));
}

TEST_CASE("Bad problems are refused with the field named", "[REQ-TRAJ-007]") {
  const auto good = rest_to_rest(3, line({0, 1, 2}), {1, 1});
  CHECK_NOTHROW(validate(good));
  auto p = good;
  p.durations[1] = 0.0;
  CHECK_THROWS_WITH(validate(p), Contains("durations[1]: must be positive and finite, got 0"));
  p = good;
  p.durations[0] = -1.0;
  CHECK_THROWS_WITH(validate(p), Contains("durations[0]: must be positive and finite, got -1"));
  p = good;
  p.durations[0] = NAN;
  CHECK_THROWS_WITH(validate(p), Contains("durations[0]: must be positive and finite, got nan"));
  p = good;
  p.durations.pop_back();
  CHECK_THROWS_WITH(validate(p), Contains("durations: expected 2 values (one per segment), got 1"));
  // One too many as well (held-out audit 8, h8-traj-01: extra durations passed validation).
  p = good;
  p.durations.push_back(1.0);
  CHECK_THROWS_WITH(validate(p), Contains("durations: expected 2 values (one per segment), got 3"));
  CHECK_THROWS_WITH(validate(rest_to_rest(3, line({0}), {})), Contains("points: need at least 2 points"));
  CHECK_THROWS_WITH(validate(rest_to_rest(3, line({0, 1, 1}), {1, 1})), Contains("points[1] and points[2] coincide"));
  // The first pair too (held-out audit 6, h6-traj-02: the check started at the second pair).
  CHECK_THROWS_WITH(validate(rest_to_rest(3, line({0, 0, 1}), {1, 1})), Contains("points[0] and points[1] coincide"));
  CHECK_THROWS_WITH(validate(rest_to_rest(5, line({0, 1}), {1})), Contains("order: must be 3 (minimum jerk) or 4 (minimum snap), got 5"));
  p = good;
  p.head = Eigen::MatrixX3d::Zero(4, 3);
  CHECK_THROWS_WITH(validate(p), Contains("head: expected 3 rows (derivatives 0..2 for order 3), got 4"));
  p = good;
  p.tail.row(0) << 5, 0, 0;
  CHECK_THROWS_WITH(validate(p), Contains("tail[0]: must equal the last point"));
  p = good;
  p.head.row(0) << 0.5, 0, 0;
  CHECK_THROWS_WITH(validate(p), Contains("head[0]: must equal points[0]"));
  p = good;
  p.head(2, 1) = INFINITY;
  CHECK_THROWS_WITH(validate(p), Contains("head[2][1]: must be a finite number"));
  p = good;
  p.points(1, 2) = NAN;
  CHECK_THROWS_WITH(validate(p), Contains("points[1][2]: must be a finite number"));
  PolynomialTrajectory out;
  p = good;
  p.order = 2;
  CHECK_THROWS_WITH(MincoSolver().solve(p, out), Contains("order: must be 3"));
  CHECK_THROWS_WITH(PolynomialTrajectory(3, {1.0}, Eigen::MatrixX3d::Zero(5, 3)), Contains("expected 6 coefficient rows"));
  CHECK_THROWS_WITH(PolynomialTrajectory().evaluate(0.0), Contains("has no segments"));
}

TEST_CASE("The Table II baselines solve the same problem to the same coefficients", "[REQ-TRAJ-009]") {
  for (int s : {3, 4}) {
    Eigen::MatrixX3d pts(5, 3);
    pts << 0, 0, 0, 1, 2, 0, 3, 1, 1, 4, 4, 2, 6, 3, 1;
    MincoProblem p = rest_to_rest(s, pts, {1.0, 2.0, 0.5, 1.5});
    p.head.row(1) << 0.5, 0, 0;
    const Eigen::MatrixX3d c = solve_minco(p).coefficients();
    INFO("s = " << s);
    // Dense LU and KKT are backward stable; the closed form inverts R_PP explicitly
    // (measured 6e-10 for s = 4), as the paper's re-implementation did.
    CHECK((solve_dense_lu(p) - c).norm() <= 1e-9 * c.norm());
    CHECK((solve_kkt_qp(p) - c).norm() <= 1e-9 * c.norm());
    CHECK((solve_closed_form(p) - c).norm() <= 1e-7 * c.norm());
  }
}

TEST_CASE("Every answer is checked: a trajectory that cannot meet its waypoints is refused naming the cause", "[REQ-TRAJ-010]") {
  // 1 m in 1e-10 s next to a 1 s segment (minimum snap): the optimum swings ~1e33 m, so
  // monomial coefficients in double precision cannot end within 1e-9 L of the last waypoint,
  // not even after the waypoint polish.
  Eigen::MatrixX3d pts(3, 3);
  pts << 0, 0, 0, 1, 0, 0, 2, 1, 0;
  CHECK_THROWS_WITH(solve_minco(rest_to_rest(4, pts, {1e-10, 1.0})),
                    Contains("segment 1 meets its waypoints only to") && Contains("swings to") &&
                        Contains("durations span 1e-10 to 1 s (ratio 1e+10)"));
  CHECK_THROWS_WITH(solve_minco(rest_to_rest(4, pts, {1e9, 1.0})), Contains("segment 0 meets its waypoints"));
  // A spread of 3e6 is carried for minimum jerk: the optimum swings ~1e14 m, and the polish
  // puts both segment ends on their waypoints (the raw solve misses by ~3e-3 m). How far the
  // raw solve misses is rounding luck: at a spread of exactly 1e6 the written-out s = 3 solve
  // happens to end within 5e-10 m, so that case would not exercise the polish.
  {
    const auto p = rest_to_rest(3, pts, {3e-7, 1.0});
    PolynomialTrajectory raw;
    MincoSolver().solve(p, raw);
    CHECK(measure_answer(p, raw).interpolation > kAnswerInterpolation);
    const auto c = measure_answer(p, solve_minco(p));
    CHECK(c.term_scale > 1e12);
    CHECK(c.interpolation <= kAnswerInterpolation);
    CHECK(c.constraint <= kAnswerConstraint);
  }
  // A spread of 1e2 is carried: waypoints met to 1e-9 x L, every condition to 1e-10.
  const auto p = rest_to_rest(3, pts, {1e-2, 1.0});
  const auto t = solve_minco(p);
  const auto c = measure_answer(p, t);
  CHECK(c.finite);
  CHECK(c.interpolation <= kAnswerInterpolation);
  CHECK(c.constraint <= kAnswerConstraint);
  CHECK(c.optimality <= kAnswerOptimality);
  CHECK(c.position_scale == 2.0);
}

TEST_CASE("Straight lines pass the answer check: a vanishing derivative is measured against the positions",
          "[REQ-TRAJ-010]") {
  // Collinear, evenly spaced waypoints at equal durations: a constant-velocity optimum whose
  // acceleration and higher derivatives are rounding noise (the paths grid and RRT* planners
  // give). Refused before with a continuity residual of ~1 "relative" from n = 30 on.
  for (const int order : {3, 4})
    for (const int n : {30, 100, 1000}) {
      Eigen::MatrixX3d pts(n + 1, 3);
      for (int i = 0; i <= n; ++i) pts.row(i) << 0.5 * i, 0.3 * i, 1.0 + 0.1 * i;
      const auto p = rest_to_rest(order, pts, std::vector<double>(static_cast<std::size_t>(n), 1.0));
      INFO("order " << order << ", " << n << " segments");
      const auto t = solve_minco(p);  // throws if the check refuses
      const auto c = measure_answer(p, t);
      INFO("constraint " << c.constraint << ", optimality " << c.optimality);
      CHECK(c.constraint <= 1e-2 * kAnswerConstraint);  // a margin of 100 below the bounds
      CHECK(c.optimality <= 1e-2 * kAnswerOptimality);
    }
}

TEST_CASE("The answer check refuses a wrong, non-finite or inaccurate answer", "[REQ-TRAJ-010]") {
  Eigen::MatrixX3d pts(4, 3);
  pts << 0, 0, 0, 1, 2, 0, 3, 1, 1, 4, 4, 2;
  const auto p = rest_to_rest(4, pts, {1.0, 2.0, 0.5});
  const auto good = solve_minco(p);
  const auto base = measure_answer(p, good);
  CHECK(base.constraint < 1e-13);  // a few eps
  CHECK(base.optimality < 1e-11);
  CHECK_NOTHROW(check_answer(p, good));
  // A coefficient off by 1e-6 (relative): a continuity or waypoint condition breaks.
  auto off = good;
  off.mutable_coefficients()(13, 1) *= 1.0 + 1e-6;
  CHECK(measure_answer(p, off).constraint > kAnswerConstraint);
  CHECK_THROWS_WITH(check_answer(p, off), Contains("a constraint (waypoint, head, tail or continuity"));
  // The top coefficient of a snap segment off by 1e-4: the 6th derivative jumps (optimality).
  auto jump = good;
  jump.mutable_coefficients()(7, 2) += 1e-4 * std::abs(jump.mutable_coefficients()(7, 2)) + 1e-4;
  CHECK_THROWS_WITH(check_answer(p, jump), Contains("a constraint") || Contains("the optimality conditions"));
  // Off by 1e-12 relative only: still within the bounds (the check does not refuse round-off).
  auto tiny = good;
  tiny.mutable_coefficients()(13, 1) *= 1.0 + 1e-12;
  CHECK_NOTHROW(check_answer(p, tiny));
  // A NaN coefficient.
  auto nan = good;
  nan.mutable_coefficients()(5, 0) = std::nan("");
  CHECK_FALSE(measure_answer(p, nan).finite);
  CHECK_THROWS_WITH(check_answer(p, nan), Contains("the answer is not finite"));
  // The snap at the start differs from the head's: refused too.
  auto moved = p;
  moved.head.row(3) << 1e-3, 0, 0;
  CHECK_THROWS_WITH(check_answer(moved, good), Contains("a constraint"));
}

TEST_CASE("Each optimality condition is checked: a jump in any one derivative s..2s-2 alone is refused",
          "[REQ-TRAJ-010]") {
  // The dense system A c = b (optimality_system) with one continuity row's right-hand side set
  // to delta: its solution meets every other condition (waypoints, head, tail, the other
  // continuity orders) and has a jump of delta in exactly that derivative at that waypoint.
  Eigen::MatrixX3d pts(4, 3);
  pts << 0, 0, 0, 1, 2, 0, 3, 1, 1, 4, 4, 2;
  const std::vector<double> durations{1.0, 2.0, 0.5};
  for (int s : {3, 4}) {
    const auto p = rest_to_rest(s, pts, durations);
    const auto sys = optimality_system(p);
    const auto lu = sys.A.partialPivLu();
    const PolynomialTrajectory exact(s, durations, lu.solve(sys.b));
    REQUIRE_NOTHROW(check_answer(p, exact));
    for (int i = 0; i + 1 < static_cast<int>(durations.size()); ++i)
      for (int k = 0; k <= 2 * s - 2; ++k) {
        INFO("s = " << s << ", waypoint " << i + 1 << ", derivative " << k);
        // A jump of 1e-3 of the derivative's size there: 1e3 x kAnswerOptimality and above
        // kAnswerConstraint's 1e-9 by far, so the check must see it whichever bound applies.
        const double size = exact.evaluate_segment(i, durations[static_cast<std::size_t>(i)], k).cwiseAbs().maxCoeff();
        auto b = sys.b;
        b(s + i * 2 * s + 1 + k, 1) = 1e-3 * (size + 1.0);
        const PolynomialTrajectory jump(s, durations, lu.solve(b));
        const AnswerCheck c = measure_answer(p, jump);
        if (k < s) {
          CHECK(c.constraint > kAnswerConstraint);
          CHECK_THROWS_WITH(check_answer(p, jump), Contains("a constraint"));
        } else {
          CHECK(c.constraint < kAnswerConstraint);  // only the optimality condition is broken
          CHECK(c.optimality > kAnswerOptimality);
          CHECK_THROWS_WITH(check_answer(p, jump), Contains("the optimality conditions"));
        }
      }
  }
}

TEST_CASE("The waypoint polish moves no coefficient whose change would move a derivative past its damage bound",
          "[REQ-TRAJ-010]") {
  // One jerk segment, T = 1, x(t) = 1e-3 t + t^2 + t^3 + t^4 + t^5: the smallest term |c_j| T^j
  // is the velocity's (j = 1), so the polish reaches for c_1 first. Moving c_j by the miss r
  // moves derivative k (1 <= k <= min(j, 2s-2)) by r j!/(j-k)! against its scale
  // scaled[k] = sum_{j>=k} |c_j| T^j j!/(j-k)! (14.001 for the velocity). Held-out audit 6,
  // h6-traj-06: the bound skipped k = j (for j = 1 every derivative), so c_1 moved.
  MincoProblem p;
  p.order = 3;
  p.durations = {1.0};
  Eigen::MatrixX3d c = Eigen::MatrixX3d::Zero(6, 3);
  c.col(0) << 0.0, 1e-3, 1.0, 1.0, 1.0, 1.0;
  const double end = c.col(0).sum();
  const auto polished = [&](double miss) {
    p.points = Eigen::MatrixX3d::Zero(2, 3);
    p.points(1, 0) = end + miss;
    PolynomialTrajectory t(3, {1.0}, c);
    polish_waypoints(p, t);
    return Eigen::VectorXd(t.coefficients().col(0));
  };
  // r = 1e-9: any move changes the velocity by >= r / 14.001 ~ 7e-11 of its scale, past the
  // bound kPolishDamage = 1e-12: nothing moves.
  CHECK(polished(1e-9) == Eigen::VectorXd(c.col(0)));
  // r = 1e-14: c_1 moves by 1e-14 (7e-16 of the velocity's scale), the end meets the waypoint.
  const Eigen::VectorXd small = polished(1e-14);
  CHECK(small(1) != c(1, 0));
  CHECK(small(1) == Approx(1e-3 + 1e-14).margin(2e-15));  // the waypoint is end + 1e-14 to an ulp of 4
  for (int j = 2; j < 6; ++j) CHECK(small(j) == c(j, 0));
}
