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
  CHECK(miner::printable_text("\xe2\x82\xac \xf0\x9f\x9a\x81") == "\xe2\x82\xac \xf0\x9f\x9a\x81");  // 3- and 4-byte forms
}

TEST_CASE("An error's message shows bytes that are not UTF-8 as hex escapes", "[REQ-CORE-002]") {
  // Sixth campaign, U5: a .bt header line's raw 0xC0 0x95 went to the terminal.
  CHECK(miner::printable_text("a\xc0\x95z") == "a\\xc0\\x95z");           // overlong lead byte
  CHECK(miner::printable_text("\xff") == "\\xff");                          // never in UTF-8
  CHECK(miner::printable_text("x\xc3") == "x\\xc3");                        // cut short at the end
  CHECK(miner::printable_text("\xc3(") == "\\xc3(");                        // lead without continuation
  CHECK(miner::printable_text("\xed\xa0\x80") == "\\xed\\xa0\\x80");      // a surrogate
  CHECK(miner::printable_text("\xe0\x80\xaf") == "\\xe0\\x80\\xaf");      // overlong 3-byte
  CHECK(miner::printable_text("\xf4\x90\x80\x80") == "\\xf4\\x90\\x80\\x80");  // above U+10FFFF
  CHECK(miner::printable_text("\x80") == "\\x80");                          // a lone continuation byte
}
