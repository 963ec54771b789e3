#pragma once
/// \file
/// rapidcheck properties inside Catch2 test cases (REQ-HARNESS-003).
///
/// miner::testing::property("name", [](double x) { RC_ASSERT(...); }) runs like
/// rc::prop but, on failure, also prints the seed and the exact command line that
/// replays the failure.

#include <sstream>
#include <string>

#include <catch2/catch.hpp>
#include <rapidcheck.h>

namespace miner::testing {

/// The fixed default: seed 20261122, 100 cases per property.
inline constexpr const char* kDefaultRcParams = "seed=20261122 max_success=100";

template <typename Testable>
void property(const std::string& description, Testable&& testable) {
  SECTION(description) {
    const auto result = rc::detail::checkTestable(std::forward<Testable>(testable));
    if (result.template is<rc::detail::SuccessResult>()) {
      SUCCEED();
    } else {
      std::ostringstream ss;
      rc::detail::printResultMessage(result, ss);
      const auto& params = rc::detail::configuration().testParams;
      ss << "\nrapidcheck seed " << params.seed << ", max_success " << params.maxSuccess
         << "\nreplay: RC_PARAMS=\"seed=" << params.seed << " max_success=" << params.maxSuccess
         << "\" <test binary> \"" << Catch::getResultCapture().getCurrentTestName() << "\"";
      INFO(ss.str());
      FAIL();
    }
  }
}

}  // namespace miner::testing
