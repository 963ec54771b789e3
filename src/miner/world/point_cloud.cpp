#include "miner/world/point_cloud.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cctype>
#include <cstring>
#include <limits>
#include <map>
#include <sstream>
#include <tuple>

#include <octomap/OcTree.h>

#include "miner/core/error.hpp"
#include "miner/core/text.hpp"
#include "miner/core/json_io.hpp"
#include "miner/core/sha256.hpp"
#include "miner/world/map.hpp"
#include "miner/world/octree_leaves.hpp"

namespace miner::world {

namespace {

[[noreturn]] void fail(const std::string& origin, const std::string& what) { throw Error(origin + ": " + what); }

/// Header lines up to and including `last` (e.g. "end_header", "DATA ..."); returns the offset
/// of the first data byte.
struct Lines {
  const std::string& bytes;
  const std::string& origin;
  std::size_t pos = 0;
  std::string next() {
    constexpr std::size_t kMaxHeaderLine = 4096;
    if (pos >= bytes.size()) fail(origin, "the header ends before its last line");
    const std::size_t end = bytes.find('\n', pos);
    const std::size_t stop = end == std::string::npos ? bytes.size() : end;
    if (stop - pos > kMaxHeaderLine) fail(origin, "a header line is longer than 4096 bytes");
    std::string line = bytes.substr(pos, stop - pos);
    pos = end == std::string::npos ? bytes.size() : end + 1;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return line;
  }
};

std::vector<std::string> words(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> w;
  for (std::string s; in >> s;) w.push_back(s);
  return w;
}

std::size_t count_of(const std::string& text, const std::string& what, const std::string& origin) {
  if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos)
    fail(origin, what + " \"" + text + "\" is not a count");
  // A count of many digits is too large, not malformed (eighteenth campaign F15); leading zeros
  // do not count (nineteenth campaign F8: "0...02 exceeds").
  const std::string digits = text.find_first_not_of('0') == std::string::npos ? "0" : text.substr(text.find_first_not_of('0'));
  if (digits.size() > 12 || std::stoull(digits) > kMaxCloudPoints)
    fail(origin, what + " " + (digits.size() > 24 ? digits.substr(0, 24) + "..." : digits) + " exceeds the " +
                     std::to_string(kMaxCloudPoints) + " points a cloud may hold");
  return std::stoull(digits);
}

/// One scalar field of a binary record: byte offset, size, kind ('f' float, 'i' signed, 'u' unsigned).
struct Field {
  std::string name;
  std::size_t offset = 0;
  std::size_t size = 0;
  char kind = 'f';
};

double read_scalar(const char* p, const Field& f, bool swap) {
  unsigned char b[8];
  std::memcpy(b, p, f.size);
  if (swap) std::reverse(b, b + f.size);
  switch (f.kind) {
    case 'f':
      if (f.size == 4) {
        float v;
        std::memcpy(&v, b, 4);
        return v;
      } else {
        double v;
        std::memcpy(&v, b, 8);
        return v;
      }
    case 'i': {
      std::int64_t v = 0;
      if (f.size == 1) { std::int8_t t; std::memcpy(&t, b, 1); v = t; }
      if (f.size == 2) { std::int16_t t; std::memcpy(&t, b, 2); v = t; }
      if (f.size == 4) { std::int32_t t; std::memcpy(&t, b, 4); v = t; }
      return static_cast<double>(v);
    }
    default: {
      std::uint64_t v = 0;
      if (f.size == 1) { std::uint8_t t; std::memcpy(&t, b, 1); v = t; }
      if (f.size == 2) { std::uint16_t t; std::memcpy(&t, b, 2); v = t; }
      if (f.size == 4) { std::uint32_t t; std::memcpy(&t, b, 4); v = t; }
      return static_cast<double>(v);
    }
  }
}

/// A decimal number, or nan / inf (organised clouds mark missing returns so; such points are
/// skipped and counted). strtod alone also reads hexadecimal floats ("0x1p3" is 8), which no
/// point cloud writer emits (issue 20, third campaign).
bool decimal_or_special(const std::string& token) {
  std::string lower;
  for (char c : token) lower += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  const std::string bare = !lower.empty() && (lower[0] == '-' || lower[0] == '+') ? lower.substr(1) : lower;
  if (bare == "nan" || bare == "inf" || bare == "infinity") return true;
  return token.find_first_not_of("0123456789+-.eE") == std::string::npos;
}

/// A cloud text's number: a decimal, or nan/inf (a missing return); not hex, and not written
/// beyond the largest double, an error in the file rather than a missing return (fifth
/// campaign: "1e400" was skipped as non-finite). Sets `v`; returns why `token` is none ("is not
/// a number", kBeyondDouble), empty when it is one.
constexpr const char* kBeyondDouble = "is beyond the largest double";
std::string number_problem(const std::string& token, double& v) {
  char* end = nullptr;
  v = std::strtod(token.c_str(), &end);
  if (end == token.c_str() || *end != '\0' || !decimal_or_special(token)) return "is not a number";
  if (std::isinf(v) && token.find_first_of("0123456789") != std::string::npos) return kBeyondDouble;
  return "";
}

/// Why the ASCII value `token` is no value of field `f`'s type, or "" when it is one: a float
/// field takes a number (number_problem) within its range, an integer field a whole number
/// within its size (eighteenth campaign F15: a uchar "abc" or 300 was never read).
std::string ascii_value_problem(const std::string& token, const Field& f) {
  if (f.kind == 'f') {
    double v = 0.0;
    if (std::string why = number_problem(token, v); !why.empty()) return why;
    if (f.size == 4 && std::isfinite(v) && std::abs(v) > static_cast<double>(std::numeric_limits<float>::max()))
      return "is beyond the range of a 4-byte float";
    return "";
  }
  const bool negative = !token.empty() && token[0] == '-';
  const std::string digits = !token.empty() && (token[0] == '-' || token[0] == '+') ? token.substr(1) : token;
  if (digits.empty() || digits.size() > 20 || digits.find_first_not_of("0123456789") != std::string::npos)
    return "is not a whole number";
  const long double v = std::strtold(digits.c_str(), nullptr) * (negative ? -1.0L : 1.0L);
  const long double bits = 8.0L * static_cast<long double>(f.size);
  const long double lo = f.kind == 'u' ? 0.0L : -std::pow(2.0L, bits - 1), hi = std::pow(2.0L, f.kind == 'u' ? bits : bits - 1) - 1;
  if (v < lo || v > hi) return "is outside the field's range";
  return "";
}

double parse_number(const std::string& token, const std::string& origin, std::size_t point) {
  double v = 0.0;
  if (const std::string why = number_problem(token, v); !why.empty()) {
    std::ostringstream os;
    os << "point " << point << ": " << (why == kBeyondDouble ? "the number " + token : "\"" + token + "\"") << " " << why;
    fail(origin, os.str());
  }
  return v;
}

void add_point(PointCloud& cloud, const Eigen::Vector3d& p) {
  if (p.allFinite()) cloud.points.push_back(p);
  else ++cloud.skipped;
}

/// Reads `n` records of `fields` (x, y, z at xyz[0..2]) from ASCII lines or binary bytes;
/// returns the offset just after them.
std::size_t read_records(PointCloud& cloud, const std::string& bytes, std::size_t pos, std::size_t n,
                  const std::vector<Field>& fields, const std::array<int, 3>& xyz, bool ascii, bool swap,
                  std::size_t stride, const std::string& origin, bool exact_end) {
  if (ascii) {
    std::size_t line_start = pos;
    for (std::size_t i = 0; i < n; ++i) {
      if (line_start >= bytes.size()) {
        std::ostringstream os;
        os << "data ends after " << i << " of " << n << " points";
        fail(origin, os.str());
      }
      std::size_t end = bytes.find('\n', line_start);
      if (end == std::string::npos) end = bytes.size();
      const std::vector<std::string> w = words(bytes.substr(line_start, end - line_start));
      line_start = end + 1;
      if (w.empty()) {
        --i;
        continue;
      }
      if (w.size() != fields.size()) {
        std::ostringstream os;
        os << "point " << i << " has " << w.size() << " values, the header declares " << fields.size();
        fail(origin, os.str());
      }
      Eigen::Vector3d p;
      for (int a = 0; a < 3; ++a) {
        const Field& f = fields[static_cast<std::size_t>(xyz[static_cast<std::size_t>(a)])];
        p[a] = parse_number(w[static_cast<std::size_t>(xyz[static_cast<std::size_t>(a)])], origin, i);
        // A value its declared type cannot hold (1e39 in a float) is no point of the cloud: the
        // binary encoding could not carry it (eleventh campaign I3).
        if (f.kind == 'f' && f.size == 4 && std::isfinite(p[a]) &&
            std::abs(p[a]) > static_cast<double>(std::numeric_limits<float>::max())) {
          std::ostringstream os;
          os << "point " << i << ": " << w[static_cast<std::size_t>(xyz[static_cast<std::size_t>(a)])] << " is beyond the range of its "
             << "4-byte float field \"" << f.name << "\"";
          fail(origin, os.str());
        }
      }
      // Every other property is read by its type too.
      for (std::size_t j = 0; j < fields.size(); ++j) {
        if (static_cast<int>(j) == xyz[0] || static_cast<int>(j) == xyz[1] || static_cast<int>(j) == xyz[2]) continue;
        if (const std::string why = ascii_value_problem(w[j], fields[j]); !why.empty()) {
          std::ostringstream os;
          os << "point " << i << ": the value \"" << w[j] << "\" of \"" << fields[j].name << "\" ("
             << (fields[j].kind == 'f' ? "float" : fields[j].kind == 'u' ? "unsigned" : "signed") << ", "
             << fields[j].size << " bytes) " << why;
          fail(origin, os.str());
        }
      }
      add_point(cloud, p);
    }
    // Nothing but blank space may follow the declared points (issue 20: extra lines were dropped).
    if (exact_end && line_start < bytes.size() &&
        bytes.find_first_not_of(" \t\r\n", line_start) != std::string::npos) {
      std::ostringstream os;
      os << "data continues after the " << n << " points the header declares";
      fail(origin, os.str());
    }
    return std::min(line_start, bytes.size());
  }
  if ((bytes.size() - pos) / stride < n) {
    std::ostringstream os;
    os << "the header declares " << n << " points of " << stride << " bytes, but only " << bytes.size() - pos
       << " data bytes follow";
    fail(origin, os.str());
  }
  if (exact_end && bytes.size() - pos != n * stride) {
    std::ostringstream os;
    os << bytes.size() - pos - n * stride << " bytes follow the " << n << " points of " << stride
       << " bytes the header declares";
    fail(origin, os.str());
  }
  cloud.points.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const char* rec = bytes.data() + pos + i * stride;
    add_point(cloud, {read_scalar(rec + fields[xyz[0]].offset, fields[xyz[0]], swap),
                      read_scalar(rec + fields[xyz[1]].offset, fields[xyz[1]], swap),
                      read_scalar(rec + fields[xyz[2]].offset, fields[xyz[2]], swap)});
  }
  return pos + n * stride;
}

