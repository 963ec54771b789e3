#include "bench/backend_bench.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <iomanip>
#include <limits>
#include <map>
#include <ostream>
#include <sstream>

#include "miner/core/error.hpp"
#include "miner/core/rng.hpp"
#include "miner/core/text.hpp"
#include "miner/traj/baselines.hpp"
#include "miner/traj/minco.hpp"
#include "miner/traj/trapezoidal_allocation.hpp"

namespace miner::bench {

namespace {

using Clock = std::chrono::steady_clock;

/// The Table II baselines by their names in the output ("minco" is timed separately,
/// through a reused MincoSolver).
using Baseline = Eigen::MatrixX3d (*)(const traj::MincoProblem&);
const std::map<std::string, Baseline>& baselines() {
  static const std::map<std::string, Baseline> table{{"dense-lu", traj::solve_dense_lu},
                                                      {"closed-form", traj::solve_closed_form},
                                                      {"kkt-qp", traj::solve_kkt_qp}};
  return table;
}

/// Waypoints of a 100 m map (paper Sec. V-B), durations by trapezoidal allocation.
traj::MincoProblem bench_problem(int order, int segments, std::uint64_t seed) {
  Rng rng(seed, static_cast<std::uint64_t>(segments * 10 + order));
  Eigen::MatrixX3d pts(segments + 1, 3);
  for (int i = 0; i <= segments; ++i) pts.row(i) << rng.uniform(0, 100), rng.uniform(0, 100), rng.uniform(0, 40);
  return traj::rest_to_rest(order, pts, traj::trapezoidal_allocation(pts, traj::Limits{2.0, 1.0}));
}

/// Times `solve` in `samples` batches sized to fill the budget; returns (median, min) us.
std::pair<double, double> time_solves(const std::function<void()>& solve, const BackendBenchOptions& o,
                                      int& samples, long& reps) {
  const auto t0 = Clock::now();
  solve();  // warm-up, and a first estimate
  const double first = std::chrono::duration<double>(Clock::now() - t0).count();
  const double per_sample = o.budget_s / o.samples;
  reps = std::max(1L, static_cast<long>(per_sample / std::max(first, 1e-9)));
  samples = first > per_sample ? std::max(1, static_cast<int>(o.budget_s / first)) : o.samples;
  samples = std::max(samples, 3);
  std::vector<double> us;
  for (int k = 0; k < samples; ++k) {
    const auto a = Clock::now();
    for (long r = 0; r < reps; ++r) solve();
    us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - a).count() / static_cast<double>(reps));
  }
  std::sort(us.begin(), us.end());
  return {us[us.size() / 2], us.front()};
}

/// Times every method of `o` on `p` (MINCO through a reused MincoSolver) and appends one
/// record per method; the O(M^3) baselines are skipped above o.max_dense_segments.
void time_methods(const traj::MincoProblem& p, const BackendBenchOptions& o, std::vector<BackendRecord>& records) {
  const int s = p.order;
  const int M = static_cast<int>(p.durations.size());
  traj::MincoSolver solver;
  traj::PolynomialTrajectory out;
  solver.solve(p, out);
  const Eigen::MatrixX3d reference = out.coefficients();
  double minco_us = 0.0;
  for (const auto& method : o.methods) {
    BackendRecord r;
    r.method = method;
    r.order = s;
    r.segments = M;
    if (method != "minco" && M > o.max_dense_segments) {
      r.skipped = true;
      records.push_back(r);
      continue;
    }
    Eigen::MatrixX3d c;
    std::function<void()> solve;
    if (method == "minco") {
      solve = [&] { solver.solve(p, out); };
    } else {
      const Baseline baseline = baselines().at(method);
      solve = [&, baseline] { c = baseline(p); };
    }
    const auto [median, fastest] = time_solves(solve, o, r.samples, r.reps_per_sample);
    r.us_per_solve = median;
    r.min_us = fastest;
    if (method == "minco") {
      minco_us = median;
      c = out.coefficients();
    }
    r.max_rel_diff = (c - reference).norm() / reference.norm();
    // Without MINCO timed in the same run there is no ratio (issue 20: 0.0 was printed).
    r.ratio_to_minco = minco_us > 0.0 ? median / minco_us : std::numeric_limits<double>::quiet_NaN();
    records.push_back(r);
  }
}

}  // namespace

