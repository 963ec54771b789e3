#include "miner/traj/problem_io.hpp"

#include <algorithm>
#include <cmath>

#include "miner/core/error.hpp"
#include "miner/core/text.hpp"

namespace miner::traj {

namespace {
/// Limits a problem file may give (m/s, m/s^2): wide enough for any unit a user picks at
/// these scales, narrow enough that the trapezoid's v^2 / a stays finite.
constexpr double kMinLimitValue = 1e-6;
constexpr double kMaxLimitValue = 1e6;
}  // namespace

namespace {
/// The largest |value| of a waypoint coordinate (m) or a head/tail derivative (m/s^k) a
/// problem file may give: 1000 km, far beyond any flight, while the cost (derivatives
/// squared, integrated) stays finite; 1e155 overflowed it to a "null" cost (issue 20).
constexpr double kMaxProblemValue = 1e6;

Eigen::MatrixX3d rows_of(const JsonField& f) {
  const std::size_t n = f.array_size();
  Eigen::MatrixX3d m(static_cast<Eigen::Index>(n), 3);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d v = f.at(i).vec3();
    if (!(v.cwiseAbs().maxCoeff() <= kMaxProblemValue)) f.at(i).fail("a value beyond +-1e6 (m, m/s, ...)");
    m.row(static_cast<Eigen::Index>(i)) = v.transpose();
  }
  return m;
}
}  // namespace

MincoProblem problem_from_json(const Json& doc, const std::string& origin) {
  const JsonField root(doc, "", origin);
  if (!doc.is_object()) root.fail("expected a JSON object (a trajectory problem)");
  root.only_keys({"order", "points", "durations", "head", "tail", "limits", "allocation", "rho"});
  MincoProblem p;
  p.order = root.at("order").integer();
  p.points = rows_of(root.at("points"));
  // Named with the file here, before any allocation reads them (eighteenth campaign F14).
  if (p.points.rows() < 2)
    root.at("points").fail("a trajectory needs at least 2 points, got " + std::to_string(p.points.rows()));
  p.head = rows_of(root.at("head"));
  p.tail = rows_of(root.at("tail"));
  if (root.has("durations")) {
    // Durations fix the timing; limits beside them would be ignored (issue 20: the answer
    // exceeded the v_max the file gave, without a word).
    if (root.has("limits")) root.at("limits").fail("durations are given: the limits would not be applied (give one of them)");
    const JsonField d = root.at("durations");
    for (std::size_t i = 0; i < d.array_size(); ++i) p.durations.push_back(d.at(i).number());
  } else {
    if (!root.has("limits")) root.fail("needs \"durations\" or \"limits\" (for trapezoidal allocation)");
    const JsonField l = root.at("limits");
    l.only_keys({"v_max", "a_max"});
    // Physical speeds and accelerations: 1e308 overflowed the trapezoid's v^2 / a into NaN
    // durations, reported as a field the file does not have (issue 20).
    const Limits limits{l.at("v_max").number_in(kMinLimitValue, kMaxLimitValue, "m/s"),
                        l.at("a_max").number_in(kMinLimitValue, kMaxLimitValue, "m/s^2")};
    try {
      validate(limits);
    } catch (const Error& e) {
      throw Error(origin + ": " + e.what());
    }
    p.durations = trapezoidal_allocation(p.points, limits);
  }
  try {
    validate(p);
  } catch (const Error& e) {
    throw Error(origin + ": " + e.what());
  }
  return p;
}

