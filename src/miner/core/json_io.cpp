#include "miner/core/json_io.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

#include <unistd.h>

#include "miner/core/error.hpp"
#include "miner/core/sha256.hpp"
#include "miner/core/text.hpp"

namespace miner {

void require_path_without_nul(const std::string& path, const std::string& what) {
  // The operating system reads a path up to its first NUL: "a.json\0junk" would open a.json
  // (issue 20, fifth campaign: a path from a JSON field, written \u0000 there, was cut short).
  const std::size_t nul = path.find('\0');
  if (nul != std::string::npos)
    throw Error(path + ": cannot open " + what + ": the path holds a NUL byte at offset " + std::to_string(nul) +
                " (a path ends at its first NUL)");
}

std::string read_file_bytes(const std::string& path, const std::string& what) {
  require_path_without_nul(path, what);
  // A device or a pipe (/dev/zero, a FIFO) would be read without end: only regular files.
  std::error_code ec;
  if (std::filesystem::exists(path, ec) && !std::filesystem::is_regular_file(path, ec))
    throw Error(path + ": cannot open " + what + ": not a regular file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot open " + what);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void require_json_file_size(const std::string& path) {
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (!ec && size > kMaxJsonFileBytes)
    throw Error(path + ": holds " + std::to_string(size) + " bytes, larger than the " + std::to_string(kMaxJsonFileBytes) +
                " a JSON document may have (it is not read)");
}

Json read_json_file(const std::string& path) {
  require_path_without_nul(path, "file");
  require_json_file_size(path);
  return parse_json(read_file_bytes(path), path);
}

std::string json_error_text(const std::exception& e) {
  std::string text = e.what();
  // "[json.exception.parse_error.101] parse error at ...": the bracket names the library's
  // internals, not the user's file (issue 20); the rest says what is wrong.
  if (text.rfind("[json.exception.", 0) == 0) {
    const std::size_t close = text.find("] ");
    if (close != std::string::npos) text.erase(0, close + 2);
  }
  return text;
}

namespace {

/// A SAX pass that refuses an object naming a key twice, naming the key by its dotted path
/// ("obstacles[].min"): each open object's keys, and each open container's name (the key it
/// was reached by, with "[]" for an array, whose elements are reached by no key).
class DuplicateKeyCheck : public nlohmann::json_sax<Json> {
 public:
  explicit DuplicateKeyCheck(std::string origin) : origin_(std::move(origin)) {}
  bool null() override { return true; }
  bool boolean(bool) override { return true; }
  bool number_integer(number_integer_t) override { return true; }
  bool number_unsigned(number_unsigned_t) override { return true; }
  bool number_float(number_float_t, const string_t&) override { return true; }
  bool string(string_t&) override { return true; }
  bool binary(binary_t&) override { return true; }
  bool start_object(std::size_t) override {
    keys_.emplace_back();
    containers_.push_back(last_key_);
    return true;
  }
  bool key(string_t& k) override {
    last_key_ = k;
    if (!keys_.back().insert(last_key_).second) {
      std::string where;
      for (const std::string& c : containers_)
        if (!c.empty()) where += (where.empty() || c == "[]" ? "" : ".") + c;
      if (!where.empty()) where += ".";
      throw Error(origin_ + ": " + where + last_key_ + ": the key appears twice in one object (which one is meant?)");
    }
    return true;
  }
  bool end_object() override {
    keys_.pop_back();
    containers_.pop_back();
    last_key_.clear();
    return true;
  }
  bool start_array(std::size_t) override {
    containers_.push_back(last_key_ + "[]");
    last_key_.clear();
    return true;
  }
  bool end_array() override {
    containers_.pop_back();
    last_key_.clear();
    return true;
  }
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception&) override { return false; }

 private:
  std::string origin_;
  std::vector<std::set<std::string>> keys_;
  std::vector<std::string> containers_;
  std::string last_key_;
};

}  // namespace

Json parse_json(const std::string& text, const std::string& origin) {
  // Nesting deeper than any MINER document needs is refused before parsing: the JSON library
  // frees and prints nested values recursively, so 10^6 brackets would overflow the stack.
  constexpr int kMaxJsonDepth = 256;
  // The binary and text formats MINER reads elsewhere are named by their first bytes, not
  // reported as malformed JSON (issue 20, ninth campaign C7: an OctoMap given as a region,
  // problem or scenario, from a file or as Python text, got "malformed JSON ... a NUL byte").
  const auto starts_with = [&](const std::string& magic) { return text.compare(0, magic.size(), magic) == 0; };
  if (starts_with("# Octomap OcTree"))
    throw Error(origin + ": is an OctoMap file (voxels), not a JSON document: give it where a map is read "
                         "(`--map`, miner.Map.load)");
  if (starts_with("ply\n") || starts_with("ply\r\n") || starts_with("# .PCD"))
    throw Error(origin + ": is a point cloud (PLY or PCD), not a JSON document: `miner map import --cloud` reads it");
  int depth = 0;
  bool in_string = false;
  // The first number the JSON library would misread, kept until the parser has said whether the
  // text is JSON at all: "hello 0-1" is not JSON at byte 0, whatever "0-1" is (sixth campaign).
  std::string bad_number;
  std::size_t bad_number_byte = 0;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    // JSON text holds no NUL byte (inside a string it is written \u0000): the JSON library
    // takes one as the end of the input, so a valid document, a NUL and garbage was read as
    // the document alone (issue 20, fourth campaign).
    if (c == '\0')
      throw Error(origin + ": malformed JSON at byte " + std::to_string(i) +
                  ": a NUL byte (JSON text has none; inside a string it is written \\u0000)");
    if (in_string) {
      if (c == '\\') ++i;
      else if (c == '"') in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxJsonDepth)
        throw Error(origin + ": JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " levels at byte " +
                    std::to_string(i));
    } else if (c == ']' || c == '}') {
      --depth;
    } else if (c == '-' || (c >= '0' && c <= '9')) {
      // A number the JSON library would silently turn into 0 (1e-400), lose precision in
      // (a subnormal) or into infinity (1e400) is refused here, where its text is still known
      // (issue 20, N13: "robot_radius": 1e-400 was read as 0 before any range check).
      std::size_t end = i;
      bool nonzero = false, exponent = false;
      while (end < text.size() && (std::isdigit(static_cast<unsigned char>(text[end])) || text[end] == '-' ||
                                   text[end] == '+' || text[end] == '.' || text[end] == 'e' || text[end] == 'E')) {
        if (text[end] == 'e' || text[end] == 'E') exponent = true;
        if (!exponent && text[end] >= '1' && text[end] <= '9') nonzero = true;
        ++end;
      }
      const std::string token = text.substr(i, end - i);
      char* parsed_end = nullptr;
      const double v = std::strtod(token.c_str(), &parsed_end);
      // Only a whole token that reads as a number is judged here; "0-1" is left to the parser.
      const bool whole = parsed_end == token.c_str() + token.size();
      if (whole && bad_number.empty() &&
          ((nonzero && std::fabs(v) < std::numeric_limits<double>::min()) || std::isinf(v))) {
        // A long literal is shown by its start and length, not echoed whole (seventh campaign C1:
        // 400 digits in one message).
        constexpr std::size_t kShownDigits = 24;
        const std::string shown = token.size() <= kShownDigits
                                      ? token
                                      : token.substr(0, kShownDigits) + "... (" + std::to_string(token.size()) +
                                            " characters)";
        bad_number = "the number " + shown + " at byte " + std::to_string(i) + " is " +
                     (std::isinf(v) ? "beyond the largest double" : "below the smallest normal double (2.2e-308)") +
                     ": it would not be read as written";
        bad_number_byte = i;
      }
      i = end - 1;
    }
  }
  // An object that names a key twice is refused (issue 20: the JSON library keeps the last
  // one, so `"resolution": 0.25, "resolution": 0.5` silently read 0.5). A SAX pass of its own:
  // the library's callback parser scans the enclosing array at every object's end, which made
  // a map of 4e5 obstacles take a minute to read (ninth campaign C3); this pass is linear.
  DuplicateKeyCheck duplicates(origin);
  Json::sax_parse(text, &duplicates);  // a syntax error stops it; the parse below names it
  Json doc;
  try {
    doc = Json::parse(text);
  } catch (const Json::parse_error& e) {
    // The library counts bytes from 1 at the byte it stopped on; a misread number before it is
    // the first fault.
    if (!bad_number.empty() && bad_number_byte + 1 < e.byte) throw Error(origin + ": " + bad_number);
    throw Error(origin + ": malformed JSON at byte " + std::to_string(e.byte) + ": " + json_error_text(e));
  } catch (const Json::exception& e) {  // e.g. out_of_range.406: a number like 1e999
    if (!bad_number.empty()) throw Error(origin + ": " + bad_number);
    throw Error(origin + ": invalid JSON: " + json_error_text(e));
  }
  if (!bad_number.empty()) throw Error(origin + ": " + bad_number);
  return doc;
}

