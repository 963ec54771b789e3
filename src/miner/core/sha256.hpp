#pragma once
/// \file
/// SHA-256 (FIPS 180-4) of a byte string, as 64 lower-case hex digits. A map that references a
/// large voxel file records the file's hash and refuses a file that no longer matches it
/// (REQ-WORLD-015), so a run folder stays reproducible without a copy of the map.

#include <string>

namespace miner {

std::string sha256_hex(const std::string& bytes);

}  // namespace miner
