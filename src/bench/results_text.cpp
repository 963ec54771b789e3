#include "bench/results_text.hpp"

#include <cmath>
#include <cstdio>

namespace miner::bench {

std::string fixed(double v, int digits) {
  if (!std::isfinite(v)) return "—";
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

std::string git_commit() {
  std::string out;
  if (FILE* p = ::popen("git describe --always --dirty 2>/dev/null", "r")) {
    char buf[128];
    while (std::fgets(buf, sizeof buf, p)) out += buf;
    ::pclose(p);
  }
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
  return out.empty() ? "unknown" : out;
}

const PlannerSummary* find_summary(const FrontendBenchResult& r, const std::string& planner) {
  for (const auto& s : r.summaries)
    if (s.planner == planner) return &s;
  return nullptr;
}

}  // namespace miner::bench
