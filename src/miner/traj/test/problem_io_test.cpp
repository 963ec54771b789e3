#include <catch2/catch.hpp>

#include <string>

#include "miner/core/error.hpp"
#include "miner/traj/problem_io.hpp"

using namespace miner::traj;
using Catch::Matchers::Contains;

namespace {
const char* kProblem = R"({"order": 3,
  "points": [[0,0,0],[1,2,0],[3,3,1]],
  "head": [[0,0,0],[0,0,0],[0,0,0]], "tail": [[3,3,1],[0,0,0],[0,0,0]],
  "limits": {"v_max": 2.0, "a_max": 1.0}})";
miner::Json problem() { return miner::parse_json(kProblem, "p.json"); }

/// The answer file of problem() solved at `order` (3 jerk, 4 snap: one more boundary row).
miner::Json solved_answer(int order) {
  miner::Json doc = problem();
  doc["order"] = order;
  if (order == 4) {
    doc["head"].push_back({0, 0, 0});
    doc["tail"].push_back({0, 0, 0});
  }
  return answer_to_json(solve_minco(problem_from_json(doc, "p.json")));
}
}  // namespace

TEST_CASE("A problem without durations gets trapezoidal ones: the answer has the contract's fields", "[REQ-TRAJ-006][REQ-TRAJ-001]") {
  const MincoProblem p = problem_from_json(problem(), "p.json");
  REQUIRE(p.durations.size() == 2);
  CHECK(p.durations[0] == Approx(trapezoidal_duration(std::sqrt(5.0), Limits{2, 1})));
  const auto answer = answer_to_json(solve_minco(p));
  CHECK(answer["order"] == 3);
  CHECK(answer["durations"].size() == 2);
  CHECK(answer["coefficients"].size() == 2);
  CHECK(answer["coefficients"][0].size() == 6);
  CHECK(answer["coefficients"][0][0].size() == 3);
  CHECK(answer["cost"].get<double>() > 0.0);
}

TEST_CASE("Explicit durations are used as given", "[REQ-TRAJ-006]") {
  auto doc = problem();
  doc["durations"] = {1.5, 2.5};
  doc.erase("limits");
  const MincoProblem p = problem_from_json(doc, "p.json");
  CHECK(p.durations == std::vector<double>{1.5, 2.5});
}

