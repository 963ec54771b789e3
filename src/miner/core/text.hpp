#pragma once
/// \file
/// Small text helpers shared by the library and the CLI (C++17 has no std::string::ends_with).

#include <sstream>
#include <string>

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

}  // namespace miner
