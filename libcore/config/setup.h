// Reading a whole job's configuration: the Setup file and the info files it names (DESIGN §4).
#pragma once

#include <filesystem>
#include <vector>

#include "libcore/config/keys.h"
#include "libcore/config/params.h"
#include "libcore/config/reader.h"

namespace hairgen {

// What the command about to run needs from the Setup.
enum class SetupUse {
  kGrow,         // hairstyle, collision and the wick
  kInterpolate,  // the same: density, clump and seed come from the hairstyle, triangles from the wick
  kRender,       // the coupe comes from the command line; visuality, render and the head
  kRun,          // everything the Setup's Load flag implies
  kCheck,        // every file the Setup names must exist
};

// Reads `setupFile` and every info file it names. A file that is named but missing, or a file the use
// needs that is not named, is an InputError at the Setup's line. Info files that are not named get
// their defaults (overrides still apply).
Config loadConfig(const std::filesystem::path& setupFile, const std::vector<Override>& overrides,
                  SetupUse use);

}  // namespace hairgen
