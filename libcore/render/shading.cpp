#include "libcore/render/shading.h"

#include <cmath>

namespace hairgen {

glm::dvec3 shadeHair(ShadingModel model, const glm::dvec3& t, const glm::dvec3& n, const glm::dvec3& l,
                     const glm::dvec3& e, const Visuality& visuality, const RenderSettings& render,
                     double shadow) {
  if (model == ShadingModel::kVolumetric) {
    const glm::dvec3 kajiyaKay = shadeHair(ShadingModel::kKajiyaKay, t, n, l, e, visuality, render, shadow);
    const double diffuse = std::max(glm::dot(n, l), 0.0);
    const double specular = std::pow(std::max(glm::dot(glm::reflect(-l, n), e), 0.0), visuality.glossiness);
    const glm::dvec3 volumetric =
        render.ambientIntensity * visuality.ambientColor +
        shadow * render.lightColor * (visuality.diffuseColor * diffuse + visuality.specularColor * specular);
    return glm::mix(kajiyaKay, volumetric, render.volumetricBlend);
  }
  if (model == ShadingModel::kAnjyo) {
    const double th = glm::dot(t, glm::normalize(l + e));
    const double specular = std::pow(std::max(1.0 - th * th, 0.0), 0.5 * visuality.glossiness);
    return render.ambientIntensity * visuality.ambientColor +
           shadow * render.lightColor * visuality.specularColor * specular;
  }
  const double tl = glm::dot(t, l), te = glm::dot(t, e);
  const double sinTL = std::sqrt(std::max(0.0, 1.0 - tl * tl)),
               sinTE = std::sqrt(std::max(0.0, 1.0 - te * te));
  double cone =
      model == ShadingModel::kThesis ? std::abs(tl) * std::abs(te) + sinTL * sinTE : -tl * te + sinTL * sinTE;
  double specular = std::pow(std::max(cone, 0.0), visuality.glossiness);
  return render.ambientIntensity * visuality.ambientColor +
         shadow * render.lightColor * (visuality.diffuseColor * sinTL + visuality.specularColor * specular);
}

}  // namespace hairgen
