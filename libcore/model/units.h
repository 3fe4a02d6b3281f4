// Lengths and up axes of strands made elsewhere, brought to hairgen's frame (DESIGN §2: metres, +y up).
// The research data sets and DCCs write centimetres, millimetres or inches, often with +z up; a file says
// neither, so the user states them (`--units`, `--up-axis`; the Setup's MeshUnits and MeshUpAxis for
// meshes) and hairgen converts once, on reading.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include <glm/glm.hpp>

#include "libcore/model/strands.h"

namespace hairgen {

enum class UpAxis { kY, kZ };

// What to apply to a file's coordinates. Unset fields leave the file as it is and its frame unknown.
struct UnitConversion {
  std::optional<double> metresPerUnit;  // multiplies positions and widths (0.01 for centimetres)
  std::optional<UpAxis> upAxis;         // kZ turns z-up to y-up: (x, y, z) → (x, z, −y)

  bool changesCoordinates() const { return (metresPerUnit && *metresPerUnit != 1.0) || upAxis == UpAxis::kZ; }
  glm::vec3 position(glm::vec3 p) const;   // turned, then scaled
  glm::vec3 direction(glm::vec3 d) const;  // turned only
  // What was applied, for provenance and messages: "units mm (x0.001); up axis z turned to +y"; "" when
  // nothing was asked for.
  std::string describe() const;
};

// The metres per unit a file's unit may be: a micrometre to a kilometre. A head modelled in anything
// outside is a wrong unit, and 1e-300 or 1e300 would turn every length into 0 or infinity.
inline constexpr double kMinMetresPerUnit = 1e-6, kMaxMetresPerUnit = 1e3;

// Metres per unit for `text`: m, cm, mm, in (inches) or a number of metres per unit ("0.01") in
// [kMinMetresPerUnit, kMaxMetresPerUnit]. nullopt for anything else.
std::optional<double> parseLengthUnit(std::string_view text);

// "y" or "z" (case-insensitive); nullopt otherwise.
std::optional<UpAxis> parseUpAxis(std::string_view text);

// Applies `conversion` to every position, direction and width of `strands`, and records it: the
// provenance's conversion text, and that the positions are now metres (when a unit was given) and +y up
// (when an axis was given).
void convertToHairgenFrame(Strands& strands, const UnitConversion& conversion);

}  // namespace hairgen