TEST_CASE("Problem file errors name the file and the field", "[REQ-TRAJ-007]") {
  auto doc = problem();
  doc.erase("limits");
  CHECK_THROWS_WITH(problem_from_json(doc, "p.json"), Contains("p.json: (top level): needs \"durations\" or \"limits\""));
  doc = problem();
  doc["limits"]["v_max"] = -2;
  CHECK_THROWS_WITH(problem_from_json(doc, "p.json"), Contains("p.json: limits.v_max: must be in [1e-06, 1e+06] m/s, got -2"));
  // Issue 20: 1e308 overflowed the trapezoid into NaN durations, blamed on "durations[0]".
  doc = problem();
  doc["limits"]["a_max"] = 1e308;
  CHECK_THROWS_WITH(problem_from_json(doc, "p.json"), Contains("p.json: limits.a_max: must be in [1e-06, 1e+06] m/s^2"));
  doc = problem();
  doc.erase("limits");
  doc["durations"] = {1.0, 0.0};
  CHECK_THROWS_WITH(problem_from_json(doc, "p.json"), Contains("p.json: durations[1]: must be positive and finite"));
  // Eighteenth campaign F14: "points: a trajectory needs at least 2 points" named no file.
  for (const miner::Json& points : {miner::Json::array(), miner::Json::array({miner::Json::array({0.0, 0.0, 0.0})})}) {
    doc = problem();
    doc["points"] = points;
    CHECK_THROWS_WITH(problem_from_json(doc, "p.json"),
                      Contains("p.json: points: a trajectory needs at least 2 points, got " + std::to_string(points.size())));
  }
  // Issue 20: a waypoint at 1e155 m overflowed the cost to "null" with exit 0; values beyond
  // 1e6 (m, m/s, ...) are refused, naming the row.
  for (const char* key : {"points", "head", "tail"}) {
    doc = problem();
    doc[key][1] = {0.0, 1e155, 0.0};
    INFO(key);
    CHECK_THROWS_WITH(problem_from_json(doc, "p.json"), Contains(std::string("p.json: ") + key + "[1]") && Contains("1e6"));
  }
  // Inside the bound, the answer check still refuses a cost that overflows.
  {
    MincoProblem far = problem_from_json(problem(), "p.json");
    far.points *= 1e160;
    far.head.row(0) = far.points.row(0);
    far.tail.row(0) = far.points.row(far.points.rows() - 1);
    CHECK_THROWS_WITH(solve_minco(far), Contains("not finite"));
  }
  doc = problem();
  doc.erase("limits");
  doc["durations"] = {1.0, 0.0};
  // Both: the limits would not be applied to given durations (issue 20: exceeded silently).
  doc["durations"] = {1.0, 1.0};
  doc["limits"] = {{"v_max", 1.0}, {"a_max", 1.0}};
  CHECK_THROWS_WITH(problem_from_json(doc, "p.json"), Contains("p.json: limits: durations are given"));
  doc = problem();
  doc["order"] = 3.5;
  CHECK_THROWS_WITH(problem_from_json(doc, "p.json"), Contains("order: expected an integer"));
  doc = problem();
  doc["head"] = {{0, 0, 0}};
  CHECK_THROWS_WITH(problem_from_json(doc, "p.json"), Contains("head: expected 3 rows"));
  doc = problem();
  doc["points"][1] = {1, 2};
  CHECK_THROWS_WITH(problem_from_json(doc, "p.json"), Contains("points[1]: expected an array of 3 numbers"));
  CHECK_THROWS_WITH(problem_from_json(miner::Json::array(), "p.json"), Contains("expected a JSON object"));
}

TEST_CASE("A trajectory answer file is read strictly: junctions meet, the cost is its own, no unknown key",
          "[REQ-TRAJ-006][REQ-TRAJ-007]") {
  // Issue 20, fifth campaign: a 0.5 m jump between segments, an unknown key and a wrong cost
  // were all read and flown.
  const miner::Json good = answer_to_json(solve_minco(problem_from_json(problem(), "p.json")));
  const PolynomialTrajectory back = trajectory_from_answer_json(good, "a.json");
  CHECK(back.segments() == 2);
  CHECK(back.cost() == Approx(good["cost"].get<double>()).epsilon(1e-12));
  miner::Json jump = good;
  jump["coefficients"][1][0][0] = jump["coefficients"][1][0][0].get<double>() + 0.5;  // position x at the junction
  CHECK_THROWS_WITH(trajectory_from_answer_json(jump, "a.json"),
                    Contains("a.json: coefficients[1]: the position at the start of segment 1") && Contains("would jump"));
  // A duration that is not positive is named by the reader, in the file's words (held-out
  // audit 8, h8-traj-02: -10 s was read and the flight then failed on a 448 m/s speed).
  for (const double bad : {-10.0, 0.0}) {
    miner::Json negative = good;
    negative["durations"][0] = bad;
    CHECK_THROWS_WITH(trajectory_from_answer_json(negative, "a.json"), Contains("a.json: durations[0]: must be positive"));
  }
  miner::Json kink = good;
  kink["coefficients"][1][1][1] = kink["coefficients"][1][1][1].get<double>() + 0.05;  // velocity y
  CHECK_THROWS_WITH(trajectory_from_answer_json(kink, "a.json"), Contains("the velocity at the start of segment 1"));
  // Every derivative 0..s-1 meets, the highest (s-1) too, for jerk and snap (held-out audit 6,
  // h6-traj-04: the last one went unchecked). Row k of a segment is t^k's coefficient: the
  // k-th derivative at its start is k! times it.
  for (const int order : {3, 4}) {
    const miner::Json answer = solved_answer(order);
    REQUIRE_NOTHROW(trajectory_from_answer_json(answer, "a.json"));
    const char* const names[] = {"position", "velocity", "acceleration", "jerk"};
    for (int k = 0; k < order; ++k) {
      INFO("order " << order << ", derivative " << k);
      miner::Json bent = answer;
      bent["coefficients"][1][k][2] = bent["coefficients"][1][k][2].get<double>() + 0.05;
      CHECK_THROWS_WITH(trajectory_from_answer_json(bent, "a.json"),
                        Contains(std::string("the ") + names[k] + " at the start of segment 1"));
    }
  }
  // As many coefficient blocks as durations: one more or one fewer is named.
  miner::Json short_of = good;
  short_of["coefficients"].erase(1);
  CHECK_THROWS_WITH(trajectory_from_answer_json(short_of, "a.json"),
                    Contains("a.json: coefficients: has 1 segments but durations has 2"));
  miner::Json long_of = good;
  long_of["durations"].push_back(1.0);
  CHECK_THROWS_WITH(trajectory_from_answer_json(long_of, "a.json"),
                    Contains("a.json: coefficients: has 2 segments but durations has 3"));
  miner::Json extra = good;
  extra["extra"] = 1;
  CHECK_THROWS_WITH(trajectory_from_answer_json(extra, "a.json"), Contains("a.json: extra: unknown key"));
  miner::Json junk = good;
  junk["allocation"] = {{"bogus", 1}};
  CHECK_THROWS_WITH(trajectory_from_answer_json(junk, "a.json"), Contains("allocation.bogus: unknown key"));
  miner::Json cost = good;
  cost["cost"] = -1.0;
  CHECK_THROWS_WITH(trajectory_from_answer_json(cost, "a.json"), Contains("a.json: cost: is -1.0 but the coefficients' cost"));
  miner::Json tiny = good;  // below the junction tolerance: the rounding of a written file
  tiny["coefficients"][1][0][0] = tiny["coefficients"][1][0][0].get<double>() + 1e-9;
  CHECK_NOTHROW(trajectory_from_answer_json(tiny, "a.json"));
}