/// A PLY element after the vertices (faces, edges): read only to check that the file holds
/// exactly what its header declares (issue 20: a face count was never checked).
struct PlyProperty {
  bool list = false;
  Field count;  ///< lists: the type of the item count
  Field item;   ///< scalars: the value; lists: each item
};
struct PlyElement {
  std::string name;
  std::size_t count = 0;
  std::vector<PlyProperty> properties;
};

/// The PLY scalar type named `type` (size 0 if unknown).
Field ply_type(const std::string& type) {
  static const std::vector<std::pair<std::vector<std::string>, std::pair<std::size_t, char>>> kTypes = {
      {{"char", "int8"}, {1, 'i'}},    {{"uchar", "uint8"}, {1, 'u'}},  {{"short", "int16"}, {2, 'i'}},
      {{"ushort", "uint16"}, {2, 'u'}}, {{"int", "int32"}, {4, 'i'}},   {{"uint", "uint32"}, {4, 'u'}},
      {{"float", "float32"}, {4, 'f'}}, {{"double", "float64"}, {8, 'f'}}};
  Field f;
  for (const auto& [names, t] : kTypes)
    if (std::find(names.begin(), names.end(), type) != names.end()) std::tie(f.size, f.kind) = t;
  return f;
}

/// Walks the records of `elements` from `pos`; the file must end with the last of them.
void check_later_elements(const std::string& bytes, std::size_t pos, const std::vector<PlyElement>& elements,
                          bool ascii, bool swap, const std::string& origin) {
  const auto record_fail = [&](const PlyElement& e, std::size_t i, const std::string& what) {
    std::ostringstream os;
    os << "element " << e.name << " " << i << " of " << e.count << ": " << what;
    fail(origin, os.str());
  };
  for (const PlyElement& e : elements) {
    for (std::size_t i = 0; i < e.count; ++i) {
      if (ascii) {
        std::vector<std::string> w;
        while (w.empty()) {
          if (pos >= bytes.size()) record_fail(e, i, "the data ends before it");
          std::size_t end = bytes.find('\n', pos);
          if (end == std::string::npos) end = bytes.size();
          w = words(bytes.substr(pos, end - pos));
          pos = end + 1;
        }
        std::size_t k = 0;
        for (const PlyProperty& p : e.properties) {
          std::size_t items = 1;
          if (p.list) {
            if (k >= w.size() || w[k].find_first_not_of("0123456789") != std::string::npos || w[k].size() > 9)
              record_fail(e, i, "a list does not start with its item count");
            items = std::stoull(w[k++]);
          }
          for (std::size_t j = 0; j < items; ++j, ++k)
            if (k >= w.size() || !decimal_or_special(w[k])) record_fail(e, i, "fewer or other values than the header declares");
        }
        if (k != w.size()) record_fail(e, i, "more values than the header declares");
      } else {
        for (const PlyProperty& p : e.properties) {
          std::size_t items = 1;
          if (p.list) {
            if (bytes.size() - pos < p.count.size) record_fail(e, i, "the data ends inside it");
            const double n = read_scalar(bytes.data() + pos, p.count, swap);
            if (n < 0) record_fail(e, i, "a negative list length");
            items = static_cast<std::size_t>(n);
            pos += p.count.size;
          }
          if ((bytes.size() - pos) / p.item.size < items) record_fail(e, i, "the data ends inside it");
          pos += items * p.item.size;
        }
      }
    }
  }
  if (pos < bytes.size() && (!ascii || bytes.find_first_not_of(" \t\r\n", pos) != std::string::npos)) {
    std::ostringstream os;
    os << "data continues after the elements the header declares (" << bytes.size() - pos << " bytes)";
    fail(origin, os.str());
  }
}

