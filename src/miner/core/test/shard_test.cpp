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
                    Contains("b: part 0/2 appears twice (also a)"));
  // Eighteenth campaign F26: a copied part beside the whole split was only "has 2 parts, got 3".
  CHECK_THROWS_WITH(miner::require_complete_parts({tag(0, 2), tag(1, 2), tag(1, 2)}, {"a0", "a1", "a1copy"}, "dataset merge"),
                    Contains("a1copy: part 1/2 appears twice (also a1)"));
  // Fifth campaign: "splits dataset merge: the dataset differently".
  CHECK_THROWS_WITH(miner::require_complete_parts({tag(0, 2), tag(1, 3)}, {"a", "b"}, "dataset merge: the dataset"),
                    Contains("b: is part 1 of 3, but a is a part of 2: the parts come from different splits"));
  // Session 23 review: an index outside its own count was called "different splits".
  CHECK_THROWS_WITH(miner::require_complete_parts({tag(0, 2), tag(5, 2)}, {"a", "b"}, "merge: the campaign"),
                    Contains("b: says it is part 5 of 2: a part's index must lie in [0, 2)"));
  CHECK(miner::parse_shard("1/4") == std::pair<int, int>{1, 4});
  CHECK_THROWS_AS(miner::parse_shard("4/4"), miner::Error);
}

TEST_CASE("Part tags are checked against their names and their fields' types before they are read",
          "[REQ-LIB-003][REQ-CORE-004]") {
  // Tenth campaign L19: fewer names than tags read past the names (a crash); L18: a string
  // "count" escaped as the JSON library's type_error.
  const Json part{{"index", 0}, {"count", 2}};
  CHECK_THROWS_WITH(miner::require_complete_parts({part, part}, {"only-one"}, "job"), Contains("2 part tags but 1 names"));
  CHECK_THROWS_WITH(miner::require_complete_parts({Json{{"index", "0"}, {"count", 1}}}, {"a.json"}, "job"),
                    Contains("a.json") && Contains("integer \"index\""));
  CHECK_THROWS_WITH(miner::require_complete_parts({Json{{"index", 0}}}, {"a.json"}, "job"), Contains("integer \"count\""));
  CHECK_NOTHROW(miner::require_complete_parts({part, Json{{"index", 1}, {"count", 2}}}, {"a", "b"}, "job"));
}

TEST_CASE("A shard is two decimal numbers and one slash: blanks, signs and other bases are refused",
          "[REQ-LIB-003][REQ-REPORT-006]") {
  // Tenth campaign recheck: std::stoi skipped a leading blank and took a sign.
  CHECK(miner::parse_shard("0/2") == std::pair<int, int>{0, 2});
  CHECK(miner::parse_shard("11/12") == std::pair<int, int>{11, 12});
  for (const char* bad : {" 0/2", "0/2 ", "+0/2", "0/+2", "-0/2", "0x1/2", "0/2/3", "/2", "0/", "0 / 2", "0/1e1", ""})
    CHECK_THROWS_WITH(miner::parse_shard(bad), Contains("--shard: expected i/N"));
}
