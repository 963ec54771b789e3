#pragma once
/// \file
/// Golden files (REQ-HARNESS-002).
///
/// A golden file golden/<capability>/<name>.json holds
///   {"tolerance": {"abs": 1e-12, "rel": 1e-9, "by_key": {"rotor_0": {...}}}, "value": <any JSON>}
/// A number a matches its golden g when |a - g| <= abs + rel * max(|a|, |g|), with the
/// tolerance of the innermost enclosing object key that has its own (by_key), else the
/// fallback; strings, booleans and null match exactly; arrays match element-wise with equal
/// lengths; objects match key-wise with the same keys. NaN never matches.
///
/// The tolerances live in the test code (issue 19 item 3): the file only records them, and a
/// file whose recorded tolerance differs from the test's fails (a re-blessed file cannot
/// loosen a test). On a mismatch or a missing golden the harness writes <name>.json.received
/// beside it (same format) and fails with the first differences. With UPDATE_GOLDEN=1 in the
/// environment it rewrites the golden instead (with the test's tolerance), except under CI
/// (CI set), where updating is refused.

#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace miner::testing {

struct Tolerance {
  double abs = 0.0;
  double rel = 0.0;
};

/// A test's tolerances: `fallback` for every number, or the one of the innermost enclosing
/// object key listed in `by_key` (sized to that quantity: metres, rad/s, probabilities).
struct Tolerances {
  Tolerance fallback;
  std::map<std::string, Tolerance> by_key;
  Tolerances(const Tolerance& t) : fallback(t) {}  // NOLINT(google-explicit-constructor): one tolerance for all
  Tolerances(const Tolerance& t, std::map<std::string, Tolerance> keys) : fallback(t), by_key(std::move(keys)) {}
  /// The "tolerance" object a golden file records.
  nlohmann::json to_json() const;
};

/// Differences between `actual` and `expected`, as "path: expected X, got Y" lines;
/// at most `limit` of them. Empty means they match.
std::vector<std::string> compare_json(const nlohmann::json& expected, const nlohmann::json& actual,
                                      const Tolerances& tol, std::size_t limit = 20);

struct GoldenOutcome {
  bool ok = false;
  std::string message;  ///< what happened, for INFO()
};

enum class GoldenMode { kCheck, kUpdate };

/// The mode the environment asks for: kUpdate iff UPDATE_GOLDEN=1. Throws
/// std::runtime_error when UPDATE_GOLDEN=1 and CI is set (goldens never change in CI).
GoldenMode golden_mode_from_environment();

/// Checks (or, in kUpdate mode, rewrites) the golden file at `path` with the test's tolerance
/// `tol`; a file recording another tolerance fails.
GoldenOutcome check_golden_file(const std::string& path, const nlohmann::json& actual, const Tolerances& tol,
                                GoldenMode mode);

/// check_golden_file on MINER_SOURCE_DIR/golden/<relative_path> in the environment's mode.
GoldenOutcome check_golden(const std::string& relative_path, const nlohmann::json& actual, const Tolerances& tol);

}  // namespace miner::testing

/// REQUIREs that `actual` matches golden/<relative_path>.
#define MINER_REQUIRE_GOLDEN(relative_path, actual, tol)                           \
  do {                                                                              \
    const auto miner_golden_outcome_ = ::miner::testing::check_golden(relative_path, actual, tol); \
    INFO(miner_golden_outcome_.message);                                            \
    REQUIRE(miner_golden_outcome_.ok);                                              \
  } while (false)
