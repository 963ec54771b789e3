// libFuzzer target: `miner bench merge` inputs (REQ-REPORT-006): the input is one or two
// campaign shard documents (split at the first NUL byte), joined as shards of one campaign.
#include <vector>

#include "bench/frontend_bench.hpp"
#include "fuzz_target.hpp"
#include "miner/core/json_io.hpp"

namespace {
void parse(const std::string& text) {
  std::vector<nlohmann::json> parts;
  const std::size_t nul = text.find('\0');
  parts.push_back(miner::parse_json(text.substr(0, nul), "fuzz shard 0"));
  if (nul != std::string::npos) parts.push_back(miner::parse_json(text.substr(nul + 1), "fuzz shard 1"));
  (void)miner::bench::merge_frontend_shards(parts);
}
}  // namespace

MINER_FUZZ_TARGET(parse)
