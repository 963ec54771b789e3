#pragma once
/// \file
/// Small text helpers shared by the library and the CLI (C++17 has no std::string::ends_with).

#include <algorithm>
#include <sstream>
#include <string>
#include <vector>

namespace miner {

/// Whether `text` ends in `suffix` (case-sensitive: ".BT" is not ".bt").
inline bool ends_with(const std::string& text, const std::string& suffix) {
  return text.size() >= suffix.size() && text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

/// A number as a message shows it: the shortest of %g's six significant digits ("0.2", "1e+09",
/// "360"), never std::to_string's fixed six decimals ("0.000000" for 1e-9).
inline std::string short_number(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

/// Rows of cells as text columns, left-aligned, each column as wide as its widest cell and two
/// spaces apart, so no value runs into the next however long it is (issue 20, sixth campaign
/// U14: a fixed width of 7 printed M = 1000000 beside 209888 as "1000000209888").
inline std::string aligned_columns(const std::vector<std::vector<std::string>>& rows) {
  std::vector<std::size_t> width;
  for (const auto& row : rows)
    for (std::size_t c = 0; c < row.size(); ++c) {
      if (width.size() <= c) width.push_back(0);
      width[c] = std::max(width[c], row[c].size());
    }
  std::string out;
  for (const auto& row : rows) {
    std::string line;
    for (std::size_t c = 0; c < row.size(); ++c) {
      line += row[c];
      if (c + 1 < row.size()) line += std::string(width[c] - row[c].size() + 2, ' ');
    }
    out += line + "\n";
  }
  return out;
}

}  // namespace miner
