// Writes every shader stage hairgen compiles, as this machine's OpenGL is handed it, for the Khronos
// reference compiler to check (tests/glsl_reference_test.sh): Mesa's compiler, which CI has, accepts
// some GLSL the specification does not, and another driver (NVIDIA's) may refuse it. Every program of
// every render is built here, not drawn: each shading model, white and coloured hair, lines and ribbons,
// one sample and several, OpenGL's camera and the rasteriser's, the motion pass, hairgen's own stages as
// custom ones (a Setup's take their place with the same prelude), and the compute passes at every kept
// count the renderer builds them for.
//
// write_stages DIR: DIR/NNNN.{vert,frag,comp}, a file a distinct stage, and DIR/programs.txt, a line a
// distinct program: its stages' files, then its name. Exits 1, naming them, when a file of
// libcore/render/glsl/ is in none of the stages (a program this does not build); 3, saying why, where
// this machine's OpenGL cannot build them all (no context, or no GL_ARB_gpu_shader_int64 for the
// compute passes: the renderer draws with the CPU's rasteriser there).
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "glsl/embedded_glsl.h"
#include "libcore/render/camera_fragments.h"
#include "libcore/render/compute_raster.h"
#include "libcore/render/custom_shaders.h"
#include "libcore/render/gl_context.h"
#include "libcore/render/gl_resources.h"
#include "libcore/render/passes.h"
#include "libcore/util/error.h"

namespace fs = std::filesystem;
using namespace hairgen;

namespace {

// hairgen's own stages as a Setup's custom ones: the files each stage's reference is.
CustomShaders ownAsCustom() {
  auto custom = [](const char* text, const char* file) { return CustomStage{text, file, "write_stages"}; };
  CustomShaders c;
  c.hairVert = custom(glsl::kHairVertex, "hair_vertex.glsl");
  c.hairFrag = custom(glsl::kHairFragment, "hair_fragment.glsl");
  c.headVert = custom(glsl::kHeadVertex, "head_vertex.glsl");
  c.headFrag = custom(glsl::kHeadFragment, "head_fragment.glsl");
  return c;
}

const char* extension(GLenum type) {
  return type == GL_VERTEX_SHADER ? "vert" : type == GL_FRAGMENT_SHADER ? "frag" : "comp";
}

// A program's stages by their files' names, and its name.
struct Linked {
  std::vector<std::string> files;
  std::string name;
};

int run(const fs::path& dir) {
  fs::create_directories(dir);
  std::map<std::pair<GLenum, std::string>, std::string> stages;  // a distinct stage: its file's name
  std::set<std::vector<std::string>> linked;                     // programs, each once
  std::vector<Linked> programs;
  Linked building;  // the program whose stages are being handed over
  auto finish = [&] {
    if (!building.files.empty() && linked.insert(building.files).second) programs.push_back(building);
    building = {};
  };
  watchStages([&](GLenum type, const StageSource& s, const char* program) {
    auto [at, added] = stages.try_emplace({type, s.text});
    if (added) {
      char name[32];
      std::snprintf(name, sizeof name, "%04zu.%s", stages.size(), extension(type));
      at->second = name;
      std::ofstream(dir / at->second, std::ios::binary) << s.text;
    }
    // A vertex stage, or a compute one, begins a program; a fragment stage ends the one its vertex began.
    if (type != GL_FRAGMENT_SHADER) finish();
    building.name = program;
    building.files.push_back(at->second);
    if (type != GL_VERTEX_SHADER) finish();
  });
  GlContext gl;
  if (!computeRasterAvailable()) {
    std::fprintf(stderr,
                 "write_stages: this OpenGL has no GL_ARB_gpu_shader_int64: no compute passes to write\n");
    return 3;
  }
  const CustomShaders none, custom = ownAsCustom();
  for (const CustomShaders* shaders : {&none, &custom})
    for (ShadingModel model : kShadingModels)
      for (bool colored : {false, true})
        for (bool rasterised : {false, true})
          for (bool ribbons : {false, true})
            for (int block : {1, 4}) Programs(ribbons, block, *shaders, true, model, colored, rasterised);
  for (int kept : {1, kKeptFragments, 255})
    if (const std::string failure = computePassesFailure(kept); !failure.empty()) {
      std::fprintf(stderr, "write_stages: %s\n", failure.c_str());
      return 1;
    }
  watchStages({});

  // programs.txt: a program a line, its stages' files then its name.
  std::ofstream list(dir / "programs.txt");
  for (const Linked& p : programs) {
    for (const std::string& file : p.files) list << file << ' ';
    list << p.name << '\n';
  }
  int missing = 0;
  for (const glsl::File& file : glsl::kFiles) {
    bool found = false;
    for (const auto& stage : stages) found = found || stage.first.second.find(file.text) != std::string::npos;
    if (!found) {
      std::fprintf(stderr, "write_stages: libcore/render/glsl/%s is in no stage built here\n", file.name);
      ++missing;
    }
  }
  std::printf("write_stages: %zu stages of %zu programs in %s\n", stages.size(), programs.size(),
              dir.c_str());
  return missing == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: write_stages DIR\n");
    return 2;
  }
  try {
    return run(argv[1]);
  } catch (const DeviceError& e) {
    std::fprintf(stderr, "write_stages: %s\n", e.what());
    return 3;  // no OpenGL here: the test is skipped
  } catch (const std::exception& e) {
    std::fprintf(stderr, "write_stages: %s\n", e.what());
    return 1;
  }
}
