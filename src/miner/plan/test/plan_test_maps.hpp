#pragma once
// Helpers shared by the plan unit tests (the maps are in miner/testing/door_maps.hpp).
#include <filesystem>
#include <string>

#include <unistd.h>

#include "miner/testing/door_maps.hpp"

namespace miner::plan::test {

/// A per-process temp folder (ctest runs the cases of one binary in parallel).
inline std::string temp_path(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("miner_plan_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

}  // namespace miner::plan::test
