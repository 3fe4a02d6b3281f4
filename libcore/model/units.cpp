#include "libcore/model/units.h"

#include <cmath>

#include "libcore/util/text.h"

namespace hairgen {
namespace {

struct NamedUnit {
  const char* name;
  double metres;
};
constexpr NamedUnit kNamedUnits[] = {{"m", 1.0}, {"cm", 0.01}, {"mm", 0.001}, {"in", 0.0254}};

}  // namespace

glm::vec3 UnitConversion::position(glm::vec3 p) const {
  p = direction(p);
  return metresPerUnit ? p * static_cast<float>(*metresPerUnit) : p;
}

glm::vec3 UnitConversion::direction(glm::vec3 d) const {
  return upAxis == UpAxis::kZ ? glm::vec3(d.x, d.z, -d.y) : d;
}

std::string UnitConversion::describe() const {
  std::string text;
  if (metresPerUnit) {
    std::string name;
    for (const NamedUnit& u : kNamedUnits)
      if (u.metres == *metresPerUnit) name = u.name;
    text = "units " + (name.empty() ? formatReal(*metresPerUnit) + " m" : name) + " (x" +
           formatReal(*metresPerUnit) + ")";
  }
  if (upAxis)
    text += std::string(text.empty() ? "" : "; ") +
            (*upAxis == UpAxis::kZ ? "up axis z turned to +y" : "up axis y kept");
  return text;
}

std::optional<double> parseLengthUnit(std::string_view text) {
  const std::string lower = toLower(text);
  for (const NamedUnit& u : kNamedUnits)
    if (lower == u.name) return u.metres;
  std::optional<double> factor = parseReal(text);
  if (!factor || !(*factor >= kMinMetresPerUnit && *factor <= kMaxMetresPerUnit)) return std::nullopt;
  return factor;
}

std::optional<UpAxis> parseUpAxis(std::string_view text) {
  const std::string lower = toLower(text);
  if (lower == "y") return UpAxis::kY;
  if (lower == "z") return UpAxis::kZ;
  return std::nullopt;
}

void convertToHairgenFrame(Strands& s, const UnitConversion& c) {
  if (c.changesCoordinates()) {
    const float scale = c.metresPerUnit ? static_cast<float>(*c.metresPerUnit) : 1.0f;
    for (glm::vec3& p : s.points) p = c.position(p);
    for (glm::vec3& t : s.tangents) t = c.direction(t);
    for (glm::vec3& n : s.normals) n = c.direction(n);
    for (float& t : s.thickness) t *= scale;
    s.defaultThickness *= scale;
  }
  const std::string applied = c.describe();
  if (!applied.empty())
    s.provenance.conversion += (s.provenance.conversion.empty() ? "" : "; then ") + applied;
  if (c.metresPerUnit) s.provenance.metres = true;
  if (c.upAxis) s.provenance.yUp = true;
}

}  // namespace hairgen
