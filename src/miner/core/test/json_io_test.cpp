#include <catch2/catch.hpp>

#include <sys/stat.h>

#include <filesystem>
#include <functional>
#include <limits>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "miner/core/error.hpp"
#include "miner/core/json_io.hpp"
#include "miner/core/sha256.hpp"

using miner::Error;
using miner::Json;
using miner::JsonField;
using Catch::Matchers::Contains;
using Catch::Matchers::StartsWith;

namespace {
std::string read_all(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}
std::filesystem::path temp_dir(const std::string& name) {
  auto dir = std::filesystem::temp_directory_path() / ("miner_core_test_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}
}  // namespace

TEST_CASE("Malformed JSON names the file and the byte offset", "[REQ-CORE-003]") {
  CHECK_THROWS_WITH(miner::parse_json("{\"a\": [1, 2,, 3]}", "x.json"),
                    Contains("x.json: malformed JSON at byte 13"));
  CHECK_THROWS_WITH(miner::parse_json("{\"a\": NaN}", "y.json"), Contains("y.json: malformed JSON"));
  // The JSON library's own tag ("[json.exception.parse_error.101]") is not shown (issue 20):
  // the message names the file, the byte and what is wrong there.
  for (const char* bad : {"", "{\"a\": 1,}", "{\"a\": Infinity}", "\x01", "[1, 2"})
    CHECK_THROWS_WITH(miner::parse_json(bad, "w.json"), Contains("w.json: malformed JSON at byte") && !Contains("json.exception"));
  CHECK_THROWS_WITH(miner::parse_json("{\"a\": 1e999}", "z.json"),
                    Contains("z.json: the number 1e999 at byte 6 is beyond the largest double"));
  // A NUL byte ended the document for the JSON library: a valid one followed by a NUL and
  // garbage was read as valid (issue 20, fourth campaign).
  CHECK_THROWS_WITH(miner::parse_json(std::string("{\"a\": 1}\0{garbage", 17), "n.json"),
                    Contains("n.json: malformed JSON at byte 8: a NUL byte"));
  CHECK_THROWS_WITH(miner::parse_json(std::string("{\"a\": \"b\0c\"}", 12), "s.json"), Contains("at byte 8: a NUL byte"));
  CHECK(miner::parse_json("{\"a\": \"b\\u0000c\"}", "u.json")["a"].get<std::string>() == std::string("b\0c", 3));
  CHECK_THROWS_WITH(miner::read_json_file("/nonexistent/file.json"),
                    Contains("/nonexistent/file.json: cannot open file"));
}

TEST_CASE("A JSON file larger than kMaxJsonFileBytes is refused by its size before it is read", "[REQ-CORE-003]") {
  // A sparse file: its size is past the bound, its blocks are never written (nor read).
  const std::string path = (std::filesystem::temp_directory_path() / "miner_json_too_large.json").string();
  {
    std::ofstream(path) << "{}";
  }
  std::filesystem::resize_file(path, miner::kMaxJsonFileBytes + 1);
  CHECK_THROWS_WITH(miner::read_json_file(path),
                    Catch::Contains(path) && Catch::Contains("268435457 bytes") && Catch::Contains("larger than"));
  // At the bound it is read (and parsed: "{}" then NUL bytes, refused as such, not by size).
  std::filesystem::resize_file(path, 64);
  CHECK_THROWS_WITH(miner::read_json_file(path), !Catch::Contains("larger than"));
  std::filesystem::remove(path);
}

TEST_CASE("A key named twice in one object is refused, naming it", "[REQ-CORE-003]") {
  CHECK_THROWS_WITH(miner::parse_json(R"({"resolution": 0.25, "bounds": {}, "resolution": 0.5})", "m.json"),
                    Contains("m.json: resolution: the key appears twice"));
  CHECK_THROWS_WITH(miner::parse_json(R"({"a": {"b": 1, "c": {"d": 1, "d": 2}}})", "x.json"),
                    Contains("x.json: a.c.d: the key appears twice"));
  // Inside an array: the array's key and [] (issue 20, N14: was "[].min").
  CHECK_THROWS_WITH(miner::parse_json(R"({"obstacles": [{"min": 1}, {"min": 1, "min": 2}]})", "o.json"),
                    Contains("o.json: obstacles[].min: the key appears twice"));
  CHECK_THROWS_WITH(miner::parse_json(R"({"a": [[{"k": 1, "k": 2}]]})", "n.json"), Contains("n.json: a[][].k: the key"));
  // The same key in different objects, or in objects of an array, is fine.
  CHECK_NOTHROW(miner::parse_json(R"({"a": {"k": 1}, "b": {"k": 2}, "l": [{"k": 1}, {"k": 2}], "k": 3})", "ok.json"));
}

TEST_CASE("A file of another format given as JSON is named by its format", "[REQ-CORE-003]") {
  // Issue 20, ninth campaign C7: an OctoMap given as a region, problem or scenario got
  // "malformed JSON at byte 140: a NUL byte".
  const std::string dir = std::filesystem::temp_directory_path() / ("miner_json_formats_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto file = [&](const std::string& name, const std::string& bytes) {
    std::ofstream(dir + "/" + name, std::ios::binary) << bytes;
    return dir + "/" + name;
  };
  static const char kOctoMap[] = "# Octomap OcTree binary file\nid OcTree\n\0\1";
  CHECK_THROWS_WITH(miner::read_json_file(file("r.bt", std::string(kOctoMap, sizeof kOctoMap - 1))),
                    Contains("r.bt: is an OctoMap file (voxels), not a JSON document"));
  CHECK_THROWS_WITH(miner::read_json_file(file("c.json", "ply\nformat ascii 1.0\n")), Contains("c.json: is a point cloud"));
  CHECK_THROWS_WITH(miner::read_json_file(file("d.json", "# .PCD v0.7\n")), Contains("is a point cloud"));
  CHECK(miner::read_json_file(file("ok.json", "{\"ply\": 1}"))["ply"] == 1);
  // Text given directly (Python's from_json) is named the same way.
  CHECK_THROWS_WITH(miner::parse_json("# Octomap OcTree binary file\n", "<string>"), Contains("<string>: is an OctoMap file"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("A number the JSON library would not read as written is refused, naming it", "[REQ-CORE-003]") {
  // Issue 20, N13: 1e-400 was read as 0 before any range check saw it.
  CHECK_THROWS_WITH(miner::parse_json(R"({"robot_radius": 1e-400})", "s.json"),
                    Contains("s.json: the number 1e-400 at byte 17 is below the smallest normal double"));
  CHECK_THROWS_WITH(miner::parse_json(R"({"v": [1, -2.5e-320]})", "s.json"), Contains("-2.5e-320"));
  CHECK_THROWS_WITH(miner::parse_json(R"({"v": 1e400})", "s.json"), Contains("beyond the largest double"));
  // A long literal is shown by its start and its length (seventh campaign C1).
  CHECK_THROWS_WITH(miner::parse_json("{\"v\": 1" + std::string(400, '0') + "}", "s.json"),
                    Contains("the number 100000000000000000000000... (401 characters) at byte 6 is beyond the largest double"));
  // Zeros written any way, the smallest normal double and ordinary numbers are read.
  const miner::Json ok = miner::parse_json(R"({"a": 0, "b": -0.0, "c": 0e-500, "d": 2.3e-308, "e": -12.5e3, "k1e-400": "1e-400"})", "ok.json");
  CHECK(ok["c"].get<double>() == 0.0);
  CHECK(ok["d"].get<double>() == 2.3e-308);
  CHECK(ok["e"].get<double>() == -12500.0);
  CHECK(ok["k1e-400"] == "1e-400");  // inside strings nothing is a number
}

TEST_CASE("Text that is not JSON is called malformed where it stops being JSON", "[REQ-CORE-003]") {
  // Sixth campaign, U3: "hello world 0-1" was blamed on "the number 0-1 ... below the smallest
  // normal double"; the fault is at the first byte, and "0-1" is no number at all.
  CHECK_THROWS_WITH(miner::parse_json("hello world 0-1\n", "t.json"), Contains("t.json: malformed JSON at byte 1"));
  CHECK_THROWS_WITH(miner::parse_json("{\"a\": 0-1}", "t.json"), Contains("t.json: malformed JSON at byte"));
  // A misread number before the first syntax fault is still the fault named.
  CHECK_THROWS_WITH(miner::parse_json("[1e-400, x]", "t.json"), Contains("t.json: the number 1e-400 at byte 1"));
  CHECK_THROWS_WITH(miner::parse_json("[1, x, 1e-400]", "t.json"), Contains("t.json: malformed JSON at byte 5"));
}

TEST_CASE("first_difference names the first differing value by its dotted path, with both values", "[REQ-CORE-003]") {
  const Json a = Json::parse(R"({"seed": 1, "dims": [8, 8, 4], "o": {"k": "x", "m": true}})");
  CHECK(miner::first_difference(a, a).empty());
  Json b = a;
  b["dims"][2] = 8;
  CHECK(miner::first_difference(b, a) == "dims[2] is 8 in the one and 4 in the other");
  b = a;
  b["o"]["m"] = false;
  CHECK(miner::first_difference(b, a) == "o.m is false in the one and true in the other");
  b = a;
  b["o"].erase("k");
  CHECK(miner::first_difference(b, a) == "o.k is absent in the one and \"x\" in the other");
  b = a;
  b["new"] = 2;
  CHECK(miner::first_difference(b, a) == "new is 2 in the one and absent in the other");
  b = a;
  b["dims"] = {8, 8};  // arrays of other lengths are named whole
  CHECK(miner::first_difference(b, a) == "dims is [8,8] in the one and [8,8,4] in the other");
  CHECK(miner::first_difference(Json(1), Json("1")) == "the document is 1 in the one and \"1\" in the other");
}

TEST_CASE("Field access names the dotted path and the type found", "[REQ-CORE-003]") {
  const Json doc = miner::parse_json(
      R"({"bounds": {"min": [0, "a", 2], "max": [1, 2]}, "r": -1, "n": 2.5, "s": 3})",
      "m.json");
  const JsonField root(doc, "", "m.json");
  CHECK_THROWS_WITH(root.at("bounds").at("min").vec3(),
                    Contains("m.json: bounds.min[1]: expected a number, got string"));
  CHECK_THROWS_WITH(root.at("bounds").at("max").vec3(),
                    Contains("bounds.max: expected an array of 3 numbers [x, y, z], got 2 elements"));
  CHECK_THROWS_WITH(root.at("missing"), Contains("m.json: missing: missing required field"));
  CHECK_THROWS_WITH(root.at("r").positive_number(), Contains("r: must be positive, got -1"));
  CHECK_THROWS_WITH(root.at("n").integer(), Contains("n: expected an integer, got 2.5"));
  // One rule for every integer field: a whole number written as a real is refused as such
  // (sixteenth campaign F5: "order": 3.0 was read while "seed": 1.0 was refused).
  for (const char* text : {"3.0", "3e0", "-2.0"}) {
    const Json whole = miner::parse_json(std::string("{\"order\": ") + text + "}", "w.json");
    CHECK_THROWS_WITH(JsonField(whole, "", "w.json").at("order").integer(),
                      Contains("w.json: order: expected an integer, got ") && Contains("(write it without a decimal point or exponent)"));
  }
  CHECK(JsonField(miner::parse_json(R"({"order": 3})", "w.json"), "", "w.json").at("order").integer() == 3);
  Json with_inf = doc;  // a document built in code (not parsed) can hold an infinity
  with_inf["big"] = std::numeric_limits<double>::infinity();
  CHECK_THROWS_WITH(JsonField(with_inf, "", "m.json").at("big").number(), Contains("big: must be a finite number"));
  CHECK_THROWS_WITH(root.at("s").string(), Contains("s: expected a string, got number"));
  CHECK_THROWS_WITH(root.at("s").at("x"), Contains("s: expected an object, got number"));
  CHECK_THROWS_WITH(root.at("bounds").at("max").at(std::size_t{5}),
                    Contains("bounds.max[5]: index out of range (size 2)"));
  CHECK(root.at("bounds").at("max").at(std::size_t{1}).integer() == 2);
  CHECK_FALSE(root.has("missing"));
  CHECK(root.has("r"));
  const Json top = miner::parse_json("[1]", "t.json");
  CHECK_THROWS_WITH(JsonField(top, "", "t.json").fail("bad"), Contains("t.json: (top level): bad"));
}

TEST_CASE("Atomic write replaces a file whole and leaves no temporary file", "[REQ-CORE-004]") {
  const auto dir = temp_dir("atomic");
  const std::string path = (dir / "out.json").string();
  miner::write_file_atomic(path, "first\n");
  CHECK(read_all(path) == "first\n");
  miner::write_file_atomic(path, "second\n");
  CHECK(read_all(path) == "second\n");
  int entries = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    (void)e;
    ++entries;
  }
  CHECK(entries == 1);
}

TEST_CASE("Atomic write into a missing folder fails and leaves the old file intact", "[REQ-CORE-004]") {
  CHECK_THROWS_WITH(miner::write_file_atomic("/nonexistent-dir/out.json", "x"),
                    Contains("folder /nonexistent-dir does not exist"));
  const auto dir = temp_dir("atomic_fail");
  const std::string path = (dir / "good.json").string();
  miner::write_file_atomic(path, "good\n");
  // A folder where the file should go cannot be replaced by rename: the old content stays.
  const std::string blocked = (dir / "blocked").string();
  std::filesystem::create_directories(blocked + "/child");
  CHECK_THROWS_AS(miner::write_file_atomic(blocked, "new"), Error);
  CHECK(read_all(path) == "good\n");
  CHECK(std::filesystem::is_directory(blocked + "/child"));
}

TEST_CASE("Files written as one: a failure on any leaves every existing file as it was", "[REQ-CORE-004][REQ-CLI-003]") {
  const auto dir = temp_dir("atomic_many");
  const std::string a = (dir / "a.bt").string(), b = (dir / "b.json").string();
  miner::write_file_atomic(a, "old a\n");
  // The second target's folder is missing: the first must not have been replaced (issue 20:
  // `map scan` wrote --out, then failed on --map-out).
  CHECK_THROWS_WITH(miner::write_files_atomic({{a, "new a\n"}, {(dir / "missing" / "b.json").string(), "b\n"}}),
                    Contains("does not exist"));
  CHECK(read_all(a) == "old a\n");
  // A folder in the second target's place: found before any rename, the temporaries removed.
  std::filesystem::create_directories(b + "/child");
  CHECK_THROWS_WITH(miner::write_files_atomic({{a, "new a\n"}, {b, "b\n"}}), Contains("is a folder, not a file"));
  CHECK(read_all(a) == "old a\n");
  CHECK(std::filesystem::is_directory(b + "/child"));
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir)) ++entries;
  CHECK(entries == 2);  // a.bt and the folder b.json: no temporary left
  miner::write_files_atomic({{a, "new a\n"}, {(dir / "c.json").string(), "c\n"}});
  CHECK(read_all(a) == "new a\n");
  CHECK(read_all((dir / "c.json").string()) == "c\n");
}

TEST_CASE("Atomic write refuses a FIFO in the file's place and writes through a symbolic link", "[REQ-CORE-004]") {
  const auto dir = temp_dir("atomic_special");
  const std::string fifo = (dir / "pipe.json").string();
  REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
  // A rename would replace the FIFO with a plain file (issue 20: /dev/null as root).
  CHECK_THROWS_WITH(miner::write_file_atomic(fifo, "x\n"), Contains("pipe.json: exists and is not a regular file"));
  CHECK(std::filesystem::is_fifo(fifo));
  // A link to a FIFO is refused the same way; a link to a file replaces the file, the link kept.
  const std::string to_fifo = (dir / "to-pipe.json").string(), target = (dir / "target.json").string(),
                    link = (dir / "link.json").string();
  std::filesystem::create_symlink(fifo, to_fifo);
  CHECK_THROWS_WITH(miner::write_file_atomic(to_fifo, "x\n"), Contains("exists and is not a regular file"));
  miner::write_file_atomic(target, "old\n");
  std::filesystem::create_symlink(target, link);
  miner::write_file_atomic(link, "new\n");
  CHECK(std::filesystem::is_symlink(link));
  CHECK(read_all(target) == "new\n");
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir)) ++entries;
  CHECK(entries == 4);  // the FIFO, two links and the target: no temporary left
}