TrajectoryRequest request_from_json(const Json& doc, const std::string& origin, const std::string& allocation_override,
                                    std::optional<double> rho_override) {
  TrajectoryRequest r;
  r.problem = problem_from_json(doc, origin);
  const JsonField root(doc, "", origin);
  std::string method = root.has("allocation") ? root.at("allocation").string() : "trapezoid";
  if (!allocation_override.empty()) method = allocation_override;
  if (method != "trapezoid" && method != "optimise") {
    const std::string expected = "expected \"trapezoid\" or \"optimise\", got \"" + method + "\"";
    if (!allocation_override.empty()) throw Error("--allocate: " + expected, ExitCode::kUsage);
    root.at("allocation").fail(expected);
  }
  if (method == "trapezoid") {
    // A command-line option the run would not use is a usage error (exit 2).
    if (rho_override) throw Error("--rho: only used with --allocate optimise", ExitCode::kUsage);
    // Given durations are the timing: an allocation request beside them would not be applied
    // (sixteenth campaign F6: `--allocate trapezoid` was ignored, while optimise was refused).
    if (root.has("durations")) {
      if (!allocation_override.empty())
        throw Error("--allocate: " + origin + " gives durations, so there is nothing to allocate: drop --allocate or the durations",
                    ExitCode::kUsage);
      if (root.has("allocation"))
        root.at("allocation").fail("durations are given, so there is nothing to allocate: drop one of them");
    }
    if (root.has("rho")) {
      // Overridden on the command line, the file's own request is not at fault: say which
      // option made its rho unused (issue 20, fifth campaign: the advice blamed the file).
      const bool overridden = !allocation_override.empty() && root.has("allocation") &&
                              root.at("allocation").string() == "optimise";
      root.at("rho").fail(overridden ? "only used with \"allocation\": \"optimise\", which --allocate trapezoid "
                                       "replaces: drop --allocate to optimise with this rho, or drop rho from the file"
                                     : "only used with \"allocation\": \"optimise\"");
    }
    return r;
  }
  if (root.has("durations")) {
    // The same conflict as with trapezoid, the same class: an option against the file is a usage
    // error (seventeenth campaign F29: exit 1 here, exit 2 there).
    if (!allocation_override.empty())
      throw Error("--allocate: " + origin + " gives durations, so there is nothing to allocate: drop --allocate or the durations",
                  ExitCode::kUsage);
    root.at("durations").fail("durations are given, so there is nothing to optimise: drop them (or the optimise request)");
  }
  AllocationOptions o;
  const JsonField l = root.at("limits");
  o.limits = Limits{l.at("v_max").number_in(kMinLimitValue, kMaxLimitValue, "m/s"),
                    l.at("a_max").number_in(kMinLimitValue, kMaxLimitValue, "m/s^2")};
  if (root.has("rho")) o.rho = root.at("rho").number_in(1e-9, 1e9);
  if (rho_override) {
    if (!std::isfinite(*rho_override) || !(*rho_override > 0.0))
      throw Error("--rho: must be positive and finite, got " + std::to_string(*rho_override));
    o.rho = *rho_override;
  }
  r.optimise = o;
  return r;
}

Json answer_to_json(const AllocationResult& a, const AllocationOptions& o) {
  Json j = answer_to_json(a.trajectory);
  j["allocation"] = {{"method", "optimise"},
                     {"rho", o.rho},
                     {"objective", a.objective},
                     {"trapezoid_objective", a.start_objective},
                     {"trapezoid_stretch", a.start_scale},
                     {"cost", a.cost},
                     {"total_time", a.total_time},
                     {"max_speed", a.max_speed},
                     {"max_acceleration", a.max_acceleration},
                     {"v_max", o.limits.v_max},
                     {"a_max", o.limits.a_max},
                     {"iterations", a.iterations},
                     {"polish_evaluations", a.polish_evaluations},
                     {"termination", a.termination}};
  // No wall-clock time: the same problem gives the same bytes (issue 20, eighth campaign N1).
  // A file written before keeps its "solve_ms", read and ignored.
  return j;
}

Json answer_to_json(const PolynomialTrajectory& t) {
  Json coefficients = Json::array();
  for (int i = 0; i < t.segments(); ++i) {
    Json seg = Json::array();
    const auto c = t.segment_coefficients(i);
    for (Eigen::Index r = 0; r < c.rows(); ++r) seg.push_back({c(r, 0), c(r, 1), c(r, 2)});
    coefficients.push_back(seg);
  }
  return {{"order", t.order()}, {"durations", t.durations()}, {"cost", t.cost()},
          {"coefficients", coefficients}};
}

namespace {
/// The "allocation" record of an answer (answer_to_json's) is what `traj solve --allocate
/// optimise` said of this curve: its method, rho and limits in their ranges, and its figures
/// those of the coefficients (seventeenth campaign F17: "magic", rho -1 and a total time of 1 s
/// for a 25 s curve were read without a word). `tolerance` is relative, floor 1.
void check_allocation_record(const JsonField& a, const PolynomialTrajectory& t, double tolerance) {
  if (a.has("method") && a.at("method").string() != "optimise")
    a.at("method").fail("expected \"optimise\" (the only allocation that writes this record), got \"" +
                        a.at("method").string() + "\"");
  if (a.has("rho")) (void)a.at("rho").number_in(1e-9, 1e9);
  if (a.has("v_max")) (void)a.at("v_max").number_in(kMinLimitValue, kMaxLimitValue, "m/s");
  if (a.has("a_max")) (void)a.at("a_max").number_in(kMinLimitValue, kMaxLimitValue, "m/s^2");
  const auto agrees = [&](const char* key, double actual, const std::string& what) {
    if (!a.has(key)) return;
    const double recorded = a.at(key).number();
    if (!(std::fabs(recorded - actual) <= tolerance * std::max(1.0, std::fabs(actual))))
      a.at(key).fail("is " + exact_number(recorded) + " but " + what + " is " + exact_number(actual) +
                     ": the record was edited or is stale");
  };
  agrees("cost", t.cost(), "the coefficients' cost");
  agrees("total_time", t.total_duration(), "the durations' sum");
  if (a.has("max_speed") || a.has("max_acceleration")) {
    const auto [v, acc] = exact_extremes(t);
    agrees("max_speed", v, "the curve's peak speed");
    agrees("max_acceleration", acc, "the curve's peak acceleration");
  }
  if (a.has("objective") && a.has("rho"))
    agrees("objective", t.cost() + a.at("rho").number() * t.total_duration(), "J + rho T of the curve");
}
}  // namespace

