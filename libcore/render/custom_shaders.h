// A Setup's custom shader files (HairVert, HairFrag, HeadVert, HeadFrag): GLSL that takes the place of
// one of hairgen's shader stages. What a file must declare, and what hairgen puts in front of it, is
// in stages/render.h and the README (Custom shaders).
#pragma once

#include <optional>
#include <string>

#include "libcore/config/params.h"

namespace hairgen {

// One custom stage, read.
struct CustomStage {
  std::string text;     // the file's contents: GLSL without a #version line
  std::string file;     // its name in messages: "FILE:LINE: what the compiler said"
  std::string namedAt;  // where the Setup named it, e.g. "setup.txt:9"; may be empty
};

// An empty one keeps hairgen's own stage.
struct CustomShaders {
  std::optional<CustomStage> hairVert, hairFrag, headVert, headFrag;
};

// Reads the files the Setup names (its paths are already resolved). A file that cannot be read is an
// InputError naming it.
CustomShaders readCustomShaders(const Setup& setup);

}  // namespace hairgen