TEST_CASE("A folder write replaces only an earlier output of the same kind", "[REQ-CORE-004]") {
  namespace fs = std::filesystem;
  const auto dir = temp_dir("folder_kind");
  const std::string run = (dir / "run").string();
  const std::vector<std::pair<std::string, std::string>> first{{"summary.json", "{}\n"}, {"log.csv", "t\n"}};
  miner::write_folder_atomic(run, first);
  // An earlier output (same kind of files, one name in common) is replaced whole.
  miner::write_folder_atomic(run, {{"summary.json", "{\"again\": 1}\n"}, {"other.csv", "x\n"}});
  CHECK(read_all(run + "/summary.json") == "{\"again\": 1}\n");
  CHECK_FALSE(fs::exists(run + "/log.csv"));
  // A trailing slash names the same folder (sixteenth campaign F20: "run/: not a folder name").
  miner::write_folder_atomic(run + "/", first);
  CHECK(read_all(run + "/log.csv") == "t\n");
  miner::write_folder_atomic((dir / "fresh").string() + "//", first);
  CHECK(read_all((dir / "fresh" / "summary.json").string()) == "{}\n");
  for (const std::string& bad : {std::string("/"), std::string("."), std::string(".."), std::string("../")})
    CHECK_THROWS_WITH(miner::write_folder_atomic(bad, first), Contains("not a folder name"));
  // A user's folder is not: a file of another kind, a subfolder, or no name in common.
  const auto refused = [&](const std::string& name, const std::function<void(const fs::path&)>& make,
                           const std::string& why) {
    const fs::path victim = dir / name;
    fs::create_directories(victim);
    make(victim);
    CHECK_THROWS_WITH(miner::write_folder_atomic(victim.string(), first), Contains(why) && Contains("not replaced"));
    CHECK(fs::exists(victim / "keep"));
    CHECK_FALSE(fs::exists(victim / "summary.json"));
  };
  refused("txt", [](const fs::path& v) { std::ofstream(v / "keep") << "precious"; }, "holds \"keep\"");
  refused("sub", [](const fs::path& v) {
    std::ofstream(v / "summary.json.bak") << "x";
    fs::create_directories(v / "keep");
  }, "which this command does not write");
  const fs::path other = dir / "other";
  fs::create_directories(other);
  std::ofstream(other / "notes.json") << "{}";
  CHECK_THROWS_WITH(miner::write_folder_atomic(other.string(), first), Contains("holds none of the files"));
  CHECK(fs::exists(other / "notes.json"));
  // A link to an earlier output is followed, as for files: the folder it names is replaced and
  // the link kept (fourteenth campaign C6: the link itself was replaced by a new folder).
  const fs::path link = dir / "link";
  fs::create_directory_symlink(fs::path("run"), link);
  miner::write_folder_atomic(link.string(), {{"summary.json", "{\"through\": 1}\n"}, {"other.csv", "y\n"}});
  CHECK(fs::is_symlink(fs::symlink_status(link)));
  CHECK(read_all(run + "/summary.json") == "{\"through\": 1}\n");
  // ... and a link to a user's folder is refused as the folder itself would be.
  const fs::path to_other = dir / "to_other";
  fs::create_directory_symlink(fs::path("other"), to_other);
  CHECK_THROWS_WITH(miner::write_folder_atomic(to_other.string(), first), Contains("holds none of the files"));
  CHECK(fs::is_symlink(fs::symlink_status(to_other)));
  CHECK(fs::exists(other / "notes.json"));
}

