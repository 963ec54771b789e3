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
/// The SHA-256 of a file's bytes, read in 1 MiB pieces (memory bounded whatever its size).
/// Throws miner::Error naming the path when it cannot be read or is no regular file.
std::string sha256_file_hex(const std::string& path);

class JsonField;
/// A recorded SHA-256 read from a file: 64 lower-case hex digits (as `sha256sum` prints them),
/// else the field is refused, so a malformed hash is named as such rather than as "the file
/// changed".
std::string sha256_field(const JsonField& f);

/// FNV-1a, 64 bit, of `size` bytes, continuing from `h` (the offset basis by default), so a
/// checksum of several pieces is one call per piece. Not cryptographic: a tensor file's data
/// check and a map's fingerprint (world::Map::fingerprint).
inline constexpr std::uint64_t kFnv1a64Basis = 0xcbf29ce484222325ULL;
std::uint64_t fnv1a64(const void* data, std::size_t size, std::uint64_t h = kFnv1a64Basis);

}  // namespace miner