namespace {
const char* type_name(const Json& j) { return j.type_name(); }
}  // namespace

void JsonField::fail(const std::string& message) const {
  throw Error(origin_ + ": " + (path_.empty() ? std::string("(top level)") : path_) + ": " +
              message);
}

bool JsonField::has(const std::string& key) const {
  return value_->is_object() && value_->contains(key);
}

JsonField JsonField::at(const std::string& key) const {
  if (!value_->is_object()) fail(std::string("expected an object, got ") + type_name(*value_));
  const auto it = value_->find(key);
  const std::string child = path_.empty() ? key : path_ + "." + key;
  if (it == value_->end()) throw Error(origin_ + ": " + child + ": missing required field");
  return JsonField(*it, child, origin_);
}

namespace {
std::string difference_at(const Json& one, const Json& other, const std::string& path) {
  if (one == other) return {};
  const auto child = [&](const std::string& key) { return path.empty() ? key : path + "." + key; };
  if (one.is_object() && other.is_object()) {
    for (const auto& [key, value] : one.items()) {
      if (!other.contains(key)) return child(key) + " is " + value.dump() + " in the one and absent in the other";
      if (std::string d = difference_at(value, other.at(key), child(key)); !d.empty()) return d;
    }
    for (const auto& [key, value] : other.items())
      if (!one.contains(key)) return child(key) + " is absent in the one and " + value.dump() + " in the other";
  }
  if (one.is_array() && other.is_array() && one.size() == other.size())
    for (std::size_t i = 0; i < one.size(); ++i)
      if (std::string d = difference_at(one[i], other[i], path + "[" + std::to_string(i) + "]"); !d.empty()) return d;
  return (path.empty() ? std::string("the document") : path) + " is " + one.dump() + " in the one and " + other.dump() +
         " in the other";
}
}  // namespace

