#include "libcore/config/setup.h"

#include <algorithm>
#include <cmath>

#include "libcore/util/file_util.h"
#include "libcore/util/text.h"

namespace hairgen {
namespace {

ConfigText emptyText(const std::filesystem::path& setupFile, const char* what) {
  return ConfigText{std::string("(no ") + what + " file; defaults)", setupFile.parent_path(), {}};
}

void requireExisting(const PathRef& ref, const char* key) {
  std::error_code ec;
  if (!std::filesystem::exists(ref.path, ec))
    throw InputError(ref.where, std::string(key) + " names '" + ref.path.string() +
                                    "', which does not exist (" +
                                    (ref.where.line == 0 ? "a --set path is relative to the current folder"
                                                         : "paths are relative to the file that names them") +
                                    ")");
  if (std::filesystem::is_directory(ref.path, ec))
    throw InputError(ref.where,
                     std::string(key) + " names '" + ref.path.string() + "', which is a directory");
}

}  // namespace

Config loadConfig(const std::filesystem::path& setupFile, const std::vector<Override>& overrides,
                  SetupUse use) {
  Config config;
  config.setup = readSetup(readConfigText(setupFile), overrides);
  const Setup& s = config.setup;
  // Every file the Setup names must exist. The Info files enter the digest by their values; the
  // others (`byContent`), whose bytes shape the output, by their content (below).
  struct Named {
    const PathRef* ref;
    const char* key;
    bool byContent;
  };
  const Named named[] = {{&s.hairstyleInfo, "HairstyleInfo", false},
                         {&s.collisionInfo, "CollisionInfo", false},
                         {&s.visualityInfo, "VisualityInfo", false},
                         {&s.renderInfo, "RenderInfo", false},
                         {&s.dynamicsInfo, "DynamicsInfo", false},
                         {&s.wickModel, "WickModel", true},
                         {&s.headModel, "HeadModel", true},
                         {&s.hairVert, "HairVert", true},
                         {&s.hairFrag, "HairFrag", true},
                         {&s.headVert, "HeadVert", true},
                         {&s.headFrag, "HeadFrag", true}};
  // check judges a Setup as run reads it where it grows (it names a wick or a Hairstyle Info) or names
  // nothing at all (an empty file is no job); one that names neither, but a Render Info or a head, is a
  // render's (`render --hair`), and check takes it as such.
  const bool namesAnything =
      std::any_of(std::begin(named), std::end(named), [](const Named& n) { return n.ref->given(); });
  const bool checkedAsRun = use == SetupUse::kCheck && !s.load &&
                            (s.hairstyleInfo.given() || s.wickModel.given() || !namesAnything);
  bool grows = use == SetupUse::kGrow || use == SetupUse::kInterpolate ||
               (use == SetupUse::kRun && !s.load) || checkedAsRun;

  auto need = [&](const PathRef& ref, const char* key, const char* why) {
    if (!ref.given())
      throw InputError({setupFile.string(), 0},
                       std::string("missing required key '") + key + "' (" + why + ")");
  };
  if (grows) {
    need(s.hairstyleInfo, "HairstyleInfo", "path of the Hairstyle Info file");
    need(s.wickModel, "WickModel", "path of the wick OBJ");
  }
  for (const Named& n : named)
    if (n.ref->given()) requireExisting(*n.ref, n.key);
  if (s.load && (use == SetupUse::kRun || use == SetupUse::kCheck)) requireExisting(s.loadFile, "LoadFile");

  auto text = [&](const PathRef& ref, const char* what) {
    return ref.given() ? readConfigText(ref.path) : emptyText(setupFile, what);
  };
  if (s.hairstyleInfo.given() || grows)
    config.hairstyle = readHairstyle(text(s.hairstyleInfo, "Hairstyle Info"), overrides);
  config.collision = readCollision(text(s.collisionInfo, "Collision Info"), overrides);
  config.visuality = readVisuality(text(s.visualityInfo, "Visuality Info"), overrides);
  config.render = readRender(text(s.renderInfo, "Render Info"), overrides);
  config.dynamics = readDynamics(text(s.dynamicsInfo, "Dynamics Info"), overrides);
  config.dynamics.given = s.dynamicsInfo.given();
  // The inputs whose bytes shape the output, each by its content (Config::canonicalText). One that
  // cannot be read is left out here: the stage that reads it says why.
  auto byContent = [&](const PathRef& ref, const char* key) {
    if (!ref.given()) return;
    if (std::string content = contentDigest(ref.path); !content.empty())
      config.inputContent.emplace_back(key, std::move(content));
  };
  for (const Named& n : named)
    if (n.byContent) byContent(*n.ref, n.key);
  if (s.load) byContent(s.loadFile, "LoadFile");
  if (config.dynamics.given) byContent(config.dynamics.densityTarget, "DensityTarget");
  return config;
}

}  // namespace hairgen
