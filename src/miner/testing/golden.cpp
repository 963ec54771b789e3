#include "miner/testing/golden.hpp"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "miner/core/json_io.hpp"

namespace miner::testing {

namespace {

void compare_into(const nlohmann::json& e, const nlohmann::json& a, const Tolerances& rules, const Tolerance& tol,
                  const std::string& path, std::size_t limit, std::vector<std::string>& out) {
  if (out.size() >= limit) return;
  const auto where = path.empty() ? std::string("value") : path;
  if (e.is_number() && a.is_number()) {
    const double x = e.get<double>(), y = a.get<double>();
    const double bound = tol.abs + tol.rel * std::max(std::fabs(x), std::fabs(y));
    if (!(std::isfinite(x) && std::isfinite(y) && std::fabs(x - y) <= bound)) {
      std::ostringstream os;
      os.precision(17);
      os << where << ": expected " << x << ", got " << y << " (|diff| " << std::fabs(x - y)
         << " > " << bound << ")";
      out.push_back(os.str());
    }
    return;
  }
  if (e.type() != a.type()) {
    out.push_back(where + ": expected " + e.type_name() + " " + e.dump() + ", got " + a.type_name() +
                  " " + a.dump());
    return;
  }
  if (e.is_array()) {
    if (e.size() != a.size()) {
      out.push_back(where + ": expected " + std::to_string(e.size()) + " elements, got " +
                    std::to_string(a.size()));
      return;
    }
    for (std::size_t i = 0; i < e.size(); ++i) {
      compare_into(e[i], a[i], rules, tol, where + "[" + std::to_string(i) + "]", limit, out);
    }
    return;
  }
  if (e.is_object()) {
    for (auto it = e.begin(); it != e.end(); ++it) {
      if (!a.contains(it.key())) {
        out.push_back(where + "." + it.key() + ": missing in the result");
      } else {
        const auto own = rules.by_key.find(it.key());
        compare_into(it.value(), a[it.key()], rules, own != rules.by_key.end() ? own->second : tol,
                     where + "." + it.key(), limit, out);
      }
    }
    for (auto it = a.begin(); it != a.end(); ++it) {
      if (!e.contains(it.key())) out.push_back(where + "." + it.key() + ": not in the golden file");
    }
    return;
  }
  if (e != a) out.push_back(where + ": expected " + e.dump() + ", got " + a.dump());
}

bool env_is_set(const char* name) {
  const char* v = std::getenv(name);
  return v != nullptr && *v != '\0' && std::string(v) != "0" && std::string(v) != "false";
}

nlohmann::json golden_document(const nlohmann::json& value, const Tolerances& tol) {
  return {{"tolerance", tol.to_json()}, {"value", value}};
}

}  // namespace

nlohmann::json Tolerances::to_json() const {
  nlohmann::json j = {{"abs", fallback.abs}, {"rel", fallback.rel}};
  for (const auto& [key, t] : by_key) j["by_key"][key] = {{"abs", t.abs}, {"rel", t.rel}};
  return j;
}

std::vector<std::string> compare_json(const nlohmann::json& expected, const nlohmann::json& actual,
                                      const Tolerances& tol, std::size_t limit) {
  std::vector<std::string> out;
  compare_into(expected, actual, tol, tol.fallback, "", limit, out);
  return out;
}

GoldenMode golden_mode_from_environment() {
  if (!env_is_set("UPDATE_GOLDEN")) return GoldenMode::kCheck;
  if (env_is_set("CI")) {
    throw std::runtime_error("UPDATE_GOLDEN=1 is refused under CI: goldens are updated by a "
                             "developer and reviewed, never rewritten by CI");
  }
  return GoldenMode::kUpdate;
}

GoldenOutcome check_golden_file(const std::string& path, const nlohmann::json& actual, const Tolerances& tol,
                                GoldenMode mode) {
  namespace fs = std::filesystem;
  const std::string received = path + ".received";
  nlohmann::json expected;
  bool have_golden = false;
  std::string problem;
  if (fs::exists(path)) {
    try {
      const nlohmann::json doc = read_json_file(path);
      expected = doc.at("value");
      // The tolerance is the test's; the file's copy is a record, and a different one (looser
      // or not) means the file was blessed under another test.
      if (doc.at("tolerance") != tol.to_json()) {
        problem = "golden file " + path + " records the tolerance " + doc.at("tolerance").dump() +
                  " but the test fixes " + tol.to_json().dump() +
                  ": tolerances live in the test code and a golden file cannot change them";
      } else {
        have_golden = true;
      }
    } catch (const std::exception& e) {
      problem = "unreadable golden file " + path + ": " + e.what();
    }
  } else {
    problem = "no golden file " + path;
  }

  std::vector<std::string> diffs;
  if (have_golden) diffs = compare_json(expected, actual, tol);
  std::error_code ec;
  if (have_golden && diffs.empty()) {
    fs::remove(received, ec);
    return {true, "matches " + path};
  }
  if (mode == GoldenMode::kUpdate) {
    fs::create_directories(fs::path(path).parent_path(), ec);
    write_file_atomic(path, dump_json(golden_document(actual, tol)));
    fs::remove(received, ec);
    return {true, "UPDATE_GOLDEN: rewrote " + path};
  }
  fs::create_directories(fs::path(path).parent_path(), ec);
  write_file_atomic(received, dump_json(golden_document(actual, tol)));
  std::ostringstream os;
  os << (problem.empty() ? "mismatch against " + path : problem) << "\n";
  for (const auto& d : diffs) os << "  " << d << "\n";
  os << "wrote the result to " << received
     << "\nif the change is intended: UPDATE_GOLDEN=1 ctest -L golden (then review the diff)";
  return {false, os.str()};
}

GoldenOutcome check_golden(const std::string& relative_path, const nlohmann::json& actual, const Tolerances& tol) {
  const char* env_dir = std::getenv("MINER_SOURCE_DIR");
  const std::string root = env_dir && *env_dir ? env_dir : MINER_SOURCE_DIR;
  return check_golden_file(root + "/golden/" + relative_path, actual, tol, golden_mode_from_environment());
}

}  // namespace miner::testing
