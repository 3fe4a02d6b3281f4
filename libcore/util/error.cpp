#include "libcore/util/error.h"

namespace hairgen {
namespace {

std::string withLocation(const FileLoc& where, const std::string& message) {
  std::string loc = where.str();
  return loc.empty() ? message : loc + ": " + message;
}

}  // namespace

std::string FileLoc::str() const {
  if (file.empty()) return {};
  return line > 0 ? file + ":" + std::to_string(line) : file;
}

Error::Error(ExitCode code, FileLoc where, const std::string& message)
    : std::runtime_error(withLocation(where, message)),
      code_(code),
      where_(std::move(where)),
      message_(message) {}

}  // namespace hairgen
