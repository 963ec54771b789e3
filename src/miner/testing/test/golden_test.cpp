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
  const auto bad = check_golden_file(path, json{{"x", 1.5}}, Tolerance{}, GoldenMode::kCheck);
  CHECK_FALSE(bad.ok);
  CHECK_THAT(bad.message, Contains("value.x: expected 1, got 1.5"));
  CHECK_THAT(bad.message, Contains("UPDATE_GOLDEN=1 ctest -L golden"));
  REQUIRE(std::filesystem::exists(path + ".received"));
  const json received = miner::read_json_file(path + ".received");
  CHECK(received["value"]["x"] == 1.5);
  CHECK(received["tolerance"]["rel"] == 1e-9);  // the golden's own tolerance is kept
  // The golden itself is untouched; a later match removes the stale .received.
  const auto good = check_golden_file(path, json{{"x", 1.0 + 1e-12}}, Tolerance{}, GoldenMode::kCheck);
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

TEST_CASE("Update mode rewrites the golden with its tolerance and CI refuses update mode", "[REQ-HARNESS-002]") {
  const std::string dir = fresh_dir("update");
  const std::string path = dir + "/sub/g.json";
  const auto first = check_golden_file(path, json{{"x", 2.0}}, Tolerance{1e-3, 0.0}, GoldenMode::kUpdate);
  CHECK(first.ok);
  CHECK(miner::read_json_file(path)["tolerance"]["abs"] == 1e-3);
  CHECK(check_golden_file(path, json{{"x", 2.0005}}, Tolerance{}, GoldenMode::kCheck).ok);
  CHECK_FALSE(check_golden_file(path, json{{"x", 2.1}}, Tolerance{}, GoldenMode::kCheck).ok);
  CHECK(check_golden_file(path, json{{"x", 2.1}}, Tolerance{}, GoldenMode::kUpdate).ok);
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
