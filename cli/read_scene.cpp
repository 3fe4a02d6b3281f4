// Reading a job's meshes as its Setup says, fitting its collision shapes and judging the scene before
// any stage starts (README, Real heads).
#include <tbb/task_arena.h>

#include "cli/common.h"
#include "libcore/io/obj_io.h"
#include "libcore/util/resources.h"
#include "stages/preflight/estimate.h"
#include "stages/preflight/scene.h"
#include "stages/shade.h"

namespace hairgen::cli {

namespace {

// " (setup.txt:4)": where a config named a mesh, for the messages of its reading.
std::string namedAt(const PathRef& ref) {
  const std::string where = ref.where.str();
  return where.empty() ? "" : " (" + where + ")";
}

}  // namespace

Mesh readWick(const Config& config) {
  MeshReadOptions options;
  options.group = config.setup.wickGroup;
  options.allowPoints = true;
  options.conversion = config.setup.meshConversion;
  options.role = "WickModel" + namedAt(config.setup.wickModel);
  return readObj(config.setup.wickModel.path, options);
}

Mesh readHead(const Config& config) {
  MeshReadOptions options;
  options.conversion = config.setup.meshConversion;
  options.role = "HeadModel" + namedAt(config.setup.headModel);
  return readObj(config.setup.headModel.path, options);
}

Scene readScene(const CommonOptions& options, Config& config, bool needWick, bool needHead, Stats& stats) {
  Scene scene;
  bool fits = false;
  for (const CollisionShape& s : config.collision.shapes) fits = fits || s.fitted;
  fits = fits || (needWick && config.hairstyle.rootFlow.fitted);  // only grow leans follicles
  if ((needWick || fits) && config.setup.wickModel.given()) scene.wick = readWick(config);
  if ((needHead || fits) && config.setup.headModel.given()) scene.head = readHead(config);
  const std::string applied = config.setup.meshConversion.describe();
  if (!applied.empty()) stats.json()["meshConversion"] = applied;
  if (!scene.wick) return scene;
  if (fits) fitCollision(config.collision, *scene.wick, scene.head ? &*scene.head : nullptr);
  if (needWick) fitRootFlow(config.hairstyle, *scene.wick, scene.head ? &*scene.head : nullptr);
  std::string refusal;
  for (const SceneFinding& f : checkScene(config, *scene.wick, scene.head ? &*scene.head : nullptr)) {
    if (f.refuse && refusal.empty())
      refusal = f.message;
    else
      note(options, "warning: " + f.message);
  }
  if (!refusal.empty()) {
    // The memory the implausible scene would take, so that the refusal says what it saved.
    uint64_t bytes = 0;
    for (const WorkEstimate& e : estimateRun(config, *scene.wick, wantsShade(config.visuality, config.render),
                                             true, size_t(tbb::this_task_arena::max_concurrency())))
      bytes = std::max(bytes, e.bytes);
    refusal += " (the work would need about " + formatBytes(bytes) + " of memory)";
    if (!options.force) throw InputError(refusal + "; pass --force to run it anyway");
    note(options, "warning: " + refusal + "; running it anyway (--force)");
  }
  return scene;
}

}  // namespace hairgen::cli
