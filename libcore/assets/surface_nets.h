// Naive surface nets (Gibson 1998): a watertight triangle mesh of the zero set of a signed distance
// function, one vertex per grid cell the surface crosses, one quad per grid edge it crosses.
#pragma once

#include <functional>

#include <glm/glm.hpp>

#include "libcore/model/mesh.h"

namespace hairgen {

using DistanceFn = std::function<double(const glm::dvec3&)>;  // < 0 inside, metres

// Samples `sdf` on a grid of `spacing` metres over [lo, hi], places each vertex at the mean of its
// cell's edge crossings, pulls it onto the surface with a few Newton steps, and takes normals from the
// SDF gradient. The surface must not touch the box's faces if a closed mesh is wanted.
Mesh surfaceNets(const DistanceFn& sdf, const glm::dvec3& lo, const glm::dvec3& hi, double spacing);

// Unit gradient of `sdf` at `p` by central differences of step `h`.
glm::dvec3 sdfNormal(const DistanceFn& sdf, const glm::dvec3& p, double h);

}  // namespace hairgen
