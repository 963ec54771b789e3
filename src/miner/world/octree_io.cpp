#include "miner/world/octree_io.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <sstream>
#include <vector>

#include "miner/core/error.hpp"
#include "miner/core/json_io.hpp"
#include "miner/world/map.hpp"

namespace miner::world {

namespace {

/// OctoMap's tree depth: the root covers 2^16 keys per axis, a depth-16 node one voxel.
constexpr int kTreeDepth = 16;
constexpr const char* kBinaryHeader = "# Octomap OcTree binary file";
constexpr const char* kFullHeader = "# Octomap OcTree file";

using Leaf = OctreeLeaf;

struct Header {
  std::string id;
  std::size_t size = 0;
  double res = 0.0;
  std::size_t data = 0;  // offset of the first data byte
  bool binary = true;
};

[[noreturn]] void fail(const std::string& origin, const std::string& what) { throw Error(origin + ": " + what); }

Header parse_header(const std::string& bytes, const std::string& origin) {
  Header h;
  std::size_t pos = 0;
  const auto next_line = [&](std::string& line) {
    if (pos >= bytes.size()) return false;
    const std::size_t end = bytes.find('\n', pos);
    // A header line longer than this is not OctoMap's.
    constexpr std::size_t kMaxHeaderLine = 4096;
    const std::size_t stop = end == std::string::npos ? bytes.size() : end;
    if (stop - pos > kMaxHeaderLine) fail(origin, "header line longer than 4096 bytes: not an OctoMap file");
    line = bytes.substr(pos, stop - pos);
    pos = end == std::string::npos ? bytes.size() : end + 1;
    return true;
  };
  std::string line;
  if (!next_line(line)) fail(origin, "empty file: not an OctoMap file");
  if (line.rfind(kBinaryHeader, 0) == 0) {
    h.binary = true;
  } else if (line.rfind(kFullHeader, 0) == 0) {
    h.binary = false;
  } else {
    fail(origin, "not an OctoMap file (the first line is neither \"" + std::string(kBinaryHeader) + "\" nor \"" +
                     kFullHeader + "\")");
  }
  bool have_id = false, have_size = false, have_res = false;
  while (true) {
    if (!next_line(line)) fail(origin, "header ends before its \"data\" line");
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    std::istringstream in(line);
    std::string key;
    in >> key;
    if (key == "data") {
      h.data = pos;
      break;
    }
    std::string value, extra;
    if (!(in >> value) || (in >> extra)) fail(origin, "header line \"" + line + "\" is not \"<key> <value>\"");
    if ((key == "id" && have_id) || (key == "size" && have_size) || (key == "res" && have_res))
      fail(origin, "header key \"" + key + "\" is given twice");
    if (key == "id") {
      h.id = value;
      have_id = true;
    } else if (key == "size") {
      if (value.find_first_not_of("0123456789") != std::string::npos || value.size() > 15)
        fail(origin, "header size \"" + value + "\" is not a node count");
      h.size = std::stoull(value);
      have_size = true;
    } else if (key == "res") {
      char* end = nullptr;
      h.res = std::strtod(value.c_str(), &end);
      if (!is_decimal_number(value) || end == value.c_str() || *end != '\0' || !std::isfinite(h.res) || !(h.res > 0.0))
        fail(origin, "header res \"" + value + "\" is not a positive resolution in m");
      if (h.res < kMinResolution || h.res > kMaxResolution) {
        std::ostringstream os;
        os << "header res " << value << " m is outside the resolutions a map may have [" << kMinResolution << ", "
           << kMaxResolution << "] m";
        fail(origin, os.str());
      }
      have_res = true;
    } else {
      fail(origin, "unknown header key \"" + key + "\" (an OctoMap header has id, size, res and data)");
    }
  }
  if (!have_id || !have_size || !have_res)
    fail(origin, std::string("header lacks ") + (!have_id ? "id" : !have_size ? "size" : "res"));
  if (h.binary && h.id != "OcTree")
    fail(origin, "binary tree id \"" + h.id + "\" is not OcTree (the only tree a .bt file holds)");
  if (!h.binary && h.id != "OcTree" && h.id != "ColorOcTree")
    fail(origin, "tree id \"" + h.id + "\" is not one MINER reads (OcTree, ColorOcTree)");
  return h;
}

/// Walks the node stream in pre-order with an explicit stack (depth <= 16); calls
/// leaf(corner, depth, state) for every known leaf. Returns the node count.
std::vector<Leaf> read_leaves(const std::string& bytes, const Header& h, const std::string& origin) {
  std::vector<Leaf> leaves;
  std::size_t pos = h.data;
  std::size_t nodes = 0;
  struct Node {
    std::array<std::uint32_t, 3> corner;
    int depth;
  };
  const auto need = [&](std::size_t n) {
    if (bytes.size() - pos < n) {
      std::ostringstream os;
      os << "data ends early: " << nodes << " nodes read of the " << h.size << " the header announces";
      fail(origin, os.str());
    }
  };
  const auto add_leaf = [&](const Node& n, VoxelState s) {
    if (leaves.size() >= kMaxOctreeLeaves) {
      std::ostringstream os;
      os << "more than " << kMaxOctreeLeaves << " leaves, more than a map may hold";
      fail(origin, os.str());
    }
    leaves.push_back({{static_cast<std::uint16_t>(n.corner[0]), static_cast<std::uint16_t>(n.corner[1]),
                       static_cast<std::uint16_t>(n.corner[2])},
                      static_cast<std::uint8_t>(n.depth), s});
  };
  const auto child_of = [](const Node& n, int i) {
    const std::uint32_t half = 1u << (kTreeDepth - n.depth - 1);
    Node c{n.corner, n.depth + 1};
    for (int a = 0; a < 3; ++a)
      if (i & (1 << a)) c.corner[a] += half;
    return c;
  };
  if (h.size == 0) fail(origin, "the tree is empty (size 0): no known cells");
  std::vector<Node> stack{{{0, 0, 0}, 0}};
  std::size_t node_bytes = 0;  // .ot: bytes of one node's data before its child byte
  if (!h.binary) node_bytes = h.id == "ColorOcTree" ? 7 : 4;
  while (!stack.empty()) {
    const Node n = stack.back();
    stack.pop_back();
    ++nodes;
    if (nodes > h.size) {
      std::ostringstream os;
      os << "data holds more nodes than the " << h.size << " the header announces";
      fail(origin, os.str());
    }
    std::array<int, 8> inner{};
    int inner_count = 0;
    if (h.binary) {
      need(2);
      const auto b0 = static_cast<unsigned char>(bytes[pos]), b1 = static_cast<unsigned char>(bytes[pos + 1]);
      pos += 2;
      for (int i = 0; i < 8; ++i) {
        const unsigned byte = i < 4 ? b0 : b1;
        const int j = i % 4;
        const bool lo = (byte >> (2 * j)) & 1u, hi = (byte >> (2 * j + 1)) & 1u;
        if (!lo && !hi) continue;
        ++nodes;
        if (lo && hi) {
          if (n.depth + 1 >= kTreeDepth) {
            std::ostringstream os;
            os << "a node at depth " << kTreeDepth << " claims children (byte " << pos - 2 + i / 4 << ")";
            fail(origin, os.str());
          }
          inner[inner_count++] = i;
          --nodes;  // counted when it is read
        } else {
          add_leaf(child_of(n, i), lo ? VoxelState::kFree : VoxelState::kOccupied);
        }
      }
    } else {
      need(node_bytes + 1);
      float logodds;
      std::memcpy(&logodds, bytes.data() + pos, sizeof logodds);
      const auto children = static_cast<unsigned char>(bytes[pos + node_bytes]);
      pos += node_bytes + 1;
      if (!std::isfinite(logodds)) {
        std::ostringstream os;
        os << "node " << nodes << " has a non-finite log-odds value";
        fail(origin, os.str());
      }
      if (children == 0) {
        if (n.depth == 0) fail(origin, "the root is a leaf: the map would span OctoMap's whole key space");
        add_leaf(n, logodds >= 0.0f ? VoxelState::kOccupied : VoxelState::kFree);
        continue;
      }
      if (n.depth >= kTreeDepth) {
        std::ostringstream os;
        os << "a node at depth " << kTreeDepth << " claims children (byte " << pos - 1 << ")";
        fail(origin, os.str());
      }
      for (int i = 0; i < 8; ++i)
        if (children & (1u << i)) inner[inner_count++] = i;
    }
    for (int k = inner_count - 1; k >= 0; --k) stack.push_back(child_of(n, inner[k]));
  }
  if (nodes != h.size) {
    std::ostringstream os;
    os << "data holds " << nodes << " nodes, the header announces " << h.size;
    fail(origin, os.str());
  }
  if (pos != bytes.size()) {
    std::ostringstream os;
    os << bytes.size() - pos << " bytes follow the tree's last node";
    fail(origin, os.str());
  }
  if (leaves.empty()) fail(origin, "the tree has no known leaf");
  return leaves;
}

/// Shortest decimal that reads back as `v` (OctoMap writes 6 digits, which loses e.g. 0.1234567).
std::string exact_decimal(double v) {
  for (int digits = 6; digits <= 17; ++digits) {
    std::ostringstream os;
    os.precision(digits);
    os << v;
    if (std::strtod(os.str().c_str(), nullptr) == v) return os.str();
  }
  return std::to_string(v);
}

}  // namespace

std::shared_ptr<const VoxelLayer> parse_octree(const std::string& bytes, const std::string& origin,
                                               double max_cells) {
  const Header h = parse_header(bytes, origin);
  return layer_from_leaves(read_leaves(bytes, h, origin), h.res, origin, max_cells);
}

std::shared_ptr<const VoxelLayer> parse_octree(const std::string& bytes, const std::string& origin) {
  return parse_octree(bytes, origin, kMaxGridCells);
}

std::shared_ptr<const VoxelLayer> layer_from_leaves(const std::vector<OctreeLeaf>& leaves, double resolution,
                                                    const std::string& origin) {
  return layer_from_leaves(leaves, resolution, origin, kMaxGridCells);
}

std::shared_ptr<const VoxelLayer> layer_from_leaves(const std::vector<OctreeLeaf>& leaves, double resolution,
                                                    const std::string& origin, double max_cells) {
  if (leaves.empty()) fail(origin, "the tree has no known leaf");
  // Tenth campaign L18: a NaN or infinite budget asked for 2^48 bytes (bad_alloc); a leaf below
  // the tree's depth or off its own lattice made a std::length_error or overlapping voxels.
  if (!(max_cells >= 1.0 && max_cells <= kMaxGridCells)) {
    std::ostringstream os;
    os << "the cell budget must be in [1, " << kMaxGridCells << "], got " << max_cells;
    fail(origin, os.str());
  }
  for (std::size_t i = 0; i < leaves.size(); ++i) {
    const Leaf& l = leaves[i];
    if (l.depth > kTreeDepth) fail(origin, "leaf " + std::to_string(i) + " has depth " + std::to_string(l.depth) +
                                               ", below the tree's " + std::to_string(kTreeDepth));
    const std::int64_t size = std::int64_t{1} << (kTreeDepth - l.depth);
    for (int a = 0; a < 3; ++a)
      if (l.key[a] % size != 0)
        fail(origin, "leaf " + std::to_string(i) + "'s key " + std::to_string(l.key[a]) + " is not on its depth's lattice (multiples of " +
                         std::to_string(size) + ")");
  }
  std::array<std::int64_t, 3> lo{}, hi{};
  lo.fill(INT64_MAX);
  hi.fill(INT64_MIN);
  for (const Leaf& l : leaves) {
    const std::int64_t size = std::int64_t{1} << (kTreeDepth - l.depth);
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min<std::int64_t>(lo[a], l.key[a]);
      hi[a] = std::max<std::int64_t>(hi[a], l.key[a] + size);
    }
  }
  const double cells = static_cast<double>(hi[0] - lo[0]) * static_cast<double>(hi[1] - lo[1]) *
                       static_cast<double>(hi[2] - lo[2]);
  if (cells > max_cells) {
    std::ostringstream os;
    os << "the known leaves span " << hi[0] - lo[0] << " x " << hi[1] - lo[1] << " x " << hi[2] - lo[2]
       << " voxels, more than the " << max_cells << " a map may hold";
    fail(origin, os.str());
  }
  const Eigen::Vector3i dims(static_cast<int>(hi[0] - lo[0]), static_cast<int>(hi[1] - lo[1]),
                             static_cast<int>(hi[2] - lo[2]));
  std::vector<std::uint8_t> states(static_cast<std::size_t>(cells), static_cast<std::uint8_t>(VoxelState::kUnknown));
  const auto nx = static_cast<std::size_t>(dims.x()), ny = static_cast<std::size_t>(dims.y());
  for (const Leaf& l : leaves) {
    const int size = 1 << (kTreeDepth - l.depth);
    const int x0 = static_cast<int>(l.key[0] - lo[0]), y0 = static_cast<int>(l.key[1] - lo[1]),
              z0 = static_cast<int>(l.key[2] - lo[2]);
    for (int z = z0; z < z0 + size; ++z)
      for (int y = y0; y < y0 + size; ++y) {
        const std::size_t row = (static_cast<std::size_t>(z) * ny + y) * nx;
        std::fill_n(states.begin() + static_cast<std::ptrdiff_t>(row + x0), size, static_cast<std::uint8_t>(l.state));
      }
  }
  const Eigen::Vector3i origin_cells(static_cast<int>(lo[0] - kOctreeKeyOffset),
                                     static_cast<int>(lo[1] - kOctreeKeyOffset),
                                     static_cast<int>(lo[2] - kOctreeKeyOffset));
  try {
    return std::make_shared<const VoxelLayer>(origin_cells, resolution, dims, std::move(states));
  } catch (const Error& e) {
    fail(origin, e.what());
  }
}

