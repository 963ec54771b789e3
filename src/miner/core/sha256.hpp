#pragma once
/// \file
/// SHA-256 (FIPS 180-4) of a byte string, as 64 lower-case hex digits. A map that references a
/// large voxel file records the file's hash and refuses a file that no longer matches it
/// (REQ-WORLD-015), so a run folder stays reproducible without a copy of the map.

#include <cstddef>
#include <cstdint>
#include <string>

namespace miner {

std::string sha256_hex(const std::string& bytes);

/// FNV-1a, 64 bit, of `size` bytes, continuing from `h` (the offset basis by default), so a
/// checksum of several pieces is one call per piece. Not cryptographic: a tensor file's data
/// check and a map's fingerprint (world::Map::fingerprint).
inline constexpr std::uint64_t kFnv1a64Basis = 0xcbf29ce484222325ULL;
std::uint64_t fnv1a64(const void* data, std::size_t size, std::uint64_t h = kFnv1a64Basis);

}  // namespace miner
