#include <catch2/catch.hpp>

#include <cstdlib>
#include <filesystem>

#include "miner/core/json_io.hpp"
#include "miner/testing/golden.hpp"

using namespace miner::testing;
using Catch::Matchers::Contains;
using nlohmann::json;

namespace {
std::string fresh_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("miner_golden_test_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

/// Sets an environment variable for one scope.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    const char* old = std::getenv(name);
    if (old) old_ = old;
    had_ = old != nullptr;
    if (value) ::setenv(name, value, 1); else ::unsetenv(name);
  }
  ~ScopedEnv() {
    if (had_) ::setenv(name_, old_.c_str(), 1); else ::unsetenv(name_);
  }
 private:
  const char* name_;
  std::string old_;
  bool had_ = false;
};
}  // namespace

TEST_CASE("compare_json applies abs + rel * max(|a|, |b|) to numbers and exact rules to the rest", "[REQ-HARNESS-002]") {
  const Tolerance tol{1e-6, 1e-3};  // bound: 1.001e-3 near 1, about 1.0 near 1000
  CHECK(compare_json(json{1.0, 1000.0}, json{1.0 + 9e-4, 1000.9}, tol).empty());
  const auto d = compare_json(json{1.0, 1000.0}, json{1.0 + 2e-3, 1002.0}, tol);
  REQUIRE(d.size() == 2);
  CHECK_THAT(d[0], Contains("value[0]: expected 1"));
  CHECK_THAT(d[1], Contains("value[1]: expected 1000, got 1002"));
  CHECK_FALSE(compare_json(json{{"a", 1}}, json{{"a", std::nan("")}}, tol).empty());
  CHECK_THAT(compare_json(json{{"a", 1}}, json{{"b", 1}}, tol).at(0), Contains("value.a: missing in the result"));
  CHECK_THAT(compare_json(json{{"a", 1}}, json{{"a", 1}, {"b", 2}}, tol).at(0), Contains("value.b: not in the golden file"));
  CHECK_THAT(compare_json(json{1, 2}, json{1}, tol).at(0), Contains("expected 2 elements, got 1"));
  CHECK_THAT(compare_json(json("x"), json("y"), tol).at(0), Contains("expected \"x\", got \"y\""));
  CHECK_THAT(compare_json(json("x"), json(1), tol).at(0), Contains("expected string"));
  CHECK(compare_json(json::array({1, 2, 3, 4, 5}), json::array({0, 0, 0, 0, 0}), tol, 2).size() == 2);
}

TEST_CASE("A mismatch fails, names the difference and writes a .received file", "[REQ-HARNESS-002]") {
  const std::string dir = fresh_dir("mismatch");
  const std::string path = dir + "/g.json";
  miner::write_file_atomic(path, miner::dump_json({{"tolerance", {{"abs", 0.0}, {"rel", 1e-9}}}, {"value", {{"x", 1.0}}}}));
  const Tolerance tol{0.0, 1e-9};  // the test's, recorded in the file
  const auto bad = check_golden_file(path, json{{"x", 1.5}}, tol, GoldenMode::kCheck);
  CHECK_FALSE(bad.ok);
  CHECK_THAT(bad.message, Contains("value.x: expected 1, got 1.5"));
  CHECK_THAT(bad.message, Contains("UPDATE_GOLDEN=1 ctest -L golden"));
  REQUIRE(std::filesystem::exists(path + ".received"));
  const json received = miner::read_json_file(path + ".received");
  CHECK(received["value"]["x"] == 1.5);
  CHECK(received["tolerance"]["rel"] == 1e-9);  // the test's tolerance is recorded
  // The golden itself is untouched; a later match removes the stale .received.
  const auto good = check_golden_file(path, json{{"x", 1.0 + 1e-12}}, tol, GoldenMode::kCheck);
  CHECK(good.ok);
  CHECK_FALSE(std::filesystem::exists(path + ".received"));
}

TEST_CASE("A missing or unreadable golden fails with a .received to accept", "[REQ-HARNESS-002]") {
  const std::string dir = fresh_dir("missing");
  const auto missing = check_golden_file(dir + "/new.json", json{1, 2}, Tolerance{1e-9, 0}, GoldenMode::kCheck);
  CHECK_FALSE(missing.ok);
  CHECK_THAT(missing.message, Contains("no golden file"));
  CHECK(std::filesystem::exists(dir + "/new.json.received"));
  miner::write_file_atomic(dir + "/broken.json", "{\"value\": 1}");
  const auto broken = check_golden_file(dir + "/broken.json", json(1), Tolerance{}, GoldenMode::kCheck);
  CHECK_FALSE(broken.ok);
  CHECK_THAT(broken.message, Contains("unreadable golden file"));
}

