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

/// Whether the user set RC_PARAMS (test_main.cpp records it before it fills in the default).
/// Then every property runs the user's max_success, its own Cases included, so a replay line
/// and a `long` run with many cases mean what they say.
inline bool& user_rc_params() {
  static bool set = false;
  return set;
}

/// A property's own case count where one case is expensive (a closed-loop flight, a generated
/// map): `reason` says why the count suffices, for the reader of the test. The `long` label
/// runs every property binary with 1000 cases (properties/CMakeLists.txt).
struct Cases {
  int count;
  const char* reason;
};

/// The parameters a property runs with: the configured ones, with `cases` as max_success
/// unless the user set RC_PARAMS.
inline rc::detail::TestParams property_params(const Cases* cases) {
  rc::detail::TestParams params = rc::detail::configuration().testParams;
  if (cases != nullptr && !user_rc_params()) params.maxSuccess = cases->count;
  return params;
}

template <typename Testable>
void property(const std::string& description, const Cases* cases, Testable&& testable) {
  SECTION(description) {
    const rc::detail::TestParams params = property_params(cases);
    const auto result = rc::detail::checkTestable(std::forward<Testable>(testable), rc::detail::TestMetadata{}, params);
    if (result.template is<rc::detail::SuccessResult>()) {
      SUCCEED();
    } else {
      std::ostringstream ss;
      rc::detail::printResultMessage(result, ss);
      ss << "\nrapidcheck seed " << params.seed << ", max_success " << params.maxSuccess
         << "\nreplay: RC_PARAMS=\"seed=" << params.seed << " max_success=" << params.maxSuccess
         << "\" <test binary> \"" << Catch::getResultCapture().getCurrentTestName() << "\"";
      INFO(ss.str());
      FAIL();
    }
  }
}

template <typename Testable>
void property(const std::string& description, Testable&& testable) {
  property(description, static_cast<const Cases*>(nullptr), std::forward<Testable>(testable));
}

/// A property with its own case count (see Cases).
template <typename Testable>
void property(const std::string& description, const Cases& cases, Testable&& testable) {
  property(description, &cases, std::forward<Testable>(testable));
}

}  // namespace miner::testing
