// Helpers shared by the unit tests: sample data generated in code, temporary directories.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "libcore/config/reader.h"
#include "libcore/config/setup.h"
#include "libcore/io/obj_io.h"
#include "libcore/model/strands.h"
#include "libcore/physics/head_motion.h"
#include "stages/grow.h"
#include "stages/interpolate.h"

namespace hairgen::test {

// The repository: where the build was configured, or $HAIRGEN_SOURCE_DIR where the tests run from a
// copy elsewhere (scripts/device-check.sh on a GPU machine).
inline std::filesystem::path sourceDir() {
  const char* moved = std::getenv("HAIRGEN_SOURCE_DIR");
  return moved && *moved ? moved : HAIRGEN_SOURCE_DIR;
}
// A bundled Setup (a path under configs/) read as a stage would, with its wick.
struct Job {
  Config config;
  Mesh wick;
};
inline Job loadJob(const std::string& setup, SetupUse use = SetupUse::kGrow) {
  Job job{loadConfig(sourceDir() / "configs" / setup, {}, use), {}};
  job.wick = readObj(job.config.setup.wickModel.path);
  return job;
}

// The job's coupe grown from its wick and interpolated at `density` strands a cm².
inline Strands coupeOf(const Job& job, int density) {
  Hairstyle h = job.config.hairstyle;
  h.hairDensity = density;
  return interpolate(job.wick, grow(job.wick, h, job.config.collision, {}).guides, h, job.config.collision,
                     {});
}

inline std::filesystem::path realData() {
  return sourceDir() / ".." / "shared" / "testdata" / "real";
}

// A fresh directory under the system temp dir, removed on destruction.
class TempDir {
 public:
  explicit TempDir(const std::string& tag) {
    path_ = std::filesystem::temp_directory_path() /
            ("hairgen-test-" + tag + "-" + std::to_string(std::random_device{}()));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

// Strands of unequal lengths carrying every optional attribute, with deterministic values.
inline Strands sampleStrands(size_t count = 7, uint32_t seed = 1) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  Strands s;
  for (size_t i = 0; i < count; ++i) {
    std::vector<glm::vec3> points;
    size_t n = 2 + (i * 3) % 9;
    glm::vec3 p(u(rng), u(rng), u(rng));
    for (size_t k = 0; k < n; ++k) points.push_back(p + glm::vec3(0.01f * k, -0.02f * k, 0.003f * k * k));
    s.addStrand(points);
    s.strandId.push_back(static_cast<uint32_t>(1000 + i));
    s.rootTriangle.push_back(static_cast<uint32_t>(i * 7));
    s.rootBary.push_back(glm::vec3(0.2f, 0.3f, 0.5f));
    s.rootUv.push_back(glm::vec2(0.1f * i, 0.5f));
    s.guideIds.push_back(glm::uvec3(i, i + 1, i + 2));
    s.guideWeights.push_back(glm::vec3(0.5f, 0.25f, 0.25f));
  }
  for (size_t p = 0; p < s.pointCount(); ++p) {
    s.tangents.push_back(glm::normalize(glm::vec3(u(rng), u(rng), 1.5f)));
    s.normals.push_back(glm::normalize(glm::vec3(1.5f, u(rng), u(rng))));
    s.colors.push_back(glm::vec3(0.5f + 0.4f * u(rng), 0.3f, 0.1f));
    s.thickness.push_back(7e-5f + 1e-5f * u(rng));
    s.transparency.push_back(0.25f + 0.2f * u(rng));
  }
  s.provenance.producer = "hairgen test";
  s.provenance.stage = "unit";
  s.provenance.seed = 42;
  s.provenance.configDigest = "0123456789abcdef";
  return s;
}

// Compares two strand sets field by field, so a failure names the attribute that differs.
inline void expectSameStrands(const Strands& a, const Strands& b) {
  EXPECT_EQ(a.points, b.points);
  EXPECT_EQ(a.firstPoint, b.firstPoint);
  EXPECT_EQ(a.tangents, b.tangents);
  EXPECT_EQ(a.normals, b.normals);
  EXPECT_EQ(a.colors, b.colors);
  EXPECT_EQ(a.thickness, b.thickness);
  EXPECT_EQ(a.transparency, b.transparency);
  EXPECT_EQ(a.strandId, b.strandId);
  EXPECT_EQ(a.rootTriangle, b.rootTriangle);
  EXPECT_EQ(a.rootBary, b.rootBary);
  EXPECT_EQ(a.rootUv, b.rootUv);
  EXPECT_EQ(a.guideIds, b.guideIds);
  EXPECT_EQ(a.guideWeights, b.guideWeights);
  EXPECT_EQ(a.defaultThickness, b.defaultThickness);
  EXPECT_EQ(a.defaultTransparency, b.defaultTransparency);
  EXPECT_EQ(a.defaultColor, b.defaultColor);
  EXPECT_EQ(a.provenance.producer, b.provenance.producer);
  EXPECT_EQ(a.provenance.stage, b.provenance.stage);
  EXPECT_EQ(a.provenance.seed, b.provenance.seed);
  EXPECT_EQ(a.provenance.configDigest, b.provenance.configDigest);
  EXPECT_EQ(a.provenance.source, b.provenance.source);
  EXPECT_EQ(a.provenance.sourceInfo, b.provenance.sourceInfo);
  EXPECT_EQ(a.provenance.conversion, b.provenance.conversion);
  EXPECT_EQ(a.provenance.metres, b.provenance.metres);
  EXPECT_EQ(a.provenance.yUp, b.provenance.yUp);
}

// The hair of the dynamics kernels' bit tests (Anjyo's and the springs'): an ellipsoid head of
// semi-axes kKernelHeadAxes at the origin with a sphere and a box beside it below, and strand s of
// counts[s] points down the head's +x side, 9° apart, from 60° above the equator 7° a point (closer for
// strands of more than 12 points, which span 84°), 2% off the surface.
constexpr glm::dvec3 kKernelHeadAxes(0.10, 0.12, 0.11);
inline Collision kernelShapes() {
  Collision shapes;
  shapes.shapes.push_back(
      {ShapeKind::kEllipsoid, 0.0, 1.0, glm::dvec3(0.0), kKernelHeadAxes, glm::dmat3(1.0), {}});
  shapes.shapes.push_back(
      {ShapeKind::kSphere, 0.0, 1.0, glm::dvec3(0.11, -0.08, 0.0), glm::dvec3(0.03), glm::dmat3(1.0), {}});
  shapes.shapes.push_back(
      {ShapeKind::kCuboid, 0.0, 1.0, glm::dvec3(0.02, -0.16, 0.06), glm::dvec3(0.04), glm::dmat3(1.0), {}});
  return shapes;
}
// Their field: a wind hard into the head beside gravity, in a head turning and speeding up.
inline AccelerationField kernelField() {
  AccelerationField field;
  field.base = {-60.0, -9.81, 15.0};
  field.rotating = true;
  field.omega = {0.3, 4.0, 0.5};
  field.alpha = {2.0, 0.0, -1.0};
  return field;
}
inline Strands kernelHair(const std::vector<int>& counts) {
  Strands hair;
  for (size_t s = 0; s < counts.size(); ++s) {
    const double u = glm::radians(9.0 * (double(s) - 6.0));
    std::vector<glm::vec3> points;
    for (int j = 0; j < counts[s]; ++j) {
      const double v = glm::radians(60.0 - 7.0 * j * 12.0 / std::max(counts[s], 12));
      points.push_back(
          glm::vec3(1.02 * kKernelHeadAxes *
                    glm::dvec3(std::cos(v) * std::cos(u), std::sin(v), std::cos(v) * std::sin(u))));
    }
    hair.addStrand(points);
  }
  return hair;
}

inline ConfigText text(const std::string& body, const std::string& name = "test.txt") {
  return parseConfigText(body, name, ".");
}

// The times at which `signal` crosses zero downward, interpolated between samples `dt` apart.
inline std::vector<double> downCrossings(const std::vector<double>& signal, double dt) {
  std::vector<double> out;
  for (size_t n = 1; n < signal.size(); ++n)
    if (signal[n - 1] > 0.0 && signal[n] <= 0.0)
      out.push_back((double(n - 1) + signal[n - 1] / (signal[n - 1] - signal[n])) * dt);
  return out;
}

// One strand from `root` along `dirs`, each segment `d` long.
inline Strands chain(const glm::dvec3& root, const std::vector<glm::dvec3>& dirs, double d) {
  std::vector<glm::vec3> points{glm::vec3(root)};
  glm::dvec3 p = root;
  for (const glm::dvec3& dir : dirs) points.push_back(glm::vec3(p += d * glm::normalize(dir)));
  Strands s;
  s.addStrand(points);
  return s;
}

}  // namespace hairgen::test
