#pragma once
/// \file
/// Reader of the `miner-tensors-v1` container that src/python/sgan/tensors.py writes (the
/// sGAN weights and the PyTorch reference tensors):
///
///     bytes 0-7   magic "MINERTS1"
///     bytes 8-11  header length H (uint32, little endian)
///     H bytes     UTF-8 JSON: {"format": "miner-tensors-v1", "kind", "meta",
///                 "tensors": [{"name", "shape", "offset", "count"}], "data_bytes",
///                 "data_fnv1a64": 16 hex digits}
///     data_bytes  float32 little endian; a tensor is `count` floats from byte `offset`
///
/// Everything is checked before use (REQ-HEUR-006): magic, header, the data size, the
/// FNV-1a-64 checksum of the data, each tensor's extent and its shape against its count.

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "miner/core/json_io.hpp"
#include "miner/core/sha256.hpp"

namespace miner::heuristic {

struct Tensor {
  std::vector<int> shape;
  std::vector<float> values;
};

struct TensorFile {
  std::string path;
  std::string kind;
  Json meta;
  std::map<std::string, Tensor> tensors;

  /// The tensor `name` with shape `shape`; throws miner::Error naming the file otherwise.
  const Tensor& at(const std::string& name, const std::vector<int>& shape) const;
};

/// FNV-1a, 64 bit (miner::fnv1a64).
using miner::fnv1a64;

/// Reads and checks `path`; `kind` is the expected "kind" (e.g. "sgan-weights").
/// Throws miner::Error naming the file and what is wrong with it.
TensorFile read_tensor_file(const std::string& path, const std::string& kind);
/// The same from the file's bytes; `origin` names them in messages.
TensorFile parse_tensor_file(const std::string& blob, const std::string& origin, const std::string& kind);

}  // namespace miner::heuristic
