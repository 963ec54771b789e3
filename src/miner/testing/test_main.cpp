// The one Catch2 runner every MINER test binary links (compiled once).
#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>

#include <cstdlib>

#include "miner/testing/property.hpp"

int main(int argc, char** argv) {
  // Property tests are deterministic by default (REQ-HARNESS-003): a fixed seed unless
  // the user sets RC_PARAMS (e.g. RC_PARAMS="seed=42 max_success=1000") to explore.
  miner::testing::user_rc_params() = std::getenv("RC_PARAMS") != nullptr;
  ::setenv("RC_PARAMS", miner::testing::kDefaultRcParams, /*overwrite=*/0);
  return Catch::Session().run(argc, argv);
}
