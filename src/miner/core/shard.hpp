#pragma once
/// \file
/// Jobs split across machines (REQ-REPORT-006): part i of N takes the items whose index is
/// i modulo N; a merge step joins parts 0..N-1. Shared by the front-end campaign and the
/// dataset generator.

#include <string>
#include <utility>
#include <vector>

#include "miner/core/json_io.hpp"

namespace miner {

/// "i/N" with 0 <= i < N -> (i, N); throws miner::Error otherwise (the --shard option).
std::pair<int, int> parse_shard(const std::string& text);

/// Throws miner::Error unless 0 <= index < count.
void require_shard(int index, int count);

/// `tags[p]` is part p's {"index": i, "count": N} and `names[p]` how to name it in a
/// message. Throws miner::Error naming the part at fault unless the tags are parts
/// 0..N-1 of one split, each exactly once ("<job> has N parts, got M" when some are
/// missing).
void require_complete_parts(const std::vector<Json>& tags, const std::vector<std::string>& names,
                            const std::string& job);

}  // namespace miner