std::string first_difference(const Json& one, const Json& other) { return difference_at(one, other, ""); }

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

std::string nearest_name(const std::string& word, const std::vector<std::string>& candidates) {
  std::string nearest;
  std::size_t best = std::max<std::size_t>(2, word.size() / 3) + 1;
  for (const auto& c : candidates) {
    const std::size_t d = edit_distance(word, c);
    if (d < best) best = d, nearest = c;
  }
  return nearest;
}

void JsonField::only_keys(const std::vector<std::string>& known) const {
  if (!value_->is_object()) fail(std::string("expected an object, got ") + type_name(*value_));
  for (auto it = value_->begin(); it != value_->end(); ++it) {
    if (std::find(known.begin(), known.end(), it.key()) != known.end()) continue;
    std::string list;
    for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
    const std::string child = path_.empty() ? it.key() : path_ + "." + it.key();
    const std::string nearest = nearest_name(it.key(), known);
    throw Error(origin_ + ": " + child + ": unknown key" + (nearest.empty() ? "" : ", did you mean \"" + nearest + "\"?") +
                " (known: " + list + ")");
  }
}

std::size_t JsonField::array_size() const {
  if (!value_->is_array()) fail(std::string("expected an array, got ") + type_name(*value_));
  return value_->size();
}

JsonField JsonField::at(std::size_t index) const {
  const std::size_t n = array_size();
  const std::string child = path_ + "[" + std::to_string(index) + "]";
  if (index >= n) throw Error(origin_ + ": " + child + ": index out of range (size " +
                              std::to_string(n) + ")");
  return JsonField((*value_)[index], child, origin_);
}

double JsonField::number() const {
  if (!value_->is_number()) fail(std::string("expected a number, got ") + type_name(*value_));
  const double v = value_->get<double>();
  if (!std::isfinite(v)) fail("must be a finite number, got " + value_->dump());
  return v;
}

double JsonField::positive_number() const {
  const double v = number();
  if (!(v > 0.0)) fail("must be positive, got " + value_->dump());
  return v;
}

void JsonField::require_format(const std::string& tag) const {
  if (!value_->is_object()) fail("expected a JSON object with \"format\": \"" + tag + "\"");
  const std::string format = at("format").string();
  if (format != tag) at("format").fail("unknown format tag \"" + format + "\", expected \"" + tag + "\"");
}

double JsonField::number_in(double lo, double hi, const std::string& unit) const {
  const double v = number();
  if (v < lo || v > hi)
    fail("must be in [" + exact_number(lo) + ", " + exact_number(hi) + "]" + (unit.empty() ? "" : " " + unit) + ", got " +
         value_->dump());
  return v;
}

double JsonField::number_above(double lo, double hi, const std::string& unit) const {
  const double v = number();
  if (!(v > lo && v <= hi))
    fail("must be in (" + exact_number(lo) + ", " + exact_number(hi) + "]" + (unit.empty() ? "" : " " + unit) + ", got " +
         value_->dump());
  return v;
}