std::array<int, 3> find_xyz(const std::vector<Field>& fields, const std::string& origin) {
  std::array<int, 3> xyz{-1, -1, -1};
  for (std::size_t i = 0; i < fields.size(); ++i)
    for (int a = 0; a < 3; ++a)
      if (fields[i].name == std::string(1, "xyz"[a])) xyz[a] = static_cast<int>(i);
  for (std::size_t i = 0; i < fields.size(); ++i)
    for (int a = 0; a < 3; ++a)
      if (fields[i].name == std::string(1, "xyz"[a]) && xyz[a] != static_cast<int>(i))
        fail(origin, std::string("field \"") + "xyz"[a] + "\" is declared twice");
  for (int a = 0; a < 3; ++a)
    if (xyz[a] < 0) fail(origin, std::string("the points have no \"") + "xyz"[a] + "\" field");
  for (int a = 0; a < 3; ++a)
    if (fields[xyz[a]].kind != 'f')
      fail(origin, std::string("field \"") + "xyz"[a] + "\" is not a float or double");
  return xyz;
}

PointCloud parse_ply(const std::string& bytes, const std::string& origin) {
  Lines lines{bytes, origin};
  if (lines.next() != "ply") fail(origin, "not a PLY file (the first line is not \"ply\")");
  std::string format;
  std::size_t vertices = 0;
  bool in_vertex = false, seen_element = false;
  std::vector<PlyElement> later;
  std::vector<Field> fields;
  std::size_t stride = 0;
  while (true) {
    const std::vector<std::string> w = words(lines.next());
    if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "end_header") break;
    if (w[0] == "format") {
      if (w.size() != 3) fail(origin, "malformed format line");
      if (!format.empty()) fail(origin, "the header has two format lines");
      if (w[2] != "1.0") fail(origin, "PLY version \"" + w[2] + "\" (MINER reads version 1.0)");
      format = w[1];
      if (format != "ascii" && format != "binary_little_endian" && format != "binary_big_endian")
        fail(origin, "unknown PLY format \"" + format + "\"");
    } else if (w[0] == "element") {
      if (w.size() != 3) fail(origin, "malformed element line");
      if (!seen_element && w[1] != "vertex") fail(origin, "the first element is \"" + w[1] + "\", not \"vertex\"");
      // One vertex element: a second one's points would be walked as another element's and
      // dropped (issue 20, fourth campaign).
      if (seen_element && w[1] == "vertex") fail(origin, "a second \"vertex\" element (MINER reads one)");
      in_vertex = !seen_element;
      if (in_vertex) vertices = count_of(w[2], "element vertex", origin);
      else later.push_back({w[1], count_of(w[2], "element " + w[1], origin), {}});
      seen_element = true;
    } else if (w[0] == "property") {
      if (!seen_element) fail(origin, "a property line before any element");
      if (!in_vertex) {  // a later element's property: its records are walked, never used
        PlyProperty p;
        p.list = w.size() == 5 && w[1] == "list";
        if (w.size() != (p.list ? 5u : 3u)) fail(origin, "malformed property line of element \"" + later.back().name + "\"");
        if (p.list) {
          p.count = ply_type(w[2]);
          p.item = ply_type(w[3]);
          if (p.count.size == 0 || p.count.kind == 'f')
            fail(origin, "element \"" + later.back().name + "\" list \"" + w[4] + "\": count type \"" + w[2] + "\" is not an integer type");
          if (p.item.size == 0) fail(origin, "element \"" + later.back().name + "\" list \"" + w[4] + "\" has unknown type \"" + w[3] + "\"");
        } else {
          p.item = ply_type(w[1]);
          if (p.item.size == 0) fail(origin, "element \"" + later.back().name + "\" property \"" + w[2] + "\" has unknown type \"" + w[1] + "\"");
        }
        later.back().properties.push_back(p);
        continue;
      }
      if (w.size() != 3) fail(origin, "vertex property \"" + (w.size() > 1 ? w[1] : std::string()) +
                                          "\": list properties are not supported in the vertex element");
      Field f = ply_type(w[1]);
      f.name = w[2];
      if (f.size == 0) fail(origin, "vertex property \"" + w[2] + "\" has unknown type \"" + w[1] + "\"");
      f.offset = stride;
      stride += f.size;
      fields.push_back(f);
    } else {
      fail(origin, "unknown header line \"" + w[0] + "\"");
    }
  }
  if (format.empty()) fail(origin, "the header has no format line");
  if (!seen_element) fail(origin, "the header declares no vertex element");
  const std::array<int, 3> xyz = find_xyz(fields, origin);
  PointCloud cloud;
  // Later elements (faces, edges) follow the vertices and are walked to the file's end.
  for (const PlyElement& e : later)
    if (e.count > 0 && e.properties.empty()) fail(origin, "element \"" + e.name + "\" has records but no properties");
  const std::size_t end = read_records(cloud, bytes, lines.pos, vertices, fields, xyz, format == "ascii",
                                       format == "binary_big_endian", stride, origin, later.empty());
  if (!later.empty()) check_later_elements(bytes, end, later, format == "ascii", format == "binary_big_endian", origin);
  return cloud;
}

