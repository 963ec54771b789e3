// libFuzzer target: `miner dataset --merge` and the split reader (REQ-HEUR-001, REQ-REPORT-006).
// The input is the files of two part folders, separated by kSeparator, in the order of kFiles;
// they are written to a scratch folder and merged. What merges must read back: every split
// with as many samples as the merged dataset.json says.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "fuzz_target.hpp"
#include "miner/heuristic/dataset.hpp"

namespace {

constexpr const char* kSeparator = "\n@@\n";
constexpr const char* kFiles[] = {"p0/dataset.json",     "p0/train-index.json", "p0/val-index.json",
                                  "p0/test-index.json",  "p0/train-00000.bin",  "p0/val-00000.bin",
                                  "p0/test-00000.bin",   "p1/dataset.json",     "p1/train-index.json",
                                  "p1/val-index.json",   "p1/test-index.json",  "p1/train-00001.bin"};

const std::filesystem::path& scratch() {
  static const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("miner_fuzz_dataset_" + std::to_string(::getpid()));
  return dir;
}

void parse(const std::string& text) {
  namespace fs = std::filesystem;
  fs::remove_all(scratch());
  fs::create_directories(scratch() / "p0");
  fs::create_directories(scratch() / "p1");
  std::size_t begin = 0;
  for (const char* name : kFiles) {
    if (begin > text.size()) break;
    const std::size_t end = std::min(text.find(kSeparator, begin), text.size());
    std::ofstream(scratch() / name, std::ios::binary) << text.substr(begin, end - begin);
    begin = end + std::string(kSeparator).size();
  }
  const std::string out = (scratch() / "merged").string();
  const miner::Json doc =
      miner::heuristic::merge_dataset_parts({(scratch() / "p0").string(), (scratch() / "p1").string()}, out);
  for (const char* split : {"train", "val", "test"})
    if (miner::heuristic::read_split(out, split).size() != doc["splits"][split]["count"].get<std::size_t>())
      std::abort();
}

}  // namespace

MINER_FUZZ_TARGET(parse)
