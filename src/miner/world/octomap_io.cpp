// OctoMap import and export for miner::world::Map (REQ-WORLD-003).
#include <fstream>
#include <iostream>
#include <sstream>

#include <octomap/OcTree.h>

#include "miner/core/error.hpp"
#include "miner/world/map.hpp"
#include "miner/world/voxel_grid.hpp"

namespace miner::world {

Map Map::load_octomap(const std::string& path) {
  {
    std::ifstream probe(path, std::ios::binary);
    if (!probe) throw Error(path + ": cannot open file");
  }
  octomap::OcTree tree(0.1);  // the resolution is replaced by the file's
  // OctoMap chats on std::cerr while reading; keep its words for the error message only.
  std::ostringstream octomap_log;
  std::streambuf* const saved = std::cerr.rdbuf(octomap_log.rdbuf());
  const bool ok = tree.readBinary(path);
  std::cerr.rdbuf(saved);
  if (!ok) {
    std::string detail = octomap_log.str();
    while (!detail.empty() && (detail.back() == '\n' || detail.back() == ' ')) detail.pop_back();
    for (auto& c : detail) if (c == '\n') c = ';';
    throw Error(path + ": not a readable OctoMap binary tree (.bt) file" +
                (detail.empty() ? std::string() : " (OctoMap: " + detail + ")"));
  }
  if (tree.size() == 0) throw Error(path + ": OctoMap tree has no known cells");
  std::vector<Box> obstacles;
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    if (!tree.isNodeOccupied(*it)) continue;
    const octomap::point3d c = it.getCoordinate();
    const double half = 0.5 * it.getSize();
    const Eigen::Vector3d center(c.x(), c.y(), c.z());
    obstacles.push_back({center.array() - half, center.array() + half});
  }
  double x0, y0, z0, x1, y1, z1;
  tree.getMetricMin(x0, y0, z0);
  tree.getMetricMax(x1, y1, z1);
  try {
    return Map(Box{{x0, y0, z0}, {x1, y1, z1}}, tree.getResolution(), std::move(obstacles));
  } catch (const Error& e) {
    throw Error(path + ": " + e.what());
  }
}

void Map::save_octomap(const std::string& path) const {
  const VoxelGrid grid(*this, 0.0);
  octomap::OcTree tree(resolution_);
  const auto to_point = [](const Eigen::Vector3d& p) {
    return octomap::point3d(static_cast<float>(p.x()), static_cast<float>(p.y()),
                            static_cast<float>(p.z()));
  };
  for (std::size_t i = 0; i < grid.cell_count(); ++i) {
    if (grid.occupied(i)) tree.updateNode(to_point(grid.cell_center(i)), true);
  }
  // Known free cells at the two corners keep the bounds in the tree's metric extent.
  tree.updateNode(to_point(grid.cell_center(0)), grid.occupied(std::size_t{0}));
  tree.updateNode(to_point(grid.cell_center(grid.cell_count() - 1)),
                  grid.occupied(grid.cell_count() - 1));
  tree.updateInnerOccupancy();
  const std::string tmp = path + ".tmp";
  if (!tree.writeBinary(tmp)) throw Error(path + ": cannot write OctoMap file");
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw Error(path + ": cannot replace file");
  }
}

}  // namespace miner::world