TEST_CASE("A folder whose kind names its files keeps a user's file of the same extension: the write is refused",
          "[REQ-CORE-004]") {
  namespace fs = std::filesystem;
  const auto dir = temp_dir("folder_own_names");
  const std::string run = (dir / "run").string();
  miner::FolderMarker marker{"summary.json", "fmt-v1"};
  marker.own_name = [](const std::string& name) { return name == "summary.json" || name == "log.csv" || name == "page.html"; };
  const std::vector<std::pair<std::string, std::string>> first{{"summary.json", "{\"format\": \"fmt-v1\"}\n"}, {"log.csv", "t\n"}};
  miner::write_folder_atomic(run, first, marker);
  // Here the folders an older miner wrote, without a manifest: judged by the kind's names.
  const auto older = [&] { REQUIRE(fs::remove(dir / "run" / miner::kFolderManifest)); };
  older();
  // An own name the new output does not write (an earlier run's page) is replaced with the rest.
  std::ofstream(dir / "run" / "page.html") << "old page";
  miner::write_folder_atomic(run, first, marker);
  CHECK_FALSE(fs::exists(dir / "run" / "page.html"));
  older();
  // Seventeenth campaign F31: a user's notes.json in the folder was deleted, its extension being
  // one the outputs use. Now the folder is refused, naming the file, and nothing changes.
  std::ofstream(dir / "run" / "notes.json") << "precious";
  CHECK_THROWS_WITH(miner::write_folder_atomic(run, {{"summary.json", "{\"format\": \"fmt-v1\", \"x\": 2}\n"}}, marker),
                    Contains("holds \"notes.json\", a file this command never writes") && Contains("not replaced"));
  CHECK(read_all(run + "/notes.json") == "precious");
  CHECK(read_all(run + "/log.csv") == "t\n");
  CHECK(miner::foreign_entry_problem(run, marker, {}, {".json"}) != "");
  fs::remove(dir / "run" / "notes.json");
  CHECK(miner::foreign_entry_problem(run, marker, {}, {".json"}) == "");
  // A marker listing its files (figure folders' manifest "files"): those names are its own.
  miner::FolderMarker listed{"figures.json", "fig-v1", true, {}, nullptr, "files"};
  const std::string figs = (dir / "figs").string();
  miner::write_folder_atomic(figs, {{"a.svg", "<svg/>"}, {"figures.json", "{\"format\": \"fig-v1\", \"files\": [\"a.svg\"]}"}}, listed);
  std::ofstream(dir / "figs" / "mine.svg") << "user's drawing";
  CHECK_THROWS_WITH(miner::write_folder_atomic(figs, {{"b.svg", "<svg/>"}, {"figures.json", "{\"format\": \"fig-v1\"}"}}, listed),
                    Contains("\"mine.svg\""));
  fs::remove(dir / "figs" / "mine.svg");
  miner::write_folder_atomic(figs, {{"b.svg", "<svg/>"}, {"figures.json", "{\"format\": \"fig-v1\", \"files\": [\"b.svg\"]}"}}, listed);
  CHECK_FALSE(fs::exists(dir / "figs" / "a.svg"));
  CHECK(fs::exists(dir / "figs" / "b.svg"));
}

