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

// Throws InputError (naming the file and line) where a stage asks more of the driver's compiler than a
// shader should: more than 256 KB; a statement of more than 1,024 tokens (macros expanded); nesting
// deeper than 64; a function-like macro; a function of more than 100,000 tokens with every call in it
// inlined. A driver's compiler took 6 GB for one statement of 5,000 additions and crashed at 20,000.
void requireBoundedStage(const CustomStage& stage);

// Reads the files the Setup names (its paths are already resolved), each bounded by
// requireBoundedStage. A file that cannot be read is an InputError naming it.
CustomShaders readCustomShaders(const Setup& setup);

}  // namespace hairgen
