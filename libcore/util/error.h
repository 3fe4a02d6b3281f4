// Typed errors of the hairgen library and the process exit codes they map to.
//
// Library code never prints and never exits: it throws one of the errors below, each carrying an
// optional file location, and the command-line front end catches it once and turns it into one line
// on stderr and an exit code.
#pragma once

#include <stdexcept>
#include <string>

namespace hairgen {

// The process exit codes, the same for every command (DESIGN §3), each declared once here with its
// meaning; `--help` lists them from this table.
#define HAIRGEN_EXIT_CODES(X)                                                   \
  X(kSuccess, 0, "success")                                                     \
  X(kWorkFailed, 1, "the work failed (I/O while writing, a numerical failure)") \
  X(kBadInput, 2, "bad usage or bad input (config, mesh, cache, command line)") \
  X(kNoDevice, 3, "no rendering device could be opened")                        \
  X(kDiffFailed, 4, "`hairgen diff` found the images or caches beyond the thresholds")

enum class ExitCode : int {
#define HAIRGEN_EXIT_ENUMERATOR(name, value, meaning) name = value,
  HAIRGEN_EXIT_CODES(HAIRGEN_EXIT_ENUMERATOR)
#undef HAIRGEN_EXIT_ENUMERATOR
};

struct ExitCodeInfo {
  ExitCode code;
  const char* meaning;
};
inline constexpr ExitCodeInfo kExitCodes[] = {
#define HAIRGEN_EXIT_INFO(name, value, meaning) {ExitCode::name, meaning},
    HAIRGEN_EXIT_CODES(HAIRGEN_EXIT_INFO)
#undef HAIRGEN_EXIT_INFO
};

// Where in a text file something was found. line == 0 means "the file as a whole".
struct FileLoc {
  std::string file;
  int line = 0;

  // "file:line", "file", or "" when nothing is known.
  std::string str() const;
};

// Base of every error the library throws. what() is "FILE:LINE: message" (or just the message).
class Error : public std::runtime_error {
 public:
  Error(ExitCode code, FileLoc where, const std::string& message);

  ExitCode code() const { return code_; }
  const FileLoc& where() const { return where_; }
  const std::string& message() const { return message_; }

 private:
  ExitCode code_;
  FileLoc where_;
  std::string message_;
};

// Something a user gave is wrong: a config value, a mesh, a cache file, an argument. Exit code 2.
class InputError : public Error {
 public:
  explicit InputError(const std::string& message) : Error(ExitCode::kBadInput, {}, message) {}
  InputError(FileLoc where, const std::string& message)
      : Error(ExitCode::kBadInput, std::move(where), message) {}
};

// A simulation left its validity (DESIGN §2): a step that overflowed, a constraint solve that did not
// converge, a hair stretched past its bound. The settings drove it there, so it is the input's fault:
// exit code 2, and the message names the keys, their values, the frame and the strand.
class SimulationDiverged : public InputError {
 public:
  explicit SimulationDiverged(const std::string& message) : InputError(message) {}
};

// Reading or writing failed for a reason outside the input's content (disk full, permissions). Exit 1.
class IoError : public Error {
 public:
  explicit IoError(const std::string& message) : Error(ExitCode::kWorkFailed, {}, message) {}
  IoError(FileLoc where, const std::string& message)
      : Error(ExitCode::kWorkFailed, std::move(where), message) {}
};

// A computation produced a non-finite or otherwise unusable result. Exit code 1.
class NumericError : public Error {
 public:
  explicit NumericError(const std::string& message) : Error(ExitCode::kWorkFailed, {}, message) {}
};

// No rendering device could be opened. Exit code 3.
class DeviceError : public Error {
 public:
  explicit DeviceError(const std::string& message) : Error(ExitCode::kNoDevice, {}, message) {}
};

// Runs `work` and returns what it returns; an InputError or IoError it throws that names no file is
// thrown again naming `file` (what a writer refuses names the file it would have written, what a stage
// refuses in a sequence names the frame's file). Errors that name a file pass unchanged.
template <class Work>
decltype(auto) namingFile(const std::string& file, Work&& work) {
  try {
    return work();
  } catch (const InputError& e) {
    if (!e.where().file.empty()) throw;
    throw InputError({file, 0}, e.message());
  } catch (const IoError& e) {
    if (!e.where().file.empty()) throw;
    throw IoError({file, 0}, e.message());
  }
}

}  // namespace hairgen