double JsonField::number_in_or(const std::string& key, double fallback, double lo, double hi,
                               const std::string& unit) const {
  return has(key) ? at(key).number_in(lo, hi, unit) : fallback;
}

int JsonField::integer() const {
  const double v = number();
  if (std::floor(v) != v) fail("expected an integer, got " + value_->dump());
  // One integer rule for every field (sixteenth campaign F5: "order": 3.0 and "dims": [8.0, ..]
  // were read, "seed": 1.0 and "run": 1.0 refused): an integer is written as one.
  if (!value_->is_number_integer())
    fail("expected an integer, got " + value_->dump() + " (write it without a decimal point or exponent)");
  // issue 20: "expected an integer, got 1000000000000" read as if the value were not whole.
  if (std::fabs(v) > 2147483647.0) fail("integer " + value_->dump() + " is out of range (at most 2147483647 in magnitude)");
  return static_cast<int>(v);
}

std::string JsonField::string() const {
  if (!value_->is_string()) fail(std::string("expected a string, got ") + type_name(*value_));
  return value_->get<std::string>();
}

Eigen::Vector3d JsonField::vec3() const {
  if (array_size() != 3) {
    fail("expected an array of 3 numbers [x, y, z], got " + std::to_string(value_->size()) +
         " elements");
  }
  return {at(std::size_t{0}).number(), at(std::size_t{1}).number(), at(std::size_t{2}).number()};
}

std::string quoted_excerpt(const std::string& text) {
  constexpr std::size_t kShown = 64;
  const bool cut = text.size() > kShown;
  return Json(cut ? text.substr(0, kShown) : text).dump(-1, ' ', false, Json::error_handler_t::replace) + (cut ? "..." : "");
}

Json vec3_json(const Eigen::Vector3d& v) { return Json::array({v.x(), v.y(), v.z()}); }

namespace {
/// The name of a temporary beside `target`: "." + the first kTemporaryStem bytes of its name +
/// "." + kind + "." + pid. Capped so that a legal name (up to 255 bytes) keeps a legal
/// temporary (issue 20: a 250-byte output name could never be written).
constexpr std::size_t kTemporaryStem = 64;
std::string temporary_name(const std::filesystem::path& target, const char* kind) {
  return "." + target.filename().string().substr(0, kTemporaryStem) + "." + kind + "." + std::to_string(::getpid());
}
}  // namespace

void write_files_atomic(const std::vector<std::pair<std::string, std::string>>& files) {
  namespace fs = std::filesystem;
  std::vector<std::pair<fs::path, fs::path>> moves;  // (temporary, target)
  std::error_code ec;
  const auto discard = [&] {
    for (const auto& [tmp, target] : moves) fs::remove(tmp, ec);
  };
  // An empty name and one file given twice are refused before anything is written (tenth
  // campaign L18: both failed at the rename with "cannot replace file: Success").
  std::set<std::string> distinct;
  for (const auto& file : files) {
    if (file.first.empty()) throw Error("output file: empty name");
    if (!distinct.insert(fs::path(file.first).lexically_normal().string()).second)
      throw Error(file.first + ": given twice in one atomic write");
  }
  for (const auto& [path, content] : files) {
    require_path_without_nul(path, "output file");
    const fs::path target(path);
    const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
    if (!fs::is_directory(dir, ec)) {
      discard();
      throw Error(path + ": folder " + dir.string() + " does not exist");
    }
    // What would make a rename fail is checked before any rename: a folder in the file's place.
    if (fs::is_directory(target, ec)) {
      discard();
      throw Error(path + ": is a folder, not a file");
    }
    // A rename replaces whatever has the name: a device, FIFO or socket there is refused
    // (issue 20: `--out /dev/null` as root replaced the device with a plain file), and a
    // symbolic link is written through (its target is replaced, the link kept).
    fs::path final_target = target;
    // A dangling link is written through too, into its target, when the target's folder
    // exists (eighteenth campaign F2: it was replaced by a file).
    try {
      final_target = output_target(path);
    } catch (const Error&) {
      discard();
      throw;
    }
    if (const auto st = fs::status(final_target, ec); fs::exists(st) && !fs::is_regular_file(st)) {
      discard();
      throw Error(path + ": exists and is not a regular file (a device, FIFO or socket); outputs are written as "
                         "regular files, which would replace it");
    }
    const fs::path target_dir = final_target.has_parent_path() ? final_target.parent_path() : fs::path(".");
    const fs::path tmp = target_dir / temporary_name(final_target, "tmp");
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) {
      discard();
      throw Error(path + ": cannot write (temporary file " + tmp.string() + ")");
    }
    moves.emplace_back(tmp, final_target);
    out << content;
    out.flush();
    if (!out) {
      out.close();
      discard();
      throw Error(path + ": write failed");
    }
    out.close();
    // A replaced file keeps its mode (eighteenth campaign F22: a private 0600 file came back 0644).
    if (const auto st = fs::status(final_target, ec); fs::is_regular_file(st)) fs::permissions(tmp, st.permissions(), ec);
  }
  for (const auto& [tmp, target] : moves) {
    fs::rename(tmp, target, ec);
    if (ec) {
      discard();
      throw Error(target.string() + ": cannot replace file: " + ec.message());
    }
  }
}

