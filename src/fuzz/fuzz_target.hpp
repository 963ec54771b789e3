#pragma once
/// \file
/// The shape every MINER libFuzzer target shares (issue 20 item 2): the input is handed to one
/// parser; a miner::Error (the parser refusing the input, naming the fault) is the expected
/// outcome for bad bytes, anything else (a crash, a sanitizer report, another exception
/// escaping, a hang, an abort from a round-trip check) is a finding.

#include <cstddef>
#include <cstdint>
#include <string>

#include "miner/core/error.hpp"

/// Defines LLVMFuzzerTestOneInput running `body(text)` on the input as a string and
/// swallowing miner::Error only.
#define MINER_FUZZ_TARGET(body)                                                    \
  extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) { \
    const std::string text(reinterpret_cast<const char*>(data), size);             \
    try {                                                                          \
      body(text);                                                                  \
    } catch (const miner::Error&) {                                                \
    }                                                                              \
    return 0;                                                                      \
  }
