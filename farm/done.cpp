#include "farm/done.h"

#include <cctype>

#include "libcore/io/exr_io.h"
#include "libcore/io/hair_io.h"
#include "libcore/util/error.h"

namespace hairgen::farm {

namespace fs = std::filesystem;

bool carriesDigest(const fs::path& file, const std::string& digest) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) return false;
  std::string ext = file.extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  try {
    if (ext == ".hair") return readHairProvenance(file).configDigest == digest;
    if (ext == ".exr") {
      for (const auto& [name, value] : readImageHeader(file).attributes)
        if (name == "hairgen:configDigest") return value == digest;
      return false;
    }
  } catch (const Error&) {
    return false;  // unreadable: a leftover of another run, redone
  }
  return true;
}

bool taskDone(const FarmTask& task, const std::string& digest) {
  for (const std::string& out : task.outputs)
    if (!carriesDigest(out, digest)) return false;
  return true;
}

std::vector<bool> doneTasks(const FarmPlan& plan) {
  std::vector<bool> done;
  for (const FarmTask& t : plan.tasks) done.push_back(taskDone(t, plan.configDigest));
  return done;
}

}  // namespace hairgen::farm
