// libFuzzer target: miner-tensors-v1 files, the sGAN weights and reference tensors
// (REQ-HEUR-006): header, JSON metadata, tensor table, sizes and checksum, and for weights the
// network they describe (every layer's shape checked before oneDNN sees it).
#include "fuzz_target.hpp"
#include "miner/heuristic/sgan.hpp"
#include "miner/heuristic/tensor_file.hpp"

namespace {
void parse(const std::string& text) {
  try {
    (void)miner::heuristic::parse_tensor_file(text, "fuzz", "sgan-reference");
  } catch (const miner::Error&) {
  }
  (void)miner::heuristic::Sgan::from_bytes(text, "fuzz");
}
}  // namespace

MINER_FUZZ_TARGET(parse)
