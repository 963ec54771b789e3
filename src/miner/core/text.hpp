#pragma once
/// \file
/// Small text helpers shared by the library and the CLI (C++17 has no std::string::ends_with).

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
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

/// A value as a reader would check it: the shortest decimal that reads back as the same double
/// (399.9999999, not short_number's 400), for the offending value and the ends of a range in a
/// message (sixteenth campaign F3: "must be in [400, 10000], got 400").
/// Plain notation from 1e-4 to below 1e6 ("10", "0.0075", "399.9999999"), %e's beyond ("1e-09", "1e+06").
inline std::string exact_number(double v) {
  if (!std::isfinite(v)) return short_number(v);
  char text[48];
  int digits = 1;
  for (; digits < 17; ++digits) {
    std::snprintf(text, sizeof text, "%.*e", digits - 1, v);
    if (std::strtod(text, nullptr) == v) break;
  }
  std::snprintf(text, sizeof text, "%.*e", digits - 1, v);
  const char* e = std::strchr(text, 'e');
  const int exponent = e ? std::atoi(e + 1) : 0;
  if (exponent < -4 || exponent >= 6) return text;
  std::snprintf(text, sizeof text, "%.*f", std::max(digits - 1 - exponent, 0), v);
  return text;
}

/// A name a file gives (a scenario's, a vehicle's): shown in summaries and used in folder names,
/// so one plain, visible word. kPlainNameRule says what is_plain_name accepts.
inline constexpr const char* kPlainNameRule = "must be 1 to 128 letters, digits or . _ + - not starting with '.'";
inline bool is_plain_name(const std::string& name) {
  return !name.empty() && name.size() <= 128 && name[0] != '.' &&
         name.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789._+-") == std::string::npos;
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
