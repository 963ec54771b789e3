#pragma once
/// \file
/// Errors a user can act on. Every failure that reaches the user is a miner::Error
/// whose message names the field, file or object at fault (REQ-CORE-002).

#include <stdexcept>
#include <string>

#include <Eigen/Core>

namespace miner {

/// Exit codes of the `miner` tool (REQ-CLI-002).
enum class ExitCode : int {
  kOk = 0,
  kInvalidInput = 1,  ///< a file, field or value is wrong
  kUsage = 2,         ///< the command line itself is wrong
  kNoSolution = 3,    ///< the input is valid but no path/trajectory exists
};

/// `text` with every control byte but newline and tab, and DEL, written as "\xNN": a message
/// quotes the user's text (a key, a name, a line of a file), and a NUL byte in it cut the
/// message there (issue 20, fourth campaign: `unknown obstacle type "bo`), other control
/// bytes drive the terminal.
std::string printable_text(const std::string& text);

/// An error caused by the user's input (a file, a field, a value). Its message is kept
/// printable (printable_text).
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& what, ExitCode code = ExitCode::kInvalidInput)
      : std::runtime_error(printable_text(what)), code_(code) {}
  ExitCode code() const { return code_; }

 private:
  ExitCode code_;
};

/// The input is valid but has no solution (e.g. the goal is unreachable).
class NoSolution : public Error {
 public:
  explicit NoSolution(const std::string& what) : Error(what, ExitCode::kNoSolution) {}
};

/// "(1, 2.5, 3)" — how points appear in messages.
std::string format_point(const Eigen::Vector3d& p);

/// Throws Error("<field>: must be finite, got nan") unless every entry of v is finite.
void require_finite(const Eigen::Vector3d& v, const std::string& field);
void require_finite(double v, const std::string& field);

}  // namespace miner