PolynomialTrajectory trajectory_from_answer_json(const Json& doc, const std::string& origin) {
  const JsonField root(doc, "", origin);
  // Strict like every file (issue 20, fifth campaign: unknown keys and a junk "allocation"
  // block were ignored): an answer's own keys, and its allocation record's.
  root.only_keys({"order", "durations", "cost", "coefficients", "allocation"});
  if (root.has("allocation"))
    root.at("allocation").only_keys({"method", "rho", "objective", "trapezoid_objective", "trapezoid_stretch", "cost",
                                     "total_time", "max_speed", "max_acceleration", "v_max", "a_max",
                                     "iterations", "polish_evaluations", "termination",
                                     "solve_ms"});
  const JsonField order_field = root.at("order");
  const int order = order_field.integer();
  if (order != 3 && order != 4) order_field.fail("must be 3 (jerk) or 4 (snap)");
  const JsonField durations_field = root.at("durations");
  const JsonField coefficients_field = root.at("coefficients");
  const std::size_t m = durations_field.array_size();
  if (m == 0) durations_field.fail("needs at least one segment");
  if (coefficients_field.array_size() != m)
    coefficients_field.fail("has " + std::to_string(coefficients_field.array_size()) +
                            " segments but durations has " + std::to_string(m));
  std::vector<double> durations(m);
  Eigen::MatrixX3d c(2 * order * static_cast<Eigen::Index>(m), 3);
  for (std::size_t i = 0; i < m; ++i) {
    durations[i] = durations_field.at(i).positive_number();
    const JsonField seg = coefficients_field.at(i);
    if (seg.array_size() != static_cast<std::size_t>(2 * order))
      seg.fail("needs 2s = " + std::to_string(2 * order) + " rows of [x, y, z]");
    for (int r = 0; r < 2 * order; ++r)
      c.row(2 * order * static_cast<Eigen::Index>(i) + r) = seg.at(static_cast<std::size_t>(r)).vec3().transpose();
  }
  PolynomialTrajectory t(order, std::move(durations), std::move(c));
  // A trajectory is flown as one curve: at every junction position and derivatives 1..s-1
  // (velocity, acceleration and, for snap, jerk) must meet, or the reference jumps (issue 20,
  // fifth campaign: a 0.5 m jump between segments was flown). kJunctionTolerance is relative
  // to the larger side, with 1 as the floor: the answers MINER writes meet to ~1e-12.
  constexpr double kJunctionTolerance = 1e-6;
  for (int i = 0; i + 1 < t.segments(); ++i)
    for (int k = 0; k < order; ++k) {
      const Eigen::Vector3d end = t.evaluate_segment(i, t.durations()[static_cast<std::size_t>(i)], k);
      const Eigen::Vector3d next = t.evaluate_segment(i + 1, 0.0, k);
      const double scale = std::max({1.0, end.cwiseAbs().maxCoeff(), next.cwiseAbs().maxCoeff()});
      if ((end - next).cwiseAbs().maxCoeff() > kJunctionTolerance * scale) {
        static const char* const kNames[] = {"position", "velocity", "acceleration", "jerk"};
        coefficients_field.at(static_cast<std::size_t>(i) + 1)
            .fail(std::string("the ") + kNames[k] + " at the start of segment " + std::to_string(i + 1) + ", " +
                  format_point(next) + ", does not meet the end of segment " + std::to_string(i) + ", " +
                  format_point(end) + ": the trajectory would jump there");
      }
    }
  // The recorded cost, when given, is this trajectory's (a stale or edited one is refused).
  if (root.has("cost")) {
    const double recorded = root.at("cost").number(), actual = t.cost();
    if (!(std::fabs(recorded - actual) <= kJunctionTolerance * std::max(1.0, std::fabs(actual))))
      root.at("cost").fail("is " + root.at("cost").value().dump() + " but the coefficients' cost is " +
                           std::to_string(actual) + ": the file was edited or is stale");
  }
  if (root.has("allocation")) check_allocation_record(root.at("allocation"), t, kJunctionTolerance);
  return t;
}

}  // namespace miner::traj
