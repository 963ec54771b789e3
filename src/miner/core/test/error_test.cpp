#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

#include "miner/core/error.hpp"

using Catch::Matchers::Contains;

TEST_CASE("require_finite names the field and the bad value", "[REQ-CORE-002]") {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_WITH(miner::require_finite(nan, "speed"), Contains("speed: must be a finite number, got nan"));
  CHECK_THROWS_WITH(miner::require_finite(Eigen::Vector3d(0, INFINITY, 0), "start"),
                    Contains("start[1]: must be a finite number, got inf"));
  CHECK_NOTHROW(miner::require_finite(Eigen::Vector3d(1, 2, 3), "start"));
}

TEST_CASE("Errors carry the exit code of their kind", "[REQ-CORE-002]") {
  CHECK(miner::Error("x").code() == miner::ExitCode::kInvalidInput);
  CHECK(miner::NoSolution("y").code() == miner::ExitCode::kNoSolution);
  CHECK(miner::format_point(Eigen::Vector3d(1, 2.5, -3)) == "(1, 2.5, -3)");
}

TEST_CASE("An error's message keeps the user's control bytes visible and whole", "[REQ-CORE-002]") {
  // A NUL in a quoted key cut the printed message there (issue 20, fourth campaign).
  const std::string key = std::string("bo") + '\0' + "x\x1b[2J";
  const miner::Error e("m.json: unknown obstacle type \"" + key + "\"");
  CHECK(std::string(e.what()) == "m.json: unknown obstacle type \"bo\\x00x\\x1b[2J\"");
  CHECK(miner::printable_text("line one\n\tline two\x7f") == "line one\n\tline two\\x7f");
  CHECK(miner::printable_text("caf\xc3\xa9") == "caf\xc3\xa9");  // UTF-8 stays as it is
}
