// Anjyo et al. 1992 §2 and §3.2.3, the second styling model of `hairgen grow` (Model cantilever):
// each hair a chain of equal segments from its pore, bent node by node by the segment-constant
// moments of a cantilever beam under gravity and force fields, kept out of the head (headShape), its
// joint angles limited, and cut by pore position and height.
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include "libcore/config/params.h"
#include "libcore/model/mesh.h"

namespace hairgen {

// Anjyo's (2) and (3): on segment i of k (1-based) under a load of `load` newtons per node, the moment
// is M_i = −load·d·(k − i + 1)²/2 and the deflection y_i = −½ (M_i / EI) d².
double cantileverDeflection(double load, double d, double rigidity, int k, int i);

// The nodes p_0 (the pore) to p_k of one hair; `head` may be null (no collision avoidance).
std::vector<glm::dvec3> bendHair(const glm::dvec3& pore, const glm::dvec3& normal, const Hairstyle& style,
                                 const CollisionShape* head);

// The pore's azimuth and zenith in degrees on `head` (or about the origin when null), as Cut reads them.
glm::dvec2 porePolar(const glm::dvec3& pore, const CollisionShape* head);

// Cuts a bent hair: when a Cut selects its pore, it ends at its last node before the first one below
// the Cut's height. Returns the number of nodes kept.
size_t cutHair(std::vector<glm::dvec3>& nodes, const Hairstyle& style, const CollisionShape* head);

}  // namespace hairgen
