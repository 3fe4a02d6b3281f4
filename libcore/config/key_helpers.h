// The helpers the config key declarations share: keys.cpp and one file per section, keys_setup.cpp,
// keys_hairstyle.cpp, keys_collision.cpp, keys_visuality.cpp, keys_render.cpp and keys_dynamics.cpp. Only
// those files include it.
#pragma once

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <iterator>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "libcore/config/keys.h"
#include "libcore/util/text.h"

namespace hairgen::keydecl {

inline std::string join(std::initializer_list<double> values) {
  std::string out;
  for (double v : values) out += (out.empty() ? "" : " ") + formatReal(v);
  return out;
}
inline std::string join(const glm::dvec3& v) {
  return join({v.x, v.y, v.z});
}

// Each section's keys, in declaration order (keys_SECTION.cpp).
Section<Setup> makeSetup();
Section<Hairstyle> makeHairstyle();
Section<Collision> makeCollision();
Section<Visuality> makeVisuality();
Section<RenderSettings> makeRender();
Section<Dynamics> makeDynamics();

}  // namespace hairgen::keydecl
