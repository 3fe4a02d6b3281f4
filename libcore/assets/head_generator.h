// The bundled head and wick meshes, generated rather than modelled so that every number behind them
// is on record (configs/assets/assets.txt) and `hairgen assets` rebuilds them byte for byte.
//
// The head is a signed-distance sculpture whose cranium is the thesis' collision ellipsoid (Appendix C:
// centre (−0.001, 0.068, 0.010) m, semi-axes 0.080, 0.080, 0.110 m, face along +z) shrunk slightly, with
// jaw, cheekbones, nose, eyes, lips, ears and neck, polygonised by surface nets. The wick is a geodesic
// mesh on that ellipsoid, just inside it, cut at a hairline: forehead, temples, above and behind the
// ears, down to the nape.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "libcore/model/mesh.h"

namespace hairgen {

struct HeadAssetParams {
  glm::dvec3 ellipsoidCentre{-0.001, 0.068, 0.010};  // metres: the thesis' head ellipsoid
  glm::dvec3 ellipsoidAxes{0.080, 0.080, 0.110};     // metres: its semi-axes along x, y, z
  double craniumScale = 0.985;                       // the head's cranium as a fraction of the ellipsoid
  double wickScale = 0.995;  // the wick as a fraction of the ellipsoid (just inside it)
  double headVoxel = 0.004;  // metres: surface-nets grid spacing of the head
  int wickFrequency = 12;    // geodesic subdivision of the wick's icosahedron (edges ~1 cm)
  int wickRelaxation = 60;   // smoothing sweeps that even out the wick's edge lengths
  // Hairline: the lowest height (in ellipsoid units, −1 bottom to +1 top) hair grows at, against the
  // azimuth from the face (degrees, 0 = forehead, 90 = above the ear, 180 = nape).
  std::vector<glm::dvec2> hairline{{0, 0.42},  {30, 0.38},   {55, 0.22},   {75, 0.22},
                                   {95, 0.08}, {115, -0.20}, {140, -0.55}, {180, -0.70}};
};

struct HeadAssets {
  Mesh head;
  Mesh wick;
};

HeadAssets generateHeadAssets(const HeadAssetParams& params);

// The head's signed distance in metres (negative inside), for tests and for checking the wick.
double headDistance(const HeadAssetParams& params, const glm::dvec3& p);

// Writes head.obj, wick.obj and assets.txt (the parameters) into `dir`, each atomically.
void writeHeadAssets(const std::filesystem::path& dir, const HeadAssetParams& params,
                     const HeadAssets& assets);

// The parameter record written as assets.txt.
std::string describeHeadAssetParams(const HeadAssetParams& params);

}  // namespace hairgen
