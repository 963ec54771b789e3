#pragma once
/// \file
/// Reading JSON files with messages that name the file and the field at fault, and
/// writing files atomically so a good file is never half-overwritten (REQ-CORE-003,
/// REQ-CORE-004).

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

namespace miner {

using Json = nlohmann::json;

/// The largest JSON file read (issue 20: a 2 GB file was read whole, then ran out of memory
/// naming nothing). MINER's largest documents, maps of ~10^5 boxes, are ~25 MB.
inline constexpr std::uintmax_t kMaxJsonFileBytes = std::uintmax_t{256} << 20;

/// Parses `path` as JSON. Throws Error naming the file on a missing file, a file larger than
/// kMaxJsonFileBytes (before reading it) or a syntax error (with the byte offset nlohmann
/// reports).
Json read_json_file(const std::string& path);
/// The message of a JSON library exception without the library's "[json.exception.kind.N] "
/// prefix (what users see names their file and field, not the library's internals).
std::string json_error_text(const std::exception& e);
/// The whole file as bytes; throws miner::Error "<path>: cannot open <what>" when it cannot
/// be opened.
std::string read_file_bytes(const std::string& path, const std::string& what = "file");
/// Throws miner::Error naming the path and both sizes when the file at `path` holds more than
/// kMaxJsonFileBytes (nothing when it cannot be sized: the read then names the fault).
void require_json_file_size(const std::string& path);
/// Throws miner::Error naming the path and the offset when it holds a NUL byte (the system
/// would open the path cut there); read_file_bytes and the atomic writers call it.
void require_path_without_nul(const std::string& path, const std::string& what);

/// The first (i, j), i < j, with docs[i] == docs[j]; nullopt when all differ. A campaign's
/// inputs given twice under two names (two files of one content, a map inlined once and
/// referenced once) are found by their documents (issue 20, fourth campaign).
std::optional<std::pair<std::size_t, std::size_t>> first_repeated(const std::vector<Json>& docs);

/// Parses JSON text; `origin` names it in messages (a path, or "<stdin>").
Json parse_json(const std::string& text, const std::string& origin);

/// Field access with the dotted path of the field in every message, e.g.
/// "map.json: bounds.min[2]: expected a number, got string".
class JsonField {
 public:
  JsonField(const Json& value, std::string path, std::string origin)
      : value_(&value), path_(std::move(path)), origin_(std::move(origin)) {}

  const Json& value() const { return *value_; }
  const std::string& path() const { return path_; }
  bool has(const std::string& key) const;

  JsonField at(const std::string& key) const;  ///< required member of an object
  JsonField at(std::size_t index) const;       ///< element of an array
  std::size_t array_size() const;              ///< requires an array

  double number() const;                ///< finite number
  double positive_number() const;       ///< finite and > 0
  /// A finite number in [lo, hi]; the message names the range and `unit` ("must be in [0, 5]
  /// m, got 1e9"). Every physical value a file gives has a range (issue 20: a goal tolerance
  /// of 1e9 m made every flight "reach" its goal).
  double number_in(double lo, double hi, const std::string& unit = "") const;
  /// The same for (lo, hi]: lo itself refused, and the message says so ("must be in (0, 5] m").
  double number_above(double lo, double hi, const std::string& unit = "") const;
  /// Member `key` as number_in(lo, hi, unit), or `fallback` when the object has no such key
  /// (an optional physical value: every file section's defaults).
  double number_in_or(const std::string& key, double fallback, double lo, double hi,
                      const std::string& unit = "") const;
  int integer() const;                  ///< an integer, written as one (3, not 3.0), in int's range
  std::string string() const;
  Eigen::Vector3d vec3() const;         ///< array of 3 finite numbers
  /// An object whose keys are all in `known` (REQ-CORE-003: no ignored unknown key);
  /// otherwise throws naming the first unknown key, the nearest known one when it is within
  /// max(2, length / 3) edits ("did you mean"), and the known ones.
  void only_keys(const std::vector<std::string>& known) const;