void write_file_atomic(const std::string& path, const std::string& content) { write_files_atomic({{path, content}}); }

namespace {
/// A folder marker's document: a small JSON file; anything large, unreadable or malformed is no
/// marker of ours (null).
Json marker_document(const std::filesystem::path& file) {
  constexpr std::uintmax_t kMaxMarkerBytes = 64u << 20;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec) || std::filesystem::file_size(file, ec) > kMaxMarkerBytes) return {};
  try {
    return parse_json(read_file_bytes(file.string()), file.string());
  } catch (const Error&) {
    return {};
  }
}
}  // namespace

std::string folder_marker_problem(const std::string& path, const FolderMarker& marker) {
  namespace fs = std::filesystem;
  if (marker.file.empty()) return {};
  std::error_code ec;
  const fs::path file = fs::path(path) / marker.file;
  const std::string not_ours = ": it is not an earlier output of this command, so it is not replaced (remove it or "
                               "choose another folder)";
  if (!fs::exists(file, ec))
    return marker.by_name_fallback ? std::string() : path + ": the folder exists and holds no " + marker.file + not_ours;
  std::string format;
  const Json doc = marker_document(file);
  if (doc.is_object() && doc.contains("format") && doc["format"].is_string()) format = doc["format"].get<std::string>();
  if (format == marker.format ||
      std::find(marker.earlier_formats.begin(), marker.earlier_formats.end(), format) != marker.earlier_formats.end())
    return {};
  return path + ": the folder holds " + marker.file + ", which is not a \"" + marker.format + "\" file (" +
         (format.empty() ? std::string("no such \"format\"") : "format \"" + format + "\"") + ")" + not_ours;
}

namespace {
/// The file names marker.listed gives in the folder's marker file (none when it is missing or
/// not such a list: folder_marker_problem judges the marker itself).
std::set<std::string> listed_names(const std::filesystem::path& folder, const FolderMarker& marker) {
  namespace fs = std::filesystem;
  std::set<std::string> listed;
  if (marker.listed.empty() || marker.file.empty()) return listed;
  const Json doc = marker_document(folder / marker.file);
  if (doc.is_object() && doc.contains(marker.listed) && doc[marker.listed].is_array())
    for (const Json& name : doc[marker.listed])
      if (name.is_string()) listed.insert(name.get<std::string>());
  return listed;
}
}  // namespace

std::string folder_manifest(const std::vector<std::pair<std::string, std::string>>& files) {
  std::map<std::string, std::string> sorted;
  for (const auto& [name, content] : files) {
    // sha256sum escapes such names; ours are plain, and one that is not is a program error.
    if (name.find_first_of("\n\\") != std::string::npos)
      throw Error(name + ": a file name with a newline or backslash cannot be listed in " + kFolderManifest);
    sorted[name] = sha256_hex(content);
  }
  std::string text;
  for (const auto& [name, hash] : sorted) text += hash + "  " + name + "\n";
  return text;
}

std::string link_target(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::path target(path);
  for (int hop = 0; fs::is_symlink(fs::symlink_status(target, ec)); ++hop) {
    if (hop == kMaxLinkHops)
      throw Error(path + ": a chain of more than " + std::to_string(kMaxLinkHops) + " symbolic links (a loop?)");
    const fs::path next = fs::read_symlink(target, ec);
    if (ec) throw Error(path + ": the symbolic link " + target.string() + " cannot be read: " + ec.message());
    target = next.is_absolute() ? next : target.parent_path() / next;
  }
  return target.string();
}

std::string output_target(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_symlink(fs::symlink_status(path, ec))) return path;
  fs::path real = fs::path(link_target(path)).lexically_normal();
  if (real.filename().empty() && real.has_relative_path()) real = real.parent_path();  // a link to "run/"
  const fs::path dir = real.has_parent_path() ? real.parent_path() : fs::path(".");
  if (!fs::is_directory(dir, ec))
    throw Error(path + ": a symbolic link to " + real.string() + ", whose folder " + dir.string() +
                " does not exist (outputs are written through links into their targets)");
  return real.string();
}