TEST_CASE("A marked folder lists what it wrote in SHA256SUMS, and only those bytes are replaced", "[REQ-CORE-004]") {
  namespace fs = std::filesystem;
  const auto dir = temp_dir("folder_manifest");
  const std::string run = (dir / "run").string();
  miner::FolderMarker marker{"summary.json", "fmt-v1"};
  marker.own_name = [](const std::string& name) { return name == "summary.json" || name == "region.json" || name == "log.csv"; };
  const std::vector<std::pair<std::string, std::string>> first{{"summary.json", "{\"format\": \"fmt-v1\"}\n"}, {"log.csv", "t\n"}};
  miner::write_folder_atomic(run, first, marker);
  // The manifest is sha256sum's format, sorted by name, and lists every file but itself.
  CHECK(read_all(run + "/SHA256SUMS") == miner::sha256_hex("t\n") + "  log.csv\n" +
                                            miner::sha256_hex("{\"format\": \"fmt-v1\"}\n") + "  summary.json\n");
  CHECK(miner::folder_manifest({{"b", "x"}, {"a", ""}}) ==
        "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855  a\n" + miner::sha256_hex("x") + "  b\n");
  // Rewriting the same output replaces it (same bytes, same manifest).
  miner::write_folder_atomic(run, first, marker);
  CHECK(read_all(run + "/log.csv") == "t\n");
  // Eighteenth campaign F1: a user's file under one of the kind's own names that this output
  // never wrote (region.json in a waypoint run's folder) was deleted with exit 0.
  std::ofstream(dir / "run" / "region.json") << "{\"mine\": 1}";
  CHECK_THROWS_WITH(miner::write_folder_atomic(run, first, marker),
                    Contains("\"region.json\", which the earlier output did not write") && Contains("not replaced"));
  CHECK(miner::foreign_entry_problem(run, marker, {}, {".json"}) != "");
  CHECK(read_all(run + "/region.json") == "{\"mine\": 1}");
  fs::remove(dir / "run" / "region.json");
  // ... and a file the output wrote but the user changed since (its figure redrawn) is kept too.
  std::ofstream(dir / "run" / "log.csv") << "edited\n";
  CHECK_THROWS_WITH(miner::write_folder_atomic(run, first, marker),
                    Contains("\"log.csv\" changed since the earlier output wrote it"));
  CHECK(read_all(run + "/log.csv") == "edited\n");
  // A listed file that is gone is no loss.
  fs::remove(dir / "run" / "log.csv");
  miner::write_folder_atomic(run, first, marker);
  CHECK(read_all(run + "/log.csv") == "t\n");
  // Nineteenth campaign F3: a file the kind never writes, listed in SHA256SUMS by the user, was
  // deleted: the manifest adds to the names rule, it does not replace it.
  std::ofstream(dir / "run" / "notes.txt") << "mine";
  std::ofstream(dir / "run" / "SHA256SUMS", std::ios::app) << miner::sha256_hex("mine") << "  notes.txt\n";
  CHECK_THROWS_WITH(miner::write_folder_atomic(run, first, marker), Contains("\"notes.txt\", a file this command never writes"));
  CHECK(read_all(run + "/notes.txt") == "mine");
  fs::remove(dir / "run" / "notes.txt");
  // sha256sum's CRLF lines and binary "*" marker are its own format (nineteenth campaign F1, F2).
  {
    const std::string manifest = read_all(run + "/SHA256SUMS");
    std::string crlf;
    for (const char c : manifest) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
    std::string star = manifest;
    for (std::size_t at = star.find("  "); at != std::string::npos; at = star.find("  ", at + 2)) star.replace(at, 2, " *");
    for (const std::string& variant : {crlf, star}) {
      std::ofstream(dir / "run" / "SHA256SUMS", std::ios::binary | std::ios::trunc) << variant;
      CHECK_NOTHROW(miner::write_folder_atomic(run, first, marker));
    }
  }
  // A manifest that is not one (a user's own SHA256SUMS) is refused, naming its line.
  std::ofstream(dir / "run" / "SHA256SUMS") << "my checksums\n";
  CHECK_THROWS_WITH(miner::write_folder_atomic(run, first, marker), Contains("SHA256SUMS: line 1 is not"));
  CHECK(read_all(run + "/SHA256SUMS") == "my checksums\n");
  // The file name is the folder's own: a writer may not give it.
  CHECK_THROWS_WITH(miner::write_folder_atomic((dir / "x").string(), {{"SHA256SUMS", ""}}, marker),
                    Contains("is the folder's manifest"));
  // Unmarked folders get no manifest.
  miner::write_folder_atomic((dir / "plain").string(), first);
  CHECK_FALSE(fs::exists(dir / "plain" / "SHA256SUMS"));
}