std::shared_ptr<const VoxelLayer> read_octree(const std::string& path) {
  return parse_octree(read_file_bytes(path, "OctoMap file"), path);
}

std::string octree_bt_bytes(const VoxelLayer& layer) {
  // Block states of a pyramid over key space: level d holds the nodes of depth d that meet the
  // layer (node size 2^(16-d) keys); 0 free, 1 occupied, 2 unknown, 3 mixed.
  constexpr std::uint8_t kMixed = 3;
  const Eigen::Vector3i key0 = layer.origin_cells().array() + kOctreeKeyOffset;
  const Eigen::Vector3i key1 = key0 + layer.dims();
  if ((key0.array() < 0).any() || (key1.array() > 2 * kOctreeKeyOffset).any())
    throw Error("the map lies outside OctoMap's key range (32768 voxels either side of the origin)");
  if (layer.count(VoxelState::kUnknown) == layer.size()) throw Error("the map has no known voxel to write");
  struct Level {
    Eigen::Vector3i first, dims;  // node indices covered
    std::vector<std::uint8_t> state;
    std::uint8_t at(const Eigen::Vector3i& n) const {
      const Eigen::Vector3i c = n - first;
      if ((c.array() < 0).any() || (c.array() >= dims.array()).any()) return 2;
      return state[(static_cast<std::size_t>(c.z()) * dims.y() + c.y()) * dims.x() + c.x()];
    }
  };
  std::vector<Level> level(kTreeDepth + 1);
  level[kTreeDepth] = {key0, layer.dims(), layer.states()};
  for (int d = kTreeDepth - 1; d >= 0; --d) {
    const Level& child = level[d + 1];
    Level& L = level[d];
    const Eigen::Vector3i last = (child.first + child.dims - Eigen::Vector3i::Ones()).array() / 2;
    L.first = child.first.array() / 2;
    L.dims = last - L.first + Eigen::Vector3i::Ones();
    L.state.assign(static_cast<std::size_t>(L.dims.prod()), 0);
    for (int z = 0; z < L.dims.z(); ++z)
      for (int y = 0; y < L.dims.y(); ++y)
        for (int x = 0; x < L.dims.x(); ++x) {
          const Eigen::Vector3i n = L.first + Eigen::Vector3i(x, y, z);
          std::uint8_t s = child.at(2 * n);
          for (int i = 1; i < 8 && s != kMixed; ++i) {
            const std::uint8_t c = child.at(2 * n + Eigen::Vector3i(i & 1, (i >> 1) & 1, (i >> 2) & 1));
            if (c != s) s = kMixed;
          }
          L.state[(static_cast<std::size_t>(z) * L.dims.y() + y) * L.dims.x() + x] = s;
        }
  }
  // Pre-order emission, two bytes per inner node; the recursion follows the tree (<= 16 deep).
  std::string data;
  std::size_t nodes = 1;
  const auto emit = [&](const auto& self, int d, const Eigen::Vector3i& n) -> void {
    unsigned char byte[2] = {0, 0};
    std::array<Eigen::Vector3i, 8> inner;
    int inner_count = 0;
    for (int i = 0; i < 8; ++i) {
      const Eigen::Vector3i c = 2 * n + Eigen::Vector3i(i & 1, (i >> 1) & 1, (i >> 2) & 1);
      const std::uint8_t s = level[d + 1].at(c);
      const int shift = 2 * (i % 4);
      if (s == 2) continue;
      ++nodes;
      if (s == 0) byte[i / 4] |= static_cast<unsigned char>(1u << shift);
      if (s == 1) byte[i / 4] |= static_cast<unsigned char>(2u << shift);
      if (s == kMixed) {
        byte[i / 4] |= static_cast<unsigned char>(3u << shift);
        inner[inner_count++] = c;
      }
    }
    data.push_back(static_cast<char>(byte[0]));
    data.push_back(static_cast<char>(byte[1]));
    for (int k = 0; k < inner_count; ++k) self(self, d + 1, inner[k]);
  };
  emit(emit, 0, Eigen::Vector3i::Zero());
  std::ostringstream head;
  head << kBinaryHeader << "\n# (feel free to add / change comments, but leave the first line as it is!)\n#\n"
       << "id OcTree\nsize " << nodes << "\nres " << exact_decimal(layer.resolution()) << "\ndata\n";
  return head.str() + data;
}

void write_octree_bt(const VoxelLayer& layer, const std::string& path) {
  std::string bytes;
  try {
    bytes = octree_bt_bytes(layer);
  } catch (const Error& e) {
    throw Error(path + ": " + e.what());
  }
  write_file_atomic(path, bytes);
}

}  // namespace miner::world