std::filesystem::path named_folder(const std::string& path) {
  std::filesystem::path p = std::filesystem::path(path).lexically_normal();
  if (!p.empty() && p.filename().empty() && p.has_relative_path()) p = p.parent_path();
  return p;
}

std::string folder_name_problem(const std::string& path) {
  const std::filesystem::path p = named_folder(path);
  if (!p.empty() && !p.filename().empty() && p.filename() != "." && p.filename() != "..") return {};
  std::error_code ec;
  return path + " is not a folder name (the output folder is replaced whole: name it, e.g. ../" +
         std::filesystem::current_path(ec).filename().string() + " for this one)";
}

namespace {
/// The manifest rule of foreign_entry_problem for a folder carrying kFolderManifest: empty when
/// every entry is the manifest or a plain file it lists with the same SHA-256.
std::string manifest_problem(const std::filesystem::path& folder, const std::string& not_ours) {
  namespace fs = std::filesystem;
  const fs::path file = folder / kFolderManifest;
  const std::string where = file.string();
  constexpr std::uintmax_t kMaxManifestBytes = 64u << 20;  // ~800,000 files, far past any output
  std::error_code ec;
  if (!fs::is_regular_file(file, ec) || fs::file_size(file, ec) > kMaxManifestBytes)
    return where + ": not a manifest this command wrote (not a plain file, or larger than 64 MiB): " + not_ours;
  std::map<std::string, std::string> listed;
  std::istringstream in(read_file_bytes(where));
  std::string line;
  for (std::size_t number = 1; std::getline(in, line); ++number) {
    // sha256sum's own variants: a CRLF line end, "*" before a name hashed in binary mode
    // (nineteenth campaign F1, F2).
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const bool hex = line.size() > 66 && std::all_of(line.begin(), line.begin() + 64, [](char c) {
                       return std::isdigit(static_cast<unsigned char>(c)) || (c >= 'a' && c <= 'f');
                     });
    const std::string name = hex ? line.substr(66) : std::string();
    if (!hex || (line.compare(64, 2, "  ") != 0 && line.compare(64, 2, " *") != 0) ||
        name.find('/') != std::string::npos || name == "." || name == ".." || !listed.emplace(name, line.substr(0, 64)).second)
      return where + ": line " + std::to_string(number) +
             " is not \"<64 hex digits>  <file name>\" naming a file once: not a manifest this command wrote: " +
             not_ours;
  }
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    const std::string name = entry.path().filename().string();
    if (name == kFolderManifest) continue;
    if (!entry.is_regular_file(ec) || entry.is_symlink(ec))
      return folder.string() + ": the folder holds \"" + name + "\", which is not a plain file (a folder, link, FIFO " +
             "or device; the command writes plain files only): " + not_ours;
    const auto it = listed.find(name);
    if (it == listed.end())
      return folder.string() + ": the folder holds \"" + name + "\", which the earlier output did not write (" +
             kFolderManifest + " does not list it; replacing the folder would delete it): " + not_ours;
    // Read in pieces: an output folder may hold files of gigabytes (nineteenth campaign F4).
    if (sha256_file_hex(entry.path().string()) != it->second)
      return folder.string() + ": \"" + name + "\" changed since the earlier output wrote it (its SHA-256 is not the one " +
             kFolderManifest + " lists; replacing the folder would lose the change): " + not_ours;
  }
  return {};
}
}  // namespace