TEST_CASE("A replaced output keeps its permission bits", "[REQ-CORE-004]") {
  namespace fs = std::filesystem;
  const auto dir = temp_dir("keep_mode");
  // Eighteenth campaign F22: a private 0600 file and a 0700 run folder came back world-readable.
  const std::string file = (dir / "priv.json").string();
  miner::write_file_atomic(file, "{}\n");
  fs::permissions(file, fs::perms::owner_read | fs::perms::owner_write);
  miner::write_file_atomic(file, "{\"new\": 1}\n");
  CHECK(read_all(file) == "{\"new\": 1}\n");
  CHECK(fs::status(file).permissions() == (fs::perms::owner_read | fs::perms::owner_write));
  const std::string run = (dir / "run").string();
  miner::write_folder_atomic(run, {{"a.txt", "1"}});
  fs::permissions(run, fs::perms::owner_all);
  fs::permissions(run + "/a.txt", fs::perms::owner_read);
  miner::write_folder_atomic(run, {{"a.txt", "2"}, {"b.txt", "3"}});
  CHECK(read_all(run + "/a.txt") == "2");
  CHECK(fs::status(run).permissions() == fs::perms::owner_all);
  CHECK(fs::status(run + "/a.txt").permissions() == fs::perms::owner_read);
}

