#include <catch2/catch.hpp>

#include "miner/core/error.hpp"
#include "miner/core/shard.hpp"

using Catch::Matchers::Contains;
using miner::Json;

TEST_CASE("Parts of one split join: others are refused naming the part in plain words", "[REQ-REPORT-006]") {
  const auto tag = [](int i, int n) { return Json{{"index", i}, {"count", n}}; };
  CHECK_NOTHROW(miner::require_complete_parts({tag(1, 2), tag(0, 2)}, {"b", "a"}, "merge: the campaign"));
  CHECK_THROWS_WITH(miner::require_complete_parts({tag(0, 3), tag(1, 3)}, {"a", "b"}, "merge: the campaign"),
                    Contains("merge: the campaign has 3 parts, got 2"));
  CHECK_THROWS_WITH(miner::require_complete_parts({tag(0, 2), tag(0, 2)}, {"a", "b"}, "merge: the campaign"),
                    Contains("b: part 0/2 appears twice"));
  // Fifth campaign: "splits dataset merge: the dataset differently".
  CHECK_THROWS_WITH(miner::require_complete_parts({tag(0, 2), tag(1, 3)}, {"a", "b"}, "dataset merge: the dataset"),
                    Contains("b: is part 1 of 3, but a is a part of 2: the parts come from different splits"));
  // Session 23 review: an index outside its own count was called "different splits".
  CHECK_THROWS_WITH(miner::require_complete_parts({tag(0, 2), tag(5, 2)}, {"a", "b"}, "merge: the campaign"),
                    Contains("b: says it is part 5 of 2: a part's index must lie in [0, 2)"));
  CHECK(miner::parse_shard("1/4") == std::pair<int, int>{1, 4});
  CHECK_THROWS_AS(miner::parse_shard("4/4"), miner::Error);
}