std::string foreign_entry_problem(const std::string& path, const FolderMarker& marker,
                                  const std::set<std::string>& new_names, const std::set<std::string>& extensions) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path folder(path);
  const std::string not_ours =
      "it is not an earlier output of this command, so it is not replaced (remove it or choose another folder)";
  // A marked folder with a manifest lists every byte it may lose: each file must be listed
  // there, unchanged, and also be one of the kind's names below (nineteenth campaign F3: a
  // user's notes.txt the user had added to SHA256SUMS was deleted). One without a manifest is
  // an older miner's output, judged by names alone.
  const bool with_manifest = !marker.file.empty() && fs::is_regular_file(folder / marker.file, ec) &&
                             fs::symlink_status(folder / kFolderManifest, ec).type() != fs::file_type::not_found;
  if (with_manifest)
    if (std::string problem = manifest_problem(folder, not_ours); !problem.empty()) return problem;
  const std::set<std::string> listed = listed_names(folder, marker);
  // The kind's names judge a folder that carries its marker; the names rule stays for one
  // without (refused by folder_marker_problem unless by_name_fallback, which then judges by
  // extensions: a figure folder written before its manifest listed its files).
  const bool marked = !marker.file.empty() && fs::is_regular_file(folder / marker.file, ec);
  const bool by_names = marked && (marker.own_name || !listed.empty());
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    const std::string name = entry.path().filename().string();
    const bool plain = entry.is_regular_file(ec);
    if (with_manifest && name == kFolderManifest) continue;
    if (plain && by_names &&
        (new_names.count(name) || name == marker.file || listed.count(name) || (marker.own_name && marker.own_name(name))))
      continue;
    if (plain && !by_names && extensions.count(entry.path().extension().string())) continue;
    if (plain && by_names)
      return path + ": the folder exists and holds \"" + name + "\", a file this command never writes (replacing " +
             "the folder would delete it): " + not_ours;
    return path + ": the folder exists and holds \"" + name + "\", which this command does not write: " + not_ours;
  }
  return {};
}

void write_folder_atomic(const std::string& path, const std::vector<std::pair<std::string, std::string>>& given,
                         const FolderMarker& marker) {
  namespace fs = std::filesystem;
  std::vector<std::pair<std::string, std::string>> files = given;
  if (!marker.file.empty()) {
    for (const auto& f : given)
      if (f.first == kFolderManifest) throw Error(path + ": " + kFolderManifest + " is the folder's manifest, not a file to write");
    files.emplace_back(kFolderManifest, folder_manifest(given));
  }
  require_path_without_nul(path, "output folder");
  // "run/" names the folder run, as the shell's completion writes it (sixteenth campaign F20:
  // refused as "not a folder name").
  if (const std::string problem = folder_name_problem(path); !problem.empty()) throw Error(problem);
  // A symbolic link is followed, as for files (fourteenth campaign C6: `dataset --out LINK`
  // replaced the user's link with a new folder and left the folder it named as it was), only
  // where the target's folder exists (nineteenth campaign F18: the missing folders were
  // created, anywhere the link pointed).
  fs::path target = named_folder(output_target(named_folder(path).string()));
  if (const std::string problem = folder_name_problem(target.string()); !problem.empty())
    throw Error(path + ": a link to " + problem);
  const fs::path parent = target.has_parent_path() ? target.parent_path() : fs::path(".");
  std::error_code ec;
  fs::create_directories(parent, ec);
  if (ec || !fs::is_directory(parent)) throw Error(path + ": cannot create parent folder " + parent.string());
  // Every file is a plain name inside the folder (tenth campaign L20: "../x" and absolute names
  // were written outside it, past the replace-only-earlier-output rule).
  for (const auto& f : files) {
    const fs::path name(f.first);
    if (f.first.empty() || name.has_parent_path() || name.is_absolute() || f.first == "." || f.first == "..")
      throw Error(path + ": file name \"" + f.first + "\" is not a plain name inside the folder");
  }
  if (fs::exists(target, ec) && !fs::is_directory(target, ec))
    throw Error(path + ": exists and is not a folder; refusing to replace it");
  // Only an earlier output of the same kind is replaced (issue 20: `--out victim` deleted a
  // user's folder): every entry a plain file with an extension the new folder has, and one
  // name in common with it. Anything else is refused before any work is lost.
  if (fs::is_directory(target, ec) && !fs::is_empty(target, ec)) {
    std::set<std::string> names, extensions;
    for (const auto& f : files) {
      names.insert(f.first);
      extensions.insert(fs::path(f.first).extension().string());
    }
    if (const std::string problem = foreign_entry_problem(target.string(), marker, names, extensions); !problem.empty())
      throw Error(problem);
    bool common = false;
    for (const auto& entry : fs::directory_iterator(target, ec))
      common = common || names.count(entry.path().filename().string()) > 0;
    if (const std::string problem = folder_marker_problem(path, marker); !problem.empty()) throw Error(problem);
    const bool marked = !marker.file.empty() && fs::exists(target / marker.file, ec);
    if (!common && !marked)
      throw Error(path + ": the folder exists and holds none of the files this command writes: it is not an earlier "
                  "output of this command, so it is not replaced (remove it or choose another folder)");
  }
  const fs::path partial = parent / temporary_name(target, "partial");
  const fs::path old = parent / temporary_name(target, "old");
  fs::remove_all(partial, ec);
  if (!fs::create_directory(partial, ec)) throw Error(path + ": cannot create " + partial.string());
  try {
    for (const auto& [name, content] : files) {
      std::ofstream out(partial / name, std::ios::binary | std::ios::trunc);
      out << content;
      out.flush();
      if (!out) throw Error(path + ": writing " + name + " failed");
    }
  } catch (...) {
    fs::remove_all(partial, ec);
    throw;
  }
  // Swap: the old folder stays whole until the new one is complete and in place.
  const bool had_old = fs::exists(target, ec);
  // The replaced folder's modes are kept, its own and each rewritten file's (eighteenth campaign
  // F22: a private 0700 run folder came back 0755).
  if (had_old) {
    for (const auto& [name, content] : files)
      if (const auto st = fs::symlink_status(target / name, ec); fs::is_regular_file(st))
        fs::permissions(partial / name, st.permissions(), ec);
    fs::permissions(partial, fs::status(target, ec).permissions(), ec);
    fs::rename(target, old, ec);
    if (ec) {
      fs::remove_all(partial, ec);
      throw Error(path + ": cannot move the previous run folder aside");
    }
  }
  fs::rename(partial, target, ec);
  if (ec) {
    std::error_code ignored;
    if (had_old) fs::rename(old, target, ignored);
    fs::remove_all(partial, ignored);
    throw Error(path + ": cannot move the new run folder in place: " + ec.message());
  }
  if (had_old) fs::remove_all(old, ec);
}