TEST_CASE("An output that is a dangling link is written into the link's target", "[REQ-CORE-004]") {
  namespace fs = std::filesystem;
  const auto dir = temp_dir("dangling_link");
  fs::create_directories(dir / "sub");
  // Eighteenth campaign F2: a live link was written through, a dangling one replaced by a file.
  fs::create_symlink("sub/none.json", dir / "dang.json");
  miner::write_file_atomic((dir / "dang.json").string(), "{}\n");
  CHECK(fs::is_symlink(fs::symlink_status(dir / "dang.json")));
  CHECK(read_all((dir / "sub" / "none.json").string()) == "{}\n");
  CHECK(miner::link_target((dir / "dang.json").string()) == (dir / "sub/none.json").string());
  // A link whose target's folder is missing is refused, naming both; the link stays.
  fs::create_symlink("gone/x.json", dir / "nowhere.json");
  CHECK_THROWS_WITH(miner::write_file_atomic((dir / "nowhere.json").string(), "{}"),
                    Contains("nowhere.json: a symbolic link to") && Contains("does not exist"));
  CHECK(fs::is_symlink(fs::symlink_status(dir / "nowhere.json")));
  // A loop is named as one, not followed for ever.
  fs::create_symlink("loop-b.json", dir / "loop-a.json");
  fs::create_symlink("loop-a.json", dir / "loop-b.json");
  CHECK_THROWS_WITH(miner::write_file_atomic((dir / "loop-a.json").string(), "{}"), Contains("more than 40 symbolic links"));
  // The same for a folder: a dangling link is written through where the target's folder
  // exists, and nothing is created elsewhere (nineteenth campaign F18: nodir/ds was made).
  fs::create_directory_symlink("sub/run", dir / "run-link");
  miner::write_folder_atomic((dir / "run-link").string(), {{"a.txt", "1"}});
  CHECK(read_all((dir / "sub" / "run" / "a.txt").string()) == "1");
  fs::create_directory_symlink("nodir/run", dir / "nowhere-run");
  CHECK_THROWS_WITH(miner::write_folder_atomic((dir / "nowhere-run").string(), {{"a.txt", "1"}}),
                    Contains("whose folder") && Contains("nodir does not exist"));
  CHECK_FALSE(fs::exists(dir / "nodir"));
  CHECK(miner::link_target((dir / "sub").string()) == (dir / "sub").string());
}