TEST_CASE("A trajectory answer's segment needs exactly 2s coefficient rows: one more or one fewer is refused",
          "[REQ-TRAJ-007][REQ-FLIGHT-007]") {
  // Held-out audit 9, h9-traj-04: only too few rows were refused; a segment with 2s + 1 rows was read
  // with the extra row silently dropped.
  for (const int order : {3, 4}) {
    INFO("order " << order);
    const miner::Json answer = solved_answer(order);
    REQUIRE(answer["coefficients"][0].size() == static_cast<std::size_t>(2 * order));
    CHECK_NOTHROW(trajectory_from_answer_json(answer, "a.json"));
    const std::string needs = "needs 2s = " + std::to_string(2 * order) + " rows";
    for (const int segment : {0, 1}) {
      miner::Json more = answer;
      more["coefficients"][segment].push_back({5, 5, 5});
      CHECK_THROWS_WITH(trajectory_from_answer_json(more, "a.json"),
                        Contains("a.json: coefficients[" + std::to_string(segment) + "]") && Contains(needs));
      miner::Json fewer = answer;
      fewer["coefficients"][segment].erase(fewer["coefficients"][segment].size() - 1);
      CHECK_THROWS_WITH(trajectory_from_answer_json(fewer, "a.json"),
                        Contains("a.json: coefficients[" + std::to_string(segment) + "]") && Contains(needs));
    }
  }
  // Order 4 with 9 rows of zeros and a last row of 5s (the input of the audit).
  const miner::Json nine = miner::parse_json(
      R"({"order":4,"durations":[1],"coefficients":[[[0,0,0],[0,0,0],[0,0,0],[0,0,0],[0,0,0],[0,0,0],[0,0,0],[0,0,0],[5,5,5]]]})",
      "a.json");
  CHECK_THROWS_WITH(trajectory_from_answer_json(nine, "a.json"), Contains("coefficients[0]: needs 2s = 8 rows"));
}
