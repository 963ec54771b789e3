#include "miner/heuristic/tensor_file.hpp"

#include <algorithm>

#include <cstdio>
#include <cstring>
#include <sstream>

#include "miner/core/error.hpp"

namespace miner::heuristic {

namespace {

constexpr char kMagic[8] = {'M', 'I', 'N', 'E', 'R', 'T', 'S', '1'};
/// A header is a few kB; a length beyond this means the file is not what it claims.
constexpr std::uint32_t kMaxHeaderBytes = 1u << 24;

std::string shape_text(const std::vector<int>& s) {
  std::string t = "[";
  for (std::size_t i = 0; i < s.size(); ++i) t += (i ? ", " : "") + std::to_string(s[i]);
  return t + "]";
}

}  // namespace

const Tensor& TensorFile::at(const std::string& name, const std::vector<int>& shape) const {
  const auto it = tensors.find(name);
  if (it == tensors.end()) throw Error(path + ": no tensor '" + name + "'");
  if (it->second.shape != shape)
    throw Error(path + ": tensor '" + name + "' has shape " + shape_text(it->second.shape) + ", expected " +
                shape_text(shape));
  return it->second;
}

TensorFile read_tensor_file(const std::string& path, const std::string& kind) {
  return parse_tensor_file(read_file_bytes(path, "the " + kind + " file"), path, kind);
}

TensorFile parse_tensor_file(const std::string& blob, const std::string& path, const std::string& kind) {
  if (blob.size() < 12 || std::memcmp(blob.data(), kMagic, 8) != 0)
    throw Error(path + ": not a miner-tensors-v1 file (bad magic)");
  std::uint32_t header_bytes = 0;
  for (int i = 3; i >= 0; --i) header_bytes = (header_bytes << 8) | static_cast<std::uint8_t>(blob[8 + static_cast<std::size_t>(i)]);
  if (header_bytes > kMaxHeaderBytes)
    throw Error(path + ": the header declares " + std::to_string(header_bytes) + " bytes, more than the " +
                std::to_string(kMaxHeaderBytes) + " a tensor file's header may have");
  if (12 + static_cast<std::size_t>(header_bytes) > blob.size())
    throw Error(path + ": truncated (the header runs past the end of the file)");
  TensorFile f;
  f.path = path;
  Json header;
  try {
    header = Json::parse(blob.substr(12, header_bytes));
  } catch (const std::exception& e) {
    throw Error(path + ": the header is not valid JSON (" + json_error_text(e) + ")");
  }
  const JsonField root(header, "", path);
  if (!header.is_object()) root.fail("the header is not a JSON object");
  root.only_keys({"format", "kind", "meta", "data_bytes", "data_fnv1a64", "tensors"});
  if (root.at("format").string() != "miner-tensors-v1") root.at("format").fail("expected miner-tensors-v1");
  f.kind = root.at("kind").string();
  if (f.kind != kind) root.at("kind").fail("expected '" + kind + "'");
  f.meta = header.contains("meta") ? header["meta"] : Json::object();
  const std::size_t data_start = 12 + header_bytes;
  const std::size_t data_bytes = blob.size() - data_start;
  const auto declared = static_cast<std::size_t>(root.at("data_bytes").integer());
  if (declared != data_bytes)
    throw Error(path + ": truncated or padded: " + std::to_string(data_bytes) + " data bytes, header says " +
                std::to_string(declared));
  const auto* data = reinterpret_cast<const std::uint8_t*>(blob.data()) + data_start;
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(fnv1a64(data, data_bytes)));
  if (root.at("data_fnv1a64").string() != hex)
    throw Error(path + ": checksum mismatch (the data was altered or the file is damaged)");
  const JsonField list = root.at("tensors");
  std::vector<std::pair<std::size_t, std::size_t>> spans;  // (first byte, end) of each tensor
  for (std::size_t t = 0; t < list.array_size(); ++t) {
    const JsonField e = list.at(t);
    e.only_keys({"name", "shape", "count", "offset"});
    const std::string name = e.at("name").string();
    Tensor tensor;
    std::size_t product = 1;
    const JsonField shape = e.at("shape");
    for (std::size_t d = 0; d < shape.array_size(); ++d) {
      const long long v = shape.at(d).integer();
      if (v < 1) shape.at(d).fail("must be >= 1");
      tensor.shape.push_back(static_cast<int>(v));
      product *= static_cast<std::size_t>(v);
    }
    const auto count = static_cast<std::size_t>(e.at("count").integer());
    const auto offset = static_cast<std::size_t>(e.at("offset").integer());
    if (count != product) e.at("count").fail("does not match the shape " + shape_text(tensor.shape));
    if (offset % 4 != 0) e.at("offset").fail("must be a multiple of 4 (float32 data), got " + std::to_string(offset));
    if (offset > data_bytes || count > (data_bytes - offset) / 4) e.at("offset").fail("the tensor runs past the data");
    spans.emplace_back(offset, offset + count * 4);
    tensor.values.resize(count);
    std::memcpy(tensor.values.data(), data + offset, count * 4);  // little-endian host (x86-64, arm64)
    if (!f.tensors.emplace(name, std::move(tensor)).second) e.at("name").fail("appears twice");
  }
  // The tensors tile the data: no two share a byte (issue 20: a bias aliased its weights) and
  // none is left over.
  std::sort(spans.begin(), spans.end());
  std::size_t end = 0;
  for (const auto& [first, last] : spans) {
    if (first < end) list.fail("two tensors overlap in the data (bytes " + std::to_string(first) + " to " +
                               std::to_string(end) + ")");
    if (first > end) list.fail("data bytes " + std::to_string(end) + " to " + std::to_string(first) + " belong to no tensor");
    end = last;
  }
  if (end != data_bytes) list.fail("data bytes " + std::to_string(end) + " to " + std::to_string(data_bytes) + " belong to no tensor");
  return f;
}

}  // namespace miner::heuristic
