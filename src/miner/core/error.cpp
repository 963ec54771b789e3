#include "miner/core/error.hpp"

#include <cmath>
#include <sstream>

namespace miner {

std::string printable_text(const std::string& text) {
  static const char* const kHex = "0123456789abcdef";
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if ((u < 0x20 && c != '\n' && c != '\t') || u == 0x7f) {
      out += "\\x";
      out += kHex[u >> 4];
      out += kHex[u & 15];
    } else {
      out += c;
    }
  }
  return out;
}

std::string format_point(const Eigen::Vector3d& p) {
  std::ostringstream os;
  os.precision(10);
  os << "(" << p.x() << ", " << p.y() << ", " << p.z() << ")";
  return os.str();
}

void require_finite(double v, const std::string& field) {
  if (!std::isfinite(v)) {
    std::ostringstream os;
    os << field << ": must be a finite number, got " << v;
    throw Error(os.str());
  }
}

void require_finite(const Eigen::Vector3d& v, const std::string& field) {
  for (int i = 0; i < 3; ++i) require_finite(v[i], field + "[" + std::to_string(i) + "]");
}

}  // namespace miner