  /// The document is an object whose "format" is `tag`; otherwise throws naming what it is
  /// (the one format check of every file kind: map, region, scenario, vehicle).
  void require_format(const std::string& tag) const;
  /// Throws Error("<origin>: <path>: <message>").
  [[noreturn]] void fail(const std::string& message) const;

 private:
  const Json* value_;
  std::string path_;
  std::string origin_;
};

/// Levenshtein distance (insertions, deletions, substitutions): the "did you mean" of
/// JsonField::only_keys.
std::size_t edit_distance(const std::string& a, const std::string& b);
/// The candidate nearest to `word` by edit distance when it is near enough to be a misspelling
/// (fewer than max(2, |word| / 3) + 1 edits; the first of equals), else empty: the "did you
/// mean" of unknown keys, commands and options.
std::string nearest_name(const std::string& word, const std::vector<std::string>& candidates);

/// Where two documents first differ, as "field is A in the one and B in the other" with the
/// dotted path of the first differing value (objects compared key by key in order, arrays
/// element by element, "absent" for a missing key); empty when they are equal. How a merge
/// names the setting two parts disagree on.
std::string first_difference(const Json& one, const Json& other);

/// [x, y, z] as a JSON array: what JsonField::vec3 reads back.
Json vec3_json(const Eigen::Vector3d& v);

/// `text` quoted as JSON writes a string (a newline shown as \n, bytes that are not UTF-8
/// replaced), cut to its first 64 bytes and "..." when longer: a bad name shown in a message.
std::string quoted_excerpt(const std::string& text);

/// Writes `content` to `path` via a temporary file in the same folder and a rename,
/// so readers see either the old file or the complete new one, never a mix.
void write_file_atomic(const std::string& path, const std::string& content);
/// Several files written as one: every content goes to a temporary file beside its target
/// first, and only when all are written are they renamed into place, so a failure leaves every
/// existing file as it was (issue 20: `map scan` replaced --out, then failed on --map-out).
void write_files_atomic(const std::vector<std::pair<std::string, std::string>>& files);

/// Writes `files` (name, content) into the folder `path` as a whole: they are written to
/// a hidden sibling folder first, which then replaces `path` (the previous folder is moved
/// aside and removed only once the new one is in place), so a good run folder is never
/// half-overwritten. Creates missing parent folders. An existing folder is replaced only when
/// it looks like an earlier output of the same command: nothing but files, each with an
/// extension among the new files', and one name in common; otherwise it throws naming the
/// entry (a user's folder, the current folder, a folder holding the inputs are never replaced).
///
/// With a marker, "an earlier output" is told by content, not by names: the folder must hold
/// marker.file, a JSON object whose "format" is marker.format (issue 20, seventh campaign D1: a
/// user's own summary.json, by its name alone, let `fly --out` replace the folder). Where
/// by_name_fallback is set (figure folders written before they carried a manifest), a folder
/// without marker.file is judged by the names rule above. A marker of one of
/// marker.earlier_formats counts as the command's output too (a dataset of the previous format
/// is regenerated in place). With a marker the folder also gets kFolderManifest, and a folder
/// carrying one is replaced only when its files are the ones listed there, unchanged. The
/// replaced folder's and files' permission bits are kept.
struct FolderMarker {
  std::string file;
  std::string format;
  bool by_name_fallback = false;
  /// Earlier formats of the same output (an older miner's folder), replaced like marker.format.
  std::vector<std::string> earlier_formats = {};
  /// The names this kind of output writes in any run (a run folder's fixed names, a dataset's
  /// shard pattern). When set, an existing folder is replaced only if every file in it is one
  /// of these or one of the new files, whatever its extension (seventeenth campaign F31: a
  /// user's notes.json kept in a run folder was deleted for having the outputs' extension).
  std::function<bool(const std::string& name)> own_name = nullptr;
  /// A field of marker.file listing the earlier output's own file names (figure folders'
  /// "files"): those names count as its own too, with own_name's rule.
  std::string listed = {};
};

/// The manifest a marked output folder carries (write_folder_atomic writes it whenever a marker
/// is given): one line `<64 hex digits of SHA-256>  <name>` per file written, the folder's own
/// files sorted by name, the format `sha256sum` prints and `sha256sum -c SHA256SUMS` checks.
/// Replacing the folder later deletes only these bytes: a file it does not list, or one whose
/// bytes changed since, is a user's and the folder is refused (eighteenth campaign F1: a user's
/// region.json in a waypoint-run folder, a shard name the earlier dataset never wrote, a user's
/// file under a figure's name were deleted or overwritten with exit 0).
inline constexpr const char* kFolderManifest = "SHA256SUMS";
/// The manifest text for `files` (name, content).
std::string folder_manifest(const std::vector<std::pair<std::string, std::string>>& files);

/// The path `path` names once symbolic links are followed (each link's target read relative to
/// the link's folder), up to kMaxLinkHops links; `path` itself when it is no link. The result
/// may not exist (a dangling link's target). Throws naming the path on a longer chain (a loop).
/// Outputs are written through links into their targets, whether the target exists or not
/// (REQ-CORE-004; eighteenth campaign F2: a dangling link was replaced by a file).
inline constexpr int kMaxLinkHops = 40;
std::string link_target(const std::string& path);

/// Where an output written at `path` lands: `path` itself, or for a symbolic link the end of its
/// chain (link_target), lexically normal. Throws naming the link when the chain loops or the
/// target's folder does not exist: a dangling link is written through only where that folder
/// exists (eighteenth campaign F2, nineteenth F18). The atomic writers and the CLI's output
/// checks all follow links through it.
std::string output_target(const std::string& path);

/// The folder an output folder path names, lexically normal: "run/", "run//" and "run/." are
/// run (sixteenth campaign F20); "./" is ".". Empty for an empty path.
std::filesystem::path named_folder(const std::string& path);
/// Why `path` names no folder an output may replace whole (".", "..", "/", "x/.."), empty when
/// it names one: checked by write_folder_atomic and, before the work, by the CLI (nineteenth
/// campaign F19).
std::string folder_name_problem(const std::string& path);

/// Why the existing folder `path` holds something that is not part of an earlier output of the
/// command `marker` describes (empty when all of it is), naming the first such entry: anything
/// but a plain file; in a folder holding marker.file, with marker.own_name or marker.listed, a
/// file that is none of the command's names (own_name, the marker's list, `new_names`); else a
/// file whose extension is not in `extensions` (the names rule). Where the folder carries
/// kFolderManifest too, each file must also be listed there with the same SHA-256 (the manifest
/// adds to the names rule, never replaces it; a malformed manifest is refused). The marker's own content is judged
/// by folder_marker_problem.
std::string foreign_entry_problem(const std::string& path, const FolderMarker& marker,
                                  const std::set<std::string>& new_names, const std::set<std::string>& extensions);
void write_folder_atomic(const std::string& path, const std::vector<std::pair<std::string, std::string>>& files,
                         const FolderMarker& marker = {});
/// Why the existing non-empty folder `path` is not an earlier output marked by `marker` (empty
/// when it is, or when the marker is absent and by_name_fallback leaves the judgement to the
/// names rule): the marker part of write_folder_atomic's rule, for checks made before the work.
std::string folder_marker_problem(const std::string& path, const FolderMarker& marker);

/// Whether `path` is `folder` or lies inside it, both made absolute and canonical as far as
/// they exist (links and ".." resolved); false when either cannot be resolved. An output
/// folder that is replaced whole must not hold an input (issue 20).
bool is_same_or_inside(const std::string& folder, const std::string& path);

/// Whether `text` is a decimal number: optional sign, digits with an optional point, an
/// optional exponent ("1", "-0.5", ".5e3"); not hex ("0x10", "0x1p-2"), "inf" or "nan", which
/// strtod also reads (issue 20: `--size 0x10` was 16 m). Command-line numbers and text file
/// headers are read through it.
bool is_decimal_number(const std::string& text);

/// JSON text as the project writes it: 2-space indent, trailing newline. Throws miner::Error
/// (prefixed with `origin` when given) naming the JSON pointer of a number parse_json would
/// refuse to read back (nonzero, below the smallest normal double), so no writer saves a file
/// its reader refuses.
std::string dump_json(const Json& j, const std::string& origin = "");

}  // namespace miner