TEST_CASE("only_keys refuses an unknown key, naming it and the known ones", "[REQ-CORE-003]") {
  const Json doc = miner::parse_json(R"({"a": 1, "b": {"c": 2, "controler": 3}})", "k.json");
  const JsonField root(doc, "", "k.json");
  CHECK_NOTHROW(root.only_keys({"a", "b"}));
  CHECK_NOTHROW(root.only_keys({"b", "a", "z"}));
  CHECK_THROWS_WITH(root.only_keys({"a"}), Contains("k.json: b: unknown key, did you mean \"a\"? (known: a)"));
  CHECK_THROWS_WITH(root.at("b").only_keys({"c", "controller"}),
                    Contains("k.json: b.controler: unknown key, did you mean \"controller\"? (known: c, controller)"));
  // Nothing near enough: no suggestion.
  CHECK_THROWS_WITH(root.at("b").only_keys({"c", "gains"}), Contains("b.controler: unknown key (known: c, gains)"));
  CHECK(miner::edit_distance("controler", "controller") == 1);
  CHECK(miner::edit_distance("", "abc") == 3);
  CHECK(miner::edit_distance("kitten", "sitting") == 3);
  CHECK_THROWS_WITH(root.at("a").only_keys({"a"}), Contains("a: expected an object, got number"));
}

