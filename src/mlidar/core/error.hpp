#pragma once
// Kinds of error kept apart (STYLE.md habit 12): programmer errors assert;
// bad input throws InputError naming the file, the field and the fix; the CLI
// maps errors to exit codes (see ExitCode).
#include <stdexcept>
#include <string>

namespace mlidar {

/// Process exit codes of the mlidar CLI (public interface; never renumber).
enum class ExitCode : int {
  kOk = 0,         ///< the job ran and its result can be trusted
  kUntrusted = 1,  ///< the job ran but failed or its result should not be trusted
  kUsage = 2,      ///< bad command line or configuration, or an output that cannot be written
  kBadInput = 3,   ///< unreadable or invalid input data
};

/// Invalid or unreadable input. what() reads "FILE: FIELD: problem (fix)".
class InputError : public std::runtime_error {
 public:
  InputError(const std::string& file, const std::string& field, const std::string& problem);
  const std::string& file() const { return file_; }
  const std::string& field() const { return field_; }

 private:
  std::string file_;
  std::string field_;
};

/// A command line or configuration that cannot be acted on (exit code 2).
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// An output could not be written (disk full, no permission).
class OutputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace mlidar
