#include "miner/core/shard.hpp"

#include <map>

#include <exception>

#include "miner/core/error.hpp"

namespace miner {

std::pair<int, int> parse_shard(const std::string& text) {
  const auto slash = text.find('/');
  // Decimal digits on both sides of one slash, nothing else: std::stoi alone skipped leading
  // blanks and took a sign (tenth campaign recheck: " 0/2" and "+0/2" were read as 0/2).
  const bool plain = slash != std::string::npos && slash > 0 && slash + 1 < text.size() &&
                     text.find_first_not_of("0123456789/") == std::string::npos &&
                     text.find('/', slash + 1) == std::string::npos;
  try {
    if (plain) {
      std::size_t a = 0, b = 0;
      const int i = std::stoi(text.substr(0, slash), &a);
      const int n = std::stoi(text.substr(slash + 1), &b);
      if (a == slash && b == text.size() - slash - 1 && n >= 1 && i >= 0 && i < n) return {i, n};
    }
  } catch (const std::exception&) {
  }
  throw Error("--shard: expected i/N with 0 <= i < N (e.g. 0/4), got \"" + text + "\"");
}

void require_shard(int index, int count) {
  if (count < 1 || index < 0 || index >= count) throw Error("--shard: needs 0 <= i < N");
}

void require_complete_parts(const std::vector<Json>& tags, const std::vector<std::string>& names,
                            const std::string& job) {
  if (tags.empty()) throw Error(job + ": no parts given");
  // One name per tag, integer fields (tenth campaign L19: fewer names read past the end; L18: a
  // string "count" escaped as the JSON library's type_error).
  if (names.size() != tags.size())
    throw Error(job + ": " + std::to_string(tags.size()) + " part tags but " + std::to_string(names.size()) + " names");
  for (std::size_t p = 0; p < tags.size(); ++p)
    for (const char* key : {"index", "count"})
      if (!tags[p].is_object() || !tags[p].contains(key) || !tags[p].at(key).is_number_integer())
        throw Error(names[p] + ": its part tag needs an integer \"" + key + "\"");
  const int n = tags.front().at("count").get<int>();
  // A part given twice is named before the count is judged (eighteenth campaign F26: a copied
  // part folder was reported only as "has 2 parts, got 3").
  std::map<int, std::size_t> first_at;  // a part's index -> where it was first given (n may be any count)
  for (std::size_t p = 0; p < tags.size(); ++p) {
    const int index = tags[p].at("index").get<int>();
    if (tags[p].at("count").get<int>() != n || index < 0 || index >= n) continue;  // judged below
    if (const auto [it, fresh] = first_at.emplace(index, p); !fresh)
      throw Error(names[p] + ": part " + std::to_string(index) + "/" + std::to_string(n) + " appears twice (also " +
                  names[it->second] + ")");
  }
  if (static_cast<int>(tags.size()) != n)
    throw Error(job + " has " + std::to_string(n) + " parts, got " + std::to_string(tags.size()));
  // Duplicates are named above; here the parts that are not of this split.
  for (std::size_t p = 0; p < tags.size(); ++p) {
    const int index = tags[p].at("index").get<int>();
    const int count = tags[p].at("count").get<int>();
    // A part numbered outside its own count was edited, not drawn from another split.
    if (index < 0 || index >= count)
      throw Error(names[p] + ": says it is part " + std::to_string(index) + " of " + std::to_string(count) +
                  ": a part's index must lie in [0, " + std::to_string(count) + ")");
    if (count != n)
      // Plain words (fifth campaign: "splits dataset merge: the dataset differently").
      throw Error(names[p] + ": is part " + std::to_string(index) + " of " + std::to_string(tags[p].at("count").get<int>()) +
                  ", but " + names.front() + " is a part of " + std::to_string(n) + ": the parts come from different splits");
  }
}

}  // namespace miner