TEST_CASE("dump_json writes two-space indented JSON with a trailing newline", "[REQ-CORE-003]") {
  CHECK(miner::dump_json(Json{{"a", 1}}) == "{\n  \"a\": 1\n}\n");
}

TEST_CASE("dump_json never writes a number parse_json refuses: a subnormal is named by its JSON pointer",
          "[REQ-CORE-003]") {
  // Fifteenth campaign F10: save() wrote 1e-310 and load() of the same file refused it.
  const Json doc{{"obstacles", Json::array({Json{{"min", {0.0, 1e-310, 0.0}}}})}, {"t", 4e-320}};
  CHECK_THROWS_WITH(miner::dump_json(doc, "m.json"),
                    StartsWith("m.json: cannot be written: the number at /obstacles/0/min/1 (1e-310)") &&
                        Contains("below the smallest normal double"));
  CHECK_THROWS_WITH(miner::dump_json(Json{{"t", -4e-320}}), StartsWith("cannot be written: the number at /t"));
  CHECK_THROWS_WITH(miner::dump_json(Json(5e-324)), Contains("the number at / "));
  // Everything it writes, zeros, the smallest normal double and the largest included, reads back.
  const Json fine{{"z", 0.0}, {"nz", -0.0}, {"min", 2.2250738585072014e-308}, {"max", 1.7976931348623157e308}, {"i", -3}};
  CHECK(miner::parse_json(miner::dump_json(fine), "fine.json") == fine);
}

TEST_CASE("A path holding a NUL byte is refused, not opened cut short", "[REQ-CORE-003][REQ-CORE-004]") {
  // "good.json\0junk" would open (or replace) good.json: the system reads a path up to its NUL.
  const auto dir = temp_dir("nul_path");
  const std::string good = (dir / "good.json").string();
  miner::write_file_atomic(good, "{}\n");
  const std::string cut = good + std::string(1, '\0') + "junk";
  CHECK_THROWS_WITH(miner::read_file_bytes(cut, "map"),
                    Contains("cannot open map: the path holds a NUL byte at offset " + std::to_string(good.size())));
  CHECK_THROWS_WITH(miner::read_json_file(cut), Contains("NUL byte"));
  CHECK_THROWS_WITH(miner::write_file_atomic(cut, "replaced\n"), Contains("cannot open output file") && Contains("NUL byte"));
  CHECK_THROWS_WITH(miner::write_folder_atomic(cut, {{"a.txt", "x"}}), Contains("cannot open output folder") && Contains("NUL byte"));
  CHECK(read_all(good) == "{}\n");  // nothing was written through the cut path
}

TEST_CASE("An atomic folder holds plain names only and an atomic write names an empty or repeated file before writing",
          "[REQ-LIB-003][REQ-CORE-004]") {
  // Tenth campaign L20: "../x" and absolute names were written outside the folder; L18: an
  // empty name and one file given twice failed at the rename with "cannot replace file: Success".
  const std::filesystem::path dir = temp_dir("plain_names");
  const std::string out = (dir / "run").string();
  for (const std::string& name : std::vector<std::string>{"../escaped.txt", (dir / "abs.txt").string(), "sub/x.txt", "..", ""})
    CHECK_THROWS_WITH(miner::write_folder_atomic(out, {{"a.txt", "a"}, {name, "x"}}), Contains("not a plain name"));
  CHECK_FALSE(std::filesystem::exists(dir / "escaped.txt"));
  CHECK_FALSE(std::filesystem::exists(dir / "abs.txt"));
  CHECK_FALSE(std::filesystem::exists(out));
  miner::write_folder_atomic(out, {{"a.txt", "a"}});
  CHECK(std::filesystem::exists(out + "/a.txt"));
  CHECK_THROWS_WITH(miner::write_files_atomic({{"", "x"}}), Contains("empty name"));
  const std::string f = (dir / "f.txt").string();
  CHECK_THROWS_WITH(miner::write_files_atomic({{f, "1"}, {(dir / "." / "f.txt").string(), "2"}}), Contains("given twice"));
  CHECK_FALSE(std::filesystem::exists(f));
}
