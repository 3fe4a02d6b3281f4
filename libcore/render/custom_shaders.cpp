#include "libcore/render/custom_shaders.h"

#include "libcore/util/file_util.h"

namespace hairgen {

CustomShaders readCustomShaders(const Setup& setup) {
  auto read = [](const PathRef& ref) -> std::optional<CustomStage> {
    if (!ref.given()) return std::nullopt;
    return CustomStage{readFileText(ref.path), ref.path.string(), ref.where.str()};
  };
  return {read(setup.hairVert), read(setup.hairFrag), read(setup.headVert), read(setup.headFrag)};
}

}  // namespace hairgen