namespace {
/// `on_path`: the run times one path (run_backend_on_path), whose M is the path's, not --segments.
void validate(const BackendBenchOptions& o, bool on_path) {
  for (const auto& m : o.methods) {
    if (m != "minco" && baselines().count(m) == 0) {
      throw Error("--methods: unknown method \"" + m + "\" (known: minco, dense-lu, closed-form, kkt-qp)");
    }
  }
  for (int s : o.orders) {
    if (s != 3 && s != 4) throw Error("--orders: must be 3 or 4, got " + std::to_string(s));
  }
  for (int m : o.segments) {
    if (m < 1) throw Error("--segments: must be at least 1, got " + std::to_string(m));
  }
  if (!(o.budget_s > 0.0) || o.samples < 1) throw Error("--budget and --samples: must be positive");
  // A baseline that --max-dense-segments skips at every M would be listed and never run
  // (issue 20, fourth campaign: dense-lu with --max-dense-segments 0 was all "skipped").
  const int smallest = o.segments.empty() ? 0 : *std::min_element(o.segments.begin(), o.segments.end());
  for (const auto& m : o.methods)
    if (!on_path && m != "minco" && !o.segments.empty() && smallest > o.max_dense_segments)
      throw Error("--methods " + m + ": --max-dense-segments " + std::to_string(o.max_dense_segments) +
                      " skips it at every --segments value (the smallest is " + std::to_string(smallest) + ")",
                  ExitCode::kUsage);
  // Bounded work: the budget is per (method, order, M), so the whole run is their product
  // (issue 20, fourth campaign: --budget 3600 ran an hour per configuration, unbounded in all).
  const std::size_t segment_counts = on_path ? 1 : o.segments.size();
  const double total = o.budget_s * static_cast<double>(o.methods.size() * o.orders.size() * segment_counts);
  if (total > kMaxBackendTotalSeconds) {
    char text[160];
    std::snprintf(text, sizeof text, "%g s x %zu methods x %zu orders x %zu segment counts = %g s, over the %g s bound",
                  o.budget_s, o.methods.size(), o.orders.size(), segment_counts, total, kMaxBackendTotalSeconds);
    throw Error(std::string("--budget: ") + text + " (lower --budget or list fewer configurations)", ExitCode::kUsage);
  }
}
}  // namespace

std::vector<BackendRecord> run_backend_bench(const BackendBenchOptions& o) {
  validate(o, false);

  std::vector<BackendRecord> records;
  for (int s : o.orders)
    for (int M : o.segments) time_methods(bench_problem(s, M, o.seed), o, records);
  return records;
}

std::vector<BackendRecord> run_backend_on_path(const Eigen::MatrixX3d& points, const traj::Limits& limits,
                                               const BackendBenchOptions& o) {
  validate(o, true);
  if (points.rows() < 2) throw Error("bench backend: a path needs at least 2 points");
  std::vector<BackendRecord> records;
  for (int s : o.orders)
    time_methods(traj::rest_to_rest(s, points, traj::trapezoidal_allocation(points, limits)), o, records);
  return records;
}

nlohmann::json to_json(const std::vector<BackendRecord>& records) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& r : records) {
    nlohmann::json j = {{"method", r.method}, {"order", r.order}, {"segments", r.segments}, {"skipped", r.skipped}};
    if (r.skipped) {
      j["us_per_solve"] = nullptr;
    } else {
      j.update({{"us_per_solve", r.us_per_solve}, {"min_us", r.min_us}, {"samples", r.samples},
                {"reps_per_sample", r.reps_per_sample},
                {"ratio_to_minco", std::isnan(r.ratio_to_minco) ? nlohmann::json(nullptr) : nlohmann::json(r.ratio_to_minco)},
                {"max_rel_diff", r.max_rel_diff}});
    }
    out.push_back(j);
  }
  return out;
}

void print_table(const std::vector<BackendRecord>& records, std::ostream& out) {
  std::vector<std::string> methods;
  std::map<std::pair<int, int>, std::map<std::string, const BackendRecord*>> rows;
  for (const auto& r : records) {
    if (std::find(methods.begin(), methods.end(), r.method) == methods.end()) methods.push_back(r.method);
    rows[{r.order, r.segments}][r.method] = &r;
  }
  out << "microseconds per solve (median), ratio to MINCO in brackets\n";
  std::vector<std::vector<std::string>> table{{"s", "M"}};
  for (const auto& m : methods) table.front().push_back(m);
  for (const auto& [key, by_method] : rows) {
    std::vector<std::string> line{std::to_string(key.first), std::to_string(key.second)};
    for (const auto& m : methods) {
      std::ostringstream cell;
      const auto it = by_method.find(m);
      if (it == by_method.end() || it->second->skipped) {
        cell << "skipped";
      } else {
        cell << std::fixed << std::setprecision(it->second->us_per_solve < 100 ? 2 : 0) << it->second->us_per_solve;
        if (m != "minco" && !std::isnan(it->second->ratio_to_minco))
          cell << " (" << std::setprecision(1) << it->second->ratio_to_minco << "x)";
      }
      line.push_back(cell.str());
    }
    table.push_back(std::move(line));
  }
  out << aligned_columns(table);
}

}  // namespace miner::bench