bool is_same_or_inside(const std::string& folder, const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path outer = fs::weakly_canonical(fs::absolute(fs::path(folder), ec), ec);
  if (ec) return false;
  const fs::path inner = fs::weakly_canonical(fs::absolute(fs::path(path), ec), ec);
  if (ec) return false;
  return std::mismatch(outer.begin(), outer.end(), inner.begin(), inner.end()).first == outer.end();
}

bool is_decimal_number(const std::string& text) {
  std::size_t i = 0;
  const std::size_t n = text.size();
  if (i < n && (text[i] == '+' || text[i] == '-')) ++i;
  std::size_t digits = 0;
  while (i < n && std::isdigit(static_cast<unsigned char>(text[i]))) ++i, ++digits;
  if (i < n && text[i] == '.') {
    ++i;
    while (i < n && std::isdigit(static_cast<unsigned char>(text[i]))) ++i, ++digits;
  }
  if (digits == 0) return false;
  if (i < n && (text[i] == 'e' || text[i] == 'E')) {
    ++i;
    if (i < n && (text[i] == '+' || text[i] == '-')) ++i;
    std::size_t exponent = 0;
    while (i < n && std::isdigit(static_cast<unsigned char>(text[i]))) ++i, ++exponent;
    if (exponent == 0) return false;
  }
  return i == n;
}

std::optional<std::pair<std::size_t, std::size_t>> first_repeated(const std::vector<Json>& docs) {
  for (std::size_t j = 1; j < docs.size(); ++j)
    for (std::size_t i = 0; i < j; ++i)
      if (docs[i] == docs[j]) return std::pair{i, j};
  return std::nullopt;
}

namespace {
/// The JSON pointer and value of the first number of j that parse_json refuses to read back (a
/// nonzero magnitude below the smallest normal double); an empty pointer if none. `at` is j's own.
std::pair<std::string, double> first_unreadable_number(const Json& j, const std::string& at) {
  if (j.is_number_float()) {
    const double v = j.get<double>();
    if (v != 0.0 && std::fabs(v) < std::numeric_limits<double>::min()) return {at.empty() ? "/" : at, v};
  } else if (j.is_object()) {
    for (const auto& [key, value] : j.items())
      if (auto found = first_unreadable_number(value, at + "/" + key); !found.first.empty()) return found;
  } else if (j.is_array()) {
    for (std::size_t i = 0; i < j.size(); ++i)
      if (auto found = first_unreadable_number(j[i], at + "/" + std::to_string(i)); !found.first.empty()) return found;
  }
  return {};
}
}  // namespace

std::string dump_json(const Json& j, const std::string& origin) {
  // What is written is read back (fifteenth campaign F10: a region threshold or an obstacle
  // coordinate of 1e-310 was saved, and load() of the file refused it): a subnormal number,
  // which parse_json refuses because it keeps too few digits to be read as written, is refused
  // here, before any byte is written.
  if (const auto [at, v] = first_unreadable_number(j, ""); !at.empty())
    throw Error((origin.empty() ? std::string() : origin + ": ") + "cannot be written: the number at " + at + " (" +
                short_number(v) + ") is below the smallest normal double (2.2e-308), which no reader takes back as "
                "written: use 0");
  return j.dump(2) + "\n";
}

}  // namespace miner