TEST_CASE("Update mode rewrites the golden with the test's tolerance and CI refuses update mode", "[REQ-HARNESS-002]") {
  const std::string dir = fresh_dir("update");
  const std::string path = dir + "/sub/g.json";
  const Tolerance tol{1e-3, 0.0};
  const auto first = check_golden_file(path, json{{"x", 2.0}}, tol, GoldenMode::kUpdate);
  CHECK(first.ok);
  CHECK(miner::read_json_file(path)["tolerance"]["abs"] == 1e-3);
  CHECK(check_golden_file(path, json{{"x", 2.0005}}, tol, GoldenMode::kCheck).ok);
  CHECK_FALSE(check_golden_file(path, json{{"x", 2.1}}, tol, GoldenMode::kCheck).ok);
  CHECK(check_golden_file(path, json{{"x", 2.1}}, tol, GoldenMode::kUpdate).ok);
  CHECK(miner::read_json_file(path)["value"]["x"] == 2.1);

  {
    ScopedEnv update("UPDATE_GOLDEN", "1");
    ScopedEnv ci("CI", "true");
    CHECK_THROWS_WITH(golden_mode_from_environment(), Contains("refused under CI"));
  }
  {
    ScopedEnv update("UPDATE_GOLDEN", "1");
    ScopedEnv ci("CI", nullptr);
    CHECK(golden_mode_from_environment() == GoldenMode::kUpdate);
  }
  {
    ScopedEnv update("UPDATE_GOLDEN", nullptr);
    CHECK(golden_mode_from_environment() == GoldenMode::kCheck);
  }
}

TEST_CASE("A golden file cannot loosen the test's tolerance: the test fixes it", "[REQ-HARNESS-002]") {
  const std::string dir = fresh_dir("strict");
  const std::string path = dir + "/g.json";
  const Tolerance strict{1e-9, 0.0};
  REQUIRE(check_golden_file(path, json{{"x", 2.0}}, strict, GoldenMode::kUpdate).ok);
  // A re-blessed (or hand-edited) file that records a looser tolerance fails, though the value
  // would match under the file's tolerance.
  json doc = miner::read_json_file(path);
  doc["tolerance"]["abs"] = 1.0;
  miner::write_file_atomic(path, miner::dump_json(doc));
  const auto loose = check_golden_file(path, json{{"x", 2.5}}, strict, GoldenMode::kCheck);
  CHECK_FALSE(loose.ok);
  CHECK_THAT(loose.message, Contains("tolerances live in the test code"));
  // So does a file blessed under a test that has since tightened its tolerance, even when the
  // value is unchanged: the file must record what is checked.
  REQUIRE(check_golden_file(path, json{{"x", 2.0}}, Tolerance{1e-3, 0.0}, GoldenMode::kUpdate).ok);
  CHECK_FALSE(check_golden_file(path, json{{"x", 2.0}}, strict, GoldenMode::kCheck).ok);
  CHECK(check_golden_file(path, json{{"x", 2.0}}, Tolerance{1e-3, 0.0}, GoldenMode::kCheck).ok);
}

TEST_CASE("A key's own tolerance applies to the numbers under it, the fallback elsewhere", "[REQ-HARNESS-002]") {
  // Rotor speeds (~800 rad/s) to 1e-6 rad/s, positions (m) to 1e-9 m, the rest exact.
  const Tolerances tol(Tolerance{0.0, 0.0}, {{"rotor", {1e-6, 0.0}}, {"position", {1e-9, 0.0}}});
  const json golden = {{"rotor", {800.0, 801.0}}, {"position", {{"x", 1.0}}}, {"count", 3}};
  CHECK(compare_json(golden, json{{"rotor", {800.0000005, 801.0}}, {"position", {{"x", 1.0 + 5e-10}}}, {"count", 3}},
                     tol).empty());
  // +1e-3 on a rotor speed (1.25e-6 relative) is caught; a relative fallback of 1e-4 would not.
  const auto rotor = compare_json(golden, json{{"rotor", {800.001, 801.0}}, {"position", {{"x", 1.0}}}, {"count", 3}}, tol);
  REQUIRE(rotor.size() == 1);
  CHECK_THAT(rotor[0], Contains("value.rotor[0]"));
  CHECK(compare_json(golden, json{{"rotor", {800.001, 801.0}}, {"position", {{"x", 1.0}}}, {"count", 3}},
                     Tolerance{0.0, 1e-4}).empty());
  CHECK(compare_json(golden, json{{"rotor", {800.0, 801.0}}, {"position", {{"x", 1.0 + 2e-9}}}, {"count", 3}}, tol).size() == 1);
  CHECK(compare_json(golden, json{{"rotor", {800.0, 801.0}}, {"position", {{"x", 1.0}}}, {"count", 3.0000001}}, tol).size() == 1);
  CHECK(tol.to_json()["by_key"]["rotor"]["abs"] == 1e-6);
}