PointCloud parse_pcd(const std::string& bytes, const std::string& origin) {
  Lines lines{bytes, origin};
  std::vector<std::string> names, sizes, types, counts;
  std::size_t points = 0, width = 0, height = 1;
  bool have_points = false, have_width = false, have_version = false;
  std::vector<std::string> seen;  // header keys, each at most once
  std::optional<Eigen::Vector3d> viewpoint;
  std::string data;
  while (true) {
    const std::string line = lines.next();
    const std::vector<std::string> w = words(line);
    if (w.empty() || w[0][0] == '#') continue;
    const std::vector<std::string> rest(w.begin() + 1, w.end());
    if (std::find(seen.begin(), seen.end(), w[0]) != seen.end())
      fail(origin, "header line " + w[0] + " is given twice");
    seen.push_back(w[0]);
    if (w[0] == "VERSION") {
      // PCL writes 0.7 (".7" in older files); other versions lay their header out differently.
      if (rest.size() != 1 || (rest[0] != "0.7" && rest[0] != ".7"))
        fail(origin, "PCD VERSION \"" + (rest.empty() ? std::string() : rest[0]) + "\" (MINER reads version 0.7)");
      have_version = true;
      continue;
    }
    if (w[0] == "FIELDS") names = rest;
    else if (w[0] == "SIZE") sizes = rest;
    else if (w[0] == "TYPE") types = rest;
    else if (w[0] == "COUNT") counts = rest;
    else if (w[0] == "WIDTH" && rest.size() == 1) {
      width = count_of(rest[0], "WIDTH", origin);
      have_width = true;
    }
    else if (w[0] == "HEIGHT" && rest.size() == 1) height = count_of(rest[0], "HEIGHT", origin);
    else if (w[0] == "POINTS" && rest.size() == 1) {
      points = count_of(rest[0], "POINTS", origin);
      have_points = true;
    } else if (w[0] == "VIEWPOINT" && rest.size() == 7) {
      Eigen::Vector3d t;
      for (int a = 0; a < 3; ++a) t[a] = parse_number(rest[a], origin + ": VIEWPOINT", 0);
      if (!t.allFinite()) fail(origin, "VIEWPOINT is not finite");
      Eigen::Vector4d q;
      for (int a = 0; a < 4; ++a) q[a] = parse_number(rest[3 + a], origin + ": VIEWPOINT", 0);
      // The orientation is a unit quaternion (w x y z); 1e-3 allows the 4-6 digits files print.
      constexpr double kUnitTolerance = 1e-3;
      if (!q.allFinite() || std::abs(q.norm() - 1.0) > kUnitTolerance)
        fail(origin, "VIEWPOINT orientation is not a unit quaternion");
      // Only the translation is used (the sensor origin); a rotation would say the points are in
      // a turned sensor frame, which the import does not apply: refused, not ignored (eleventh
      // campaign I2). q and -q are the same rotation.
      if ((q - Eigen::Vector4d(1, 0, 0, 0)).norm() > kUnitTolerance && (q + Eigen::Vector4d(1, 0, 0, 0)).norm() > kUnitTolerance)
        fail(origin, "VIEWPOINT orientation " + rest[3] + " " + rest[4] + " " + rest[5] + " " + rest[6] +
                         " is not the identity: MINER takes the points in the map frame (rotate them first)");
      viewpoint = t;
    } else if (w[0] == "DATA" && rest.size() == 1) {
      data = rest[0];
      break;
    } else {
      fail(origin, "unknown or malformed header line \"" + line + "\"");
    }
  }
  // PCD 0.7 names its version and point count in every header PCL writes (eleventh campaign I3:
  // a header without either was read).
  if (!have_version) fail(origin, "the header has no VERSION line (PCD 0.7)");
  if (!have_points) fail(origin, "the header has no POINTS line");
  if (names.empty()) fail(origin, "the header has no FIELDS line");
  if (sizes.size() != names.size() || types.size() != names.size() || (!counts.empty() && counts.size() != names.size()))
    fail(origin, "FIELDS, SIZE, TYPE and COUNT list different numbers of fields");
  if (height == 0) fail(origin, "HEIGHT is 0 (an unorganised cloud has HEIGHT 1)");
  if (!have_points) points = width * height;
  if (have_points && have_width && width * height != points) {
    std::ostringstream os;
    os << "WIDTH x HEIGHT = " << width << " x " << height << " does not match POINTS " << points;
    fail(origin, os.str());
  }
  if (data == "binary_compressed") fail(origin, "DATA binary_compressed is not supported (save the cloud as ascii or binary)");
  if (data != "ascii" && data != "binary") fail(origin, "unknown DATA \"" + data + "\"");
  std::vector<Field> fields;
  std::size_t stride = 0;
  for (std::size_t i = 0; i < names.size(); ++i) {
    Field f;
    f.name = names[i];
    if (sizes[i] != "1" && sizes[i] != "2" && sizes[i] != "4" && sizes[i] != "8")
      fail(origin, "field \"" + f.name + "\" has SIZE \"" + sizes[i] + "\"");
    f.size = std::stoul(sizes[i]);
    if (types[i] != "F" && types[i] != "I" && types[i] != "U")
      fail(origin, "field \"" + f.name + "\" has TYPE \"" + types[i] + "\"");
    f.kind = types[i] == "F" ? 'f' : types[i] == "I" ? 'i' : 'u';
    if ((f.kind == 'f' && f.size != 4 && f.size != 8) || (f.kind != 'f' && f.size == 8))
      fail(origin, "field \"" + f.name + "\": TYPE " + types[i] + " with SIZE " + sizes[i] + " is not supported");
    const std::size_t count = counts.empty() ? 1 : count_of(counts[i], "COUNT", origin);
    if (count == 0 || count > 4096) fail(origin, "field \"" + f.name + "\" has COUNT " + std::to_string(count));
    if (count != 1 && (f.name == "x" || f.name == "y" || f.name == "z"))
      fail(origin, "field \"" + f.name + "\" must have COUNT 1");
    f.offset = stride;
    stride += f.size * count;
    fields.push_back(f);
    // ASCII data lists COUNT values per field: stand-ins keep the token positions.
    for (std::size_t c = 1; c < count && data == "ascii"; ++c) fields.push_back({f.name + "#", 0, f.size, f.kind});
  }
  const std::array<int, 3> xyz = find_xyz(fields, origin);
  PointCloud cloud;
  cloud.viewpoint = viewpoint;
  read_records(cloud, bytes, lines.pos, points, fields, xyz, data == "ascii", false, stride, origin, true);
  return cloud;
}

}  // namespace

