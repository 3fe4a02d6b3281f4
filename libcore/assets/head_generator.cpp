// Head and wick generator. The head shape is built from smooth unions of ellipsoids and capsules
// (signed-distance modelling); the wick follows thesis §4.1.4.1: every wick vertex is a follicle whose
// normal is the outward normal of the scalp.
#include "libcore/assets/head_generator.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <tuple>

#include "libcore/assets/surface_nets.h"
#include "libcore/io/obj_io.h"
#include "libcore/util/file_util.h"
#include "libcore/util/text.h"

namespace hairgen {
namespace {

// Bounded approximation of the distance to an ellipsoid (exact on the surface, sign always right).
double ellipsoid(const glm::dvec3& p, const glm::dvec3& r) {
  double k0 = glm::length(p / r);
  double k1 = glm::length(p / (r * r));
  return k1 > 0.0 ? k0 * (k0 - 1.0) / k1 : -glm::min(r.x, glm::min(r.y, r.z));
}

double capsule(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b, double ra, double rb) {
  glm::dvec3 ab = b - a;
  double t = glm::clamp(glm::dot(p - a, ab) / glm::dot(ab, ab), 0.0, 1.0);
  return glm::length(p - (a + t * ab)) - (ra + t * (rb - ra));
}

// Polynomial smooth minimum: blends two distances over a band of width k.
double smoothUnion(double a, double b, double k) {
  double h = glm::clamp(0.5 + 0.5 * (b - a) / k, 0.0, 1.0);
  return glm::mix(b, a, h) - k * h * (1.0 - h);
}
double smoothSubtract(double a, double b, double k) {
  return -smoothUnion(-a, b, k);
}

double mirrorX(double x) {
  return std::abs(x);
}

double hairlineHeight(const HeadAssetParams& params, double azimuthDegrees) {
  const auto& table = params.hairline;
  double a = std::abs(azimuthDegrees);
  if (a <= table.front().x) return table.front().y;
  for (size_t i = 1; i < table.size(); ++i)
    if (a <= table[i].x) {
      double t = (a - table[i - 1].x) / (table[i].x - table[i - 1].x);
      t = t * t * (3.0 - 2.0 * t);  // smoothstep: no kinks in the hairline
      return glm::mix(table[i - 1].y, table[i].y, t);
    }
  return table.back().y;
}

// Geodesic sphere: the icosahedron with every face split into frequency² triangles, on the unit sphere.
Mesh geodesicSphere(int frequency) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<glm::dvec3> ico = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                                 {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  const int faces[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                            {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                            {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                            {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  Mesh mesh;
  std::map<std::tuple<int64_t, int64_t, int64_t>, uint32_t> index;
  auto vertex = [&](glm::dvec3 p) {
    p = glm::normalize(p);
    auto key = std::make_tuple(std::llround(p.x * 1e9), std::llround(p.y * 1e9), std::llround(p.z * 1e9));
    auto [it, inserted] = index.emplace(key, static_cast<uint32_t>(mesh.positions.size()));
    if (inserted) mesh.positions.push_back(glm::vec3(p));
    return it->second;
  };
  const int n = frequency;
  for (const auto& f : faces) {
    glm::dvec3 a = ico[f[0]], b = ico[f[1]], c = ico[f[2]];
    auto point = [&](int i, int j) {
      return vertex(a + (b - a) * (double(i) / n) + (c - a) * (double(j) / n));
    };
    for (int i = 0; i < n; ++i)
      for (int j = 0; i + j < n; ++j) {
        mesh.triangles.push_back(glm::uvec3(point(i, j), point(i + 1, j), point(i, j + 1)));
        if (i + j + 1 < n)
          mesh.triangles.push_back(glm::uvec3(point(i + 1, j), point(i + 1, j + 1), point(i, j + 1)));
      }
  }
  return mesh;
}

float round(double v, double step) {
  return static_cast<float>(std::round(v / step) * step);
}

}  // namespace

double headDistance(const HeadAssetParams& params, const glm::dvec3& world) {
  const glm::dvec3 c = params.ellipsoidCentre;
  const glm::dvec3 p =
      world - glm::dvec3(0.0, c.y, c.z) - glm::dvec3(c.x, 0, 0);  // head frame: cranium centre at origin
  const glm::dvec3 m(mirrorX(p.x), p.y, p.z);                     // left-right symmetric features

  double d = ellipsoid(p, params.ellipsoidAxes * params.craniumScale);

  // Jaw: an ellipsoid below the front of the cranium, narrowing towards the chin.
  glm::dvec3 q = p - glm::dvec3(0.0, -0.073, 0.035);
  double taper =
      1.0 - 0.30 * glm::clamp((q.z + 0.02) / 0.1, 0.0, 1.0) * glm::clamp(-q.y / 0.06 + 0.3, 0.0, 1.0);
  q.x /= taper;
  d = smoothUnion(d, ellipsoid(q, {0.064, 0.074, 0.078}) * taper, 0.025);
  d = smoothUnion(d, ellipsoid(p - glm::dvec3(0.0, -0.136, 0.080), {0.019, 0.012, 0.013}), 0.020);  // chin
  d = smoothUnion(d, ellipsoid(m - glm::dvec3(0.044, -0.048, 0.074), {0.016, 0.012, 0.018}),
                  0.018);  // cheekbones

  // Neck, cut flat below.
  double neck = capsule(p, {0.0, -0.115, -0.028}, {0.0, -0.300, -0.035}, 0.054, 0.058);
  neck = std::max(neck, -(p.y + 0.225));
  d = smoothUnion(d, neck, 0.025);

  // Brow, eye sockets and eyes.
  d = smoothUnion(d, capsule(m, {0.012, -0.015, 0.104}, {0.046, -0.012, 0.094}, 0.008, 0.006), 0.010);
  d = smoothSubtract(d, glm::length(m - glm::dvec3(0.032, -0.033, 0.113)) - 0.016, 0.006);
  d = smoothUnion(d, glm::length(m - glm::dvec3(0.032, -0.033, 0.094)) - 0.0125, 0.002);

  // Nose: bridge, tip, wings.
  d = smoothUnion(d, capsule(p, {0.0, -0.030, 0.110}, {0.0, -0.066, 0.134}, 0.006, 0.010), 0.010);
  d = smoothUnion(d, ellipsoid(m - glm::dvec3(0.010, -0.070, 0.122), {0.010, 0.008, 0.010}), 0.006);

  // Lips and the line between them.
  d = smoothUnion(d, ellipsoid(p - glm::dvec3(0.0, -0.091, 0.114), {0.023, 0.006, 0.009}), 0.006);
  d = smoothUnion(d, ellipsoid(p - glm::dvec3(0.0, -0.103, 0.110), {0.020, 0.007, 0.009}), 0.006);
  d = smoothSubtract(d, ellipsoid(p - glm::dvec3(0.0, -0.097, 0.125), {0.022, 0.0012, 0.012}), 0.002);

  // Ears: a flattened shell with a hollow, tilted back a little.
  glm::dvec3 e = m - glm::dvec3(0.074, -0.040, -0.008);
  double tilt = 0.25;
  e = glm::dvec3(e.x, std::cos(tilt) * e.y - std::sin(tilt) * e.z,
                 std::sin(tilt) * e.y + std::cos(tilt) * e.z);
  double ear = ellipsoid(e, {0.011, 0.031, 0.018});
  ear = smoothSubtract(ear, ellipsoid(e - glm::dvec3(0.007, 0.002, 0.002), {0.006, 0.020, 0.011}), 0.003);
  d = smoothUnion(d, ear, 0.006);
  return d;
}

HeadAssets generateHeadAssets(const HeadAssetParams& params) {
  HeadAssets assets;
  const glm::dvec3 c = params.ellipsoidCentre;

  // Head.
  DistanceFn sdf = [&](const glm::dvec3& p) { return headDistance(params, p); };
  glm::dvec3 lo = c + glm::dvec3(-0.110, -0.300, -0.135), hi = c + glm::dvec3(0.110, 0.095, 0.160);
  assets.head = surfaceNets(sdf, lo, hi, params.headVoxel);
  for (glm::vec3& v : assets.head.positions) v = {round(v.x, 1e-5), round(v.y, 1e-5), round(v.z, 1e-5)};
  for (glm::vec3& n : assets.head.normals) n = {round(n.x, 1e-4), round(n.y, 1e-4), round(n.z, 1e-4)};

  // Wick: a geodesic sphere mapped onto the ellipsoid, evened out, cut at the hairline.
  const glm::dvec3 axes = params.ellipsoidAxes * params.wickScale;
  Mesh sphere = geodesicSphere(params.wickFrequency);
  std::vector<glm::dvec3> pos(sphere.positions.size());
  for (size_t i = 0; i < pos.size(); ++i) pos[i] = glm::dvec3(sphere.positions[i]) * axes;
  std::vector<std::vector<uint32_t>> neighbours(pos.size());
  for (const glm::uvec3& t : sphere.triangles)
    for (int k = 0; k < 3; ++k) {
      auto& list = neighbours[t[k]];
      for (uint32_t other : {t[(k + 1) % 3], t[(k + 2) % 3]})
        if (std::find(list.begin(), list.end(), other) == list.end()) list.push_back(other);
    }
  auto project = [&](glm::dvec3 p) {
    return p / glm::length(p / axes);
  };  // radial projection onto the ellipsoid
  for (int sweep = 0; sweep < params.wickRelaxation; ++sweep) {
    std::vector<glm::dvec3> next(pos.size());
    for (size_t i = 0; i < pos.size(); ++i) {
      glm::dvec3 mean(0.0);
      for (uint32_t j : neighbours[i]) mean += pos[j];
      mean /= double(neighbours[i].size());
      next[i] = project(glm::mix(pos[i], mean, 0.5));
    }
    pos.swap(next);
  }

  auto onScalp = [&](const glm::dvec3& p) {
    glm::dvec3 u = p / axes;  // unit-sphere coordinates
    double azimuth = glm::degrees(std::atan2(u.x, u.z));
    return u.y >= hairlineHeight(params, azimuth);
  };
  std::vector<uint32_t> remap(pos.size(), UINT32_MAX);
  Mesh& wick = assets.wick;
  for (const glm::uvec3& t : sphere.triangles) {
    if (!onScalp(pos[t.x]) || !onScalp(pos[t.y]) || !onScalp(pos[t.z])) continue;
    glm::uvec3 out;
    for (int k = 0; k < 3; ++k) {
      if (remap[t[k]] == UINT32_MAX) {
        remap[t[k]] = static_cast<uint32_t>(wick.positions.size());
        const glm::dvec3& p = pos[t[k]];
        glm::dvec3 u = p / axes;
        wick.positions.push_back(
            glm::vec3(round(c.x + p.x, 1e-5), round(c.y + p.y, 1e-5), round(c.z + p.z, 1e-5)));
        glm::dvec3 n = glm::normalize(p / (axes * axes));  // the ellipsoid's outward normal
        wick.normals.push_back(glm::vec3(round(n.x, 1e-4), round(n.y, 1e-4), round(n.z, 1e-4)));
        double azimuth = std::atan2(u.x, u.z);
        wick.uvs.push_back(
            glm::vec2(round(0.5 + azimuth / (2.0 * M_PI), 1e-5), round(0.5 + 0.5 * u.y, 1e-5)));
      }
      out[k] = remap[t[k]];
    }
    wick.triangles.push_back(out);
  }
  return assets;
}

std::string describeHeadAssetParams(const HeadAssetParams& params) {
  std::ostringstream out;
  auto v3 = [](const glm::dvec3& v) {
    return formatReal(v.x) + " " + formatReal(v.y) + " " + formatReal(v.z);
  };
  out << "# Parameters of the bundled head.obj and wick.obj, written by `hairgen assets -o DIR`.\n"
      << "# Regenerate with that command; tests check that it reproduces the committed files byte for byte.\n"
      << "ellipsoidCentre " << v3(params.ellipsoidCentre) << "    # metres, thesis Appendix C\n"
      << "ellipsoidAxes " << v3(params.ellipsoidAxes) << "    # metres, semi-axes along x y z\n"
      << "craniumScale " << formatReal(params.craniumScale) << "\n"
      << "wickScale " << formatReal(params.wickScale) << "\n"
      << "headVoxel " << formatReal(params.headVoxel) << "    # metres\n"
      << "wickFrequency " << params.wickFrequency << "\n"
      << "wickRelaxation " << params.wickRelaxation << "\n"
      << "hairline";
  for (const glm::dvec2& h : params.hairline) out << " " << formatReal(h.x) << ":" << formatReal(h.y);
  out << "    # azimuth degrees : lowest height in ellipsoid units\n";
  return out.str();
}

void writeHeadAssets(const std::filesystem::path& dir, const HeadAssetParams& params,
                     const HeadAssets& assets) {
  for (auto [mesh, file, what] :
       {std::tuple{&assets.head, "head.obj", "head"}, {&assets.wick, "wick.obj", "wick"}}) {
    std::ostringstream text;
    writeObj(*mesh, text,
             std::string("hairgen ") + what +
                 " mesh, generated by `hairgen assets`; parameters in assets.txt\n" +
                 "metres, +y up, face along +z");
    writeFileAtomic(dir / file, text.str());
  }
  writeFileAtomic(dir / "assets.txt", describeHeadAssetParams(params));
}

}  // namespace hairgen
