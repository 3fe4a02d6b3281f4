// Petrovic, Henne and Anderson, Volumetric Methods for Simulation and Rendering of Hair, Pixar Technical Memo
// 06-08 (2006), §5.2: density targeting. The energy E = ½ Σ (D_s − D_t)² of the difference between the
// simulated density D_s and a target D_t, and the force −∂E/∂p it puts on a strand point.
#pragma once

#include <glm/glm.hpp>

#include "libcore/volume/grid.h"

namespace hairgen {

// Petrovic et al. §5.2: the force on a point at `p` from the density difference `difference` = D_s −
// D_t of the memo's (3), E = ½ Σ (D_s − D_t)²: −∂E/∂p in grid units (p measured in voxels), the memo's
// F_x, F_y, F_z (points per node). Along an axis where p sits exactly on a grid line the derivative is
// taken as 0, as the memo does. Zero outside the grid.
glm::dvec3 densityForce(const Grid& difference, const glm::dvec3& p);

// E = ½ Σ d² over the nodes of `difference`, summed in node order.
double densityEnergy(const Grid& difference);

}  // namespace hairgen
