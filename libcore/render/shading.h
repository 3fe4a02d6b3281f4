// Hair and head reflectance, on the CPU. The renderer's shaders evaluate the same formulas; tests
// compare the two pixel by pixel.
//
// Kajiya-Kay (thesis §3.3.2.1.1, DESIGN §7), t the unit tangent, l and e unit vectors to the light and
// the eye:
//   diffuse  = sin(t, l) = sqrt(1 − (t·l)²)
//   specular = max(cos(θ − φ), 0)^p with cos θ = −t·l, cos φ = t·e: the mirror cone, brightest where
//              the eye sees the light's reflection off the cylinder;
//   `thesis` = the thesis' shader, (|t·l| |t·e| + sin(t,l) sin(t,e))^p, which lights both sides.
//   `anjyo`  = Anjyo et al. 1992 (8): specular k_s (1 − (t·h)²)^{p/2}, h the halfway vector, no diffuse;
//   `volumetric` = Petrovic et al. 2005 §4: the strand shaded as a surface with the stored volume
//              normal n, diffuse max(n·l, 0) and a Phong specular max(r·e, 0)^p with r = l mirrored
//              about n; the colour is mixed with Kajiya-Kay's by VolumetricBlend (0 = Kajiya-Kay).
//   colour   = AmbientIntensity·AmbientColor + shadow·LightColor·(DiffuseColor·diffuse +
//   SpecularColor·specular)
// A strand's per-vertex colour, where the cache has one, multiplies AmbientColor and DiffuseColor.
// Head: AmbientIntensity·HeadColor + shadow·LightColor·HeadColor·max(n·l, 0).
// `shadow` is the light that arrives: 1 − (1 − kShadowFloor)·opacity (the thesis maps opacity [0, 1]
// to [1, 0.25]).
#pragma once

#include <glm/glm.hpp>

#include "libcore/config/params.h"
#include "libcore/render/shader_interface.h"

namespace hairgen {

// `n` is the strand's stored normal; only `volumetric` reads it.
glm::dvec3 shadeHair(ShadingModel model, const glm::dvec3& t, const glm::dvec3& n, const glm::dvec3& l,
                     const glm::dvec3& e, const Visuality& visuality, const RenderSettings& render,
                     double shadow);

inline double shadowFactor(double opacity) {
  return 1.0 - (1.0 - double(kShadowFloor)) * glm::clamp(opacity, 0.0, 1.0);
}

}  // namespace hairgen
