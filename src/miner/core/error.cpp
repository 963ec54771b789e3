#include "miner/core/error.hpp"

#include <cmath>
#include <sstream>

namespace miner {

namespace {
/// The length of the well-formed UTF-8 sequence at text[i] (RFC 3629: no overlong form, no
/// surrogate, nothing above U+10FFFF), or 0 when the bytes there are not one.
std::size_t utf8_sequence_length(const std::string& text, std::size_t i) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char lead = byte(i);
  std::size_t length = 0;
  unsigned char lo = 0x80, hi = 0xbf;  // the second byte's range
  if (lead >= 0xc2 && lead <= 0xdf) {
    length = 2;
  } else if (lead >= 0xe0 && lead <= 0xef) {
    length = 3;
    if (lead == 0xe0) lo = 0xa0;  // overlong
    if (lead == 0xed) hi = 0x9f;  // surrogates
  } else if (lead >= 0xf0 && lead <= 0xf4) {
    length = 4;
    if (lead == 0xf0) lo = 0x90;  // overlong
    if (lead == 0xf4) hi = 0x8f;  // above U+10FFFF
  } else {
    return 0;
  }
  if (i + length > text.size()) return 0;
  if (byte(i + 1) < lo || byte(i + 1) > hi) return 0;
  for (std::size_t k = 2; k < length; ++k)
    if (byte(i + k) < 0x80 || byte(i + k) > 0xbf) return 0;
  return length;
}
}  // namespace

std::string printable_text(const std::string& text) {
  static const char* const kHex = "0123456789abcdef";
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto u = static_cast<unsigned char>(text[i]);
    if (u >= 0x80) {
      // Well-formed UTF-8 is the user's text and stays; any other high byte is shown as \xNN, so
      // the terminal never receives a broken sequence (issue 20, sixth campaign U5).
      if (const std::size_t length = utf8_sequence_length(text, i); length > 0) {
        out.append(text, i, length);
        i += length - 1;
        continue;
      }
    }
    if ((u < 0x20 && text[i] != '\n' && text[i] != '\t') || u == 0x7f || u >= 0x80) {
      out += "\\x";
      out += kHex[u >> 4];
      out += kHex[u & 15];
    } else {
      out += text[i];
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