PointCloud parse_point_cloud(const std::string& bytes, bool ply, const std::string& origin) {
  return ply ? parse_ply(bytes, origin) : parse_pcd(bytes, origin);
}

PointCloud read_point_cloud(const std::string& path) {
  const auto ends_with = [&](const char* s) {
    const std::size_t n = std::strlen(s);
    return path.size() >= n && path.compare(path.size() - n, n, s) == 0;
  };
  if (!ends_with(".ply") && !ends_with(".pcd")) throw Error(path + ": a point cloud must be a .ply or .pcd file");
  return parse_point_cloud(read_file_bytes(path, "point cloud"), ends_with(".ply"), path);
}

std::shared_ptr<const VoxelLayer> integrate_clouds(const std::vector<CloudScan>& scans, double resolution,
                                                   double max_range) {
  check_resolution(resolution, "resolution");
  // "If positive": 0 is no limit; a NaN or negative range was also taken as none (eleventh
  // campaign L3).
  if (!(std::isfinite(max_range) && max_range >= 0.0))
    throw Error("max_range: must be a finite range >= 0 m (0: no limit), got " + exact_number(max_range));
  octomap::OcTree tree(resolution);
  const double reach = 32767.0 * resolution;
  const auto point = [](const Eigen::Vector3d& p) {
    return octomap::point3d(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
  };
  // Sensor origins first: one beyond the keys made the ray bound below infinite, blamed on the
  // rays (issue 20); and a cloud of no finite point is named as such.
  // Each cloud is named by its file when it has one (issue 20, fourth campaign: "cloud 0:
  // point 0" named none).
  const auto label = [&](std::size_t s) {
    return scans[s].name.empty() ? "cloud " + std::to_string(s) : scans[s].name;
  };
  // One scan given twice (a copy under another name) would push every voxel's log-odds twice
  // as far (eighteenth campaign F28): the same origin and the same points are refused, naming
  // both. Compared by a checksum first, then point by point.
  {
    std::map<std::uint64_t, std::size_t> first_with;
    for (std::size_t s = 0; s < scans.size(); ++s) {
      const auto& pts = scans[s].cloud.points;
      std::uint64_t h = fnv1a64(scans[s].origin.data(), sizeof(double) * 3);
      for (const Eigen::Vector3d& p : pts) h = fnv1a64(p.data(), sizeof(double) * 3, h);
      const auto [it, fresh] = first_with.emplace(h, s);
      if (!fresh && scans[it->second].origin == scans[s].origin && scans[it->second].cloud.points == pts)
        throw Error(label(s) + ": the same scan as " + label(it->second) +
                    " (the same sensor origin and points): integrating it twice would count every ray twice");
    }
  }
  // Each point's ray walks |point - origin| / res voxels (at most max_range / res): the total is
  // bounded before OctoMap starts (it integrates ~1e7 voxels per second).
  constexpr double kMaxRaySteps = 2e9;
  std::size_t finite_points = 0;
  for (std::size_t s = 0; s < scans.size(); ++s) {
    if (!(scans[s].origin.allFinite() && scans[s].origin.cwiseAbs().maxCoeff() < reach))
      throw Error(label(s) + ": the sensor origin " + format_point(scans[s].origin) +
                  " (--origin, or the cloud's own viewpoint) lies beyond OctoMap's key range at this resolution "
                  "(32767 voxels from the origin)");
    // The file readers skip and count non-finite points; a cloud filled in code must leave them
    // out too (eleventh campaign L3: (3, 0, NaN) was integrated as some voxel, (NaN, 0, 1) blamed
    // on the key range).
    const auto& points = scans[s].cloud.points;
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (!points[i].allFinite())
        throw Error(label(s) + ": point " + std::to_string(i) + " " + format_point(points[i]) +
                    " is not finite (leave such points out, as the file readers do: they skip and count them)");
      // A point whose ray alone passes the work bound below is named now, by file and index
      // (seventeenth campaign F13: a point at 1e300 was refused as "rays would walk inf voxels").
      // Nearer points beyond the key range meet the outlier advice below first.
      if (!((points[i] - scans[s].origin).norm() / resolution <= kMaxRaySteps))
        throw Error(label(s) + ": point " + std::to_string(i) + " " + format_point(points[i]) +
                    " lies beyond OctoMap's key range at this resolution (32767 voxels from the origin)");
    }
    finite_points += points.size();
  }
  // Named by the clouds' files (seventh campaign C8: an empty PLY named none).
  if (finite_points == 0) {
    std::string names;
    for (std::size_t s = 0; s < scans.size(); ++s) names += (s ? ", " : "") + label(s);
    throw Error(names + ": no finite point to integrate (non-finite points are skipped)");
  }
  double steps = 0.0;
  for (const CloudScan& scan : scans)
    for (const Eigen::Vector3d& p : scan.cloud.points) {
      const double length = (p - scan.origin).norm();
      steps += (max_range > 0.0 ? std::min(length, max_range) : length) / resolution;
    }
  if (steps > kMaxRaySteps) {
    std::ostringstream os;
    os << "the clouds' rays would walk " << steps << " voxels at " << resolution << " m, more than the " << kMaxRaySteps
       << " an import may; use --range, a coarser --resolution or fewer points";
    throw Error(os.str());
  }
  // The voxels the rays reach span the box of the origins and the rays' ends: a grid over it
  // larger than a map may have is refused now, not after integrating (issue 20, fifth campaign:
  // 100 points 1600 m away integrated for 27 s before the layer was refused).
  Eigen::Vector3d lo = scans.front().origin, hi = lo;
  for (const CloudScan& scan : scans) {
    lo = lo.cwiseMin(scan.origin);
    hi = hi.cwiseMax(scan.origin);
    for (const Eigen::Vector3d& p : scan.cloud.points) {
      const double length = (p - scan.origin).norm();
      const Eigen::Vector3d end =
          max_range > 0.0 && length > max_range ? Eigen::Vector3d(scan.origin + (p - scan.origin) * (max_range / length)) : p;
      lo = lo.cwiseMin(end);
      hi = hi.cwiseMax(end);
    }
  }
  const Eigen::Vector3d cells = ((hi - lo) / resolution).array().floor() + 1.0;
  if (cells.prod() > kMaxGridCells) {
    std::ostringstream os;
    os << "the clouds and their sensor origins span " << format_point(lo) << " - " << format_point(hi) << ", "
       << cells.x() << " x " << cells.y() << " x " << cells.z() << " voxels at " << resolution << " m, more than the "
       << kMaxGridCells << " a map may have";
    // Name the outliers: a few returns kilometres away (eleventh campaign I1) cannot be helped by
    // --range, whose truncated rays still free space up to it in their direction.
    std::vector<double> ranges;
    for (const CloudScan& scan : scans)
      for (const Eigen::Vector3d& p : scan.cloud.points) ranges.push_back((p - scan.origin).norm());
    std::vector<double> sorted = ranges;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
    const double median = sorted[sorted.size() / 2];
    constexpr double kOutlierFactor = 10.0;  // returns 10 times farther than the median one
    const auto far = std::count_if(ranges.begin(), ranges.end(), [&](double r) { return r > kOutlierFactor * median; });
    if (far > 0)
      os << "; " << far << " of the " << ranges.size() << " points lie farther than " << kOutlierFactor
         << " x the median range (" << median << " m) from their sensor: drop such outliers before importing (--range "
         << "truncates their rays but still frees space up to it in their direction)";
    os << "; use a coarser --resolution" << (far > 0 ? "" : ", --range") << " or drop the far points";
    throw Error(os.str());
  }
  for (std::size_t s = 0; s < scans.size(); ++s) {
    const CloudScan& scan = scans[s];
    const auto beyond = [&](const Eigen::Vector3d& p) { return !(p.cwiseAbs().maxCoeff() < reach); };  // origins checked above
    octomap::Pointcloud cloud;
    cloud.reserve(scan.cloud.points.size());
    for (std::size_t i = 0; i < scan.cloud.points.size(); ++i) {
      const Eigen::Vector3d& p = scan.cloud.points[i];
      if (beyond(p))
        throw Error(label(s) + ": point " + std::to_string(i) + " " + format_point(p) +
                    " lies beyond OctoMap's key range at this resolution (32767 voxels from the origin)");
      cloud.push_back(point(p));
    }
    // Discretized insertion (OctoMap's own option): the points of one voxel share one ray to
    // that voxel's centre, so a dense scan casts one ray per hit voxel, not per point (issue 20,
    // tenth campaign I1: 10^7 points of a room took 72 s; now ~3.5 s). The occupied voxels are the
    // same; the free ones differ only where a ray's last stretch crosses another voxel.
    tree.insertPointCloud(cloud, point(scan.origin), max_range > 0.0 ? max_range : -1.0, /*lazy_eval=*/false,
                          /*discretize=*/true);
  }
  tree.updateInnerOccupancy();
  return layer_of_tree(tree, "point clouds");
}

}  // namespace miner::world
