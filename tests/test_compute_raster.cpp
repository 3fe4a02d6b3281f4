// hairgen's rasteriser as GLSL compute passes (compute_raster.h) against the CPU's (light_maps.h,
// camera_fragments.h) on this machine's OpenGL (llvmpipe in CI): the same integer maps and the same kept
// fragments, to the bit, for hair crossing every way, strands thinner and wider than a pixel, segments
// seen end on, strands running off the image, behind a head's depth, and the camera's rows in slabs.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <glm/gtc/matrix_transform.hpp>

#include "libcore/io/obj_io.h"
#include "libcore/render/camera_fragments.h"
#include "libcore/render/compute_raster.h"
#include "libcore/render/gl_context.h"
#include "libcore/render/light_maps.h"
#include "stages/grow.h"
#include "stages/interpolate.h"
#include "stages/render.h"
#include "tests/test_util.h"

namespace hairgen {
namespace {

GlContext& gl() {
  static GlContext context;
  return context;
}

// A pinhole view from (0, 0, 0.5) toward the origin, `width` × `height` pixels, 30° vertically.
View perspective(int width, int height) {
  View v;
  v.width = width;
  v.height = height;
  const double fov = glm::radians(30.0);
  v.view = glm::lookAt(glm::dvec3(0.0, 0.0, 0.5), glm::dvec3(0.0), glm::dvec3(0.0, 1.0, 0.0));
  v.proj = glm::perspective(fov, double(width) / height, 0.05, 5.0);
  v.focalPx = 0.5 * height / std::tan(0.5 * fov);
  return v;
}

// Curly strands crossing every way around the origin, some running off the image, some straight along
// the view's axis (seen end on), a few points nearer than the near plane.
Strands tangle(int strands, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  Strands s;
  for (int i = 0; i < strands; ++i) {
    std::vector<glm::vec3> points;
    glm::vec3 p(0.12f * u(random), 0.12f * u(random), 0.05f * u(random));
    const glm::vec3 d = glm::normalize(glm::vec3(u(random), u(random), 0.3f * u(random)));
    const float curl = 40.0f * u(random);
    for (int k = 0; k < 16; ++k) {
      points.push_back(p);
      const float a = curl * 0.01f * float(k);
      p += 0.006f * glm::normalize(d + 0.6f * glm::vec3(std::cos(a), std::sin(a), 0.0f));
    }
    s.addStrand(points);
  }
  s.addStrand({{0.01f, 0.01f, 0.0f}, {0.01f, 0.01f, -0.02f}, {0.01f, 0.01f, -0.04f}});  // end on
  s.addStrand({{0.0f, 0.0f, 0.0f}, {0.02f, 0.0f, 0.49f}});                              // to the eye
  s.addStrand({{-0.3f, 0.0f, 0.0f}, {0.3f, 0.02f, 0.0f}});                              // off both sides
  return s;
}

constexpr glm::dvec4 kLayers{0.002, 0.006, 0.015, 0.04};

// The light's maps: the integers and the textures the shadow lookup reads.
TEST(ComputeRaster, TheLightsMapsAreTheCpusBits) {
  ASSERT_TRUE(gl().current());
  ASSERT_TRUE(computeRasterAvailable());
  const Strands hair = tangle(600, 7);
  for (const double width : {0.00008, 0.0015}) {
    const View light = perspective(256, 256);
    const HairLightMaps cpu = rasteriseLightMaps(hair, light, width, kLayers);
    const DeviceProjection device(raster::project(hair, light, width));
    const Texture start(GL_R32F, 256, 256), opacity(GL_RGBA32F, 256, 256);
    HairLightMaps gpu;
    computeLightMaps(device, kLayers, 0.4, 1.0e10f, start, opacity, &gpu);
    size_t reached = 0;
    for (int32_t s : cpu.start) reached += s != INT32_MAX;
    EXPECT_GT(reached, 5000u) << "the hair covers much of the map";
    EXPECT_TRUE(gpu.start == cpu.start) << width;
    EXPECT_TRUE(gpu.layers == cpu.layers) << width;
    std::vector<float> startMetres(256 * 256);
    std::vector<glm::vec4> layers(256 * 256);
    glGetTextureImage(start.id, 0, GL_RED, GL_FLOAT, GLsizei(startMetres.size() * 4), startMetres.data());
    glGetTextureImage(opacity.id, 0, GL_RGBA, GL_FLOAT, GLsizei(layers.size() * 16), layers.data());
    EXPECT_TRUE(startMetres == cpu.startMetres(1.0e10f));
    EXPECT_TRUE(layers == cpu.opacity(0.4));
  }
}

// The camera's kept fragments, with and without a head's depth in front of some of the hair, at 8 and
// at 2 fragments a pixel (more in the tails), in one slab and in slabs of a few rows.
TEST(ComputeRaster, TheCamerasFragmentsAreTheCpusBits) {
  ASSERT_TRUE(gl().current());
  const Strands hair = tangle(900, 11);
  const View camera = perspective(200, 150);
  const size_t pixels = 200 * 150;
  // The head: a plane tilted through the hair, nearer on the left.
  std::vector<float> head(pixels);
  std::vector<glm::vec4> headTexels(pixels);
  for (size_t p = 0; p < pixels; ++p) {
    head[p] = float(0.47 + 0.0004 * double(p % 200));
    headTexels[p] = glm::vec4(head[p], 0.0f, 1.0f, 0.0f);
  }
  const Texture headData(GL_RGBA32F, 200, 150);
  glTextureSubImage2D(headData.id, 0, 0, 0, 200, 150, GL_RGBA, GL_FLOAT, headTexels.data());
  for (const double width : {0.00008, 0.001})
    for (const int kept : {8, 2})
      for (const bool withHead : {false, true})
        for (const size_t slab : {size_t(0), size_t(16) << 10}) {
          const CameraFragments cpu = cameraFragments(raster::projectIntoBands(hair, camera, width), kept,
                                                      withHead ? head.data() : nullptr);
          const DeviceProjection device(raster::project(hair, camera, width));
          const std::optional<DeviceFragments> drawn =
              computeCameraFragments(device, kept, withHead ? &headData : nullptr, slab);
          ASSERT_TRUE(drawn);
          const CameraFragments gpu = drawn->read(200, 150);
          SCOPED_TRACE(testing::Message()
                       << width << " m wide, " << kept << " kept, head " << withHead << ", slab " << slab);
          EXPECT_GT(cpu.count(), 10000u);
          EXPECT_TRUE(gpu.first == cpu.first);
          EXPECT_TRUE(gpu.tail == cpu.tail);
          EXPECT_TRUE(gpu.words == cpu.words);
        }
  // A row's fragments that do not fit the slab's buffer: nothing, and the renderer draws them on the CPU.
  const DeviceProjection device(raster::project(hair, camera, 0.001));
  EXPECT_FALSE(computeCameraFragments(device, 8, nullptr, 64));
}

// A whole render, coupe 3 at a fifth of its density on its head at 320×240 with 4 samples, the light's
// maps kept: the rasteriser on the device gives the image and maps the CPU's does, every channel to the
// bit (on llvmpipe the shading around them is the same code too).
TEST(ComputeRaster, ARenderIsTheSameBitsWhereverTheRasteriserRuns) {
  test::Job job = test::loadJob("thesis/coupe3/setup.txt", SetupUse::kRender);
  Hairstyle h = job.config.hairstyle;
  h.hairDensity = 20;
  const Strands coupe =
      interpolate(job.wick, grow(job.wick, h, job.config.collision, {}).guides, h, job.config.collision, {});
  const Mesh head = readObj(job.config.setup.headModel.path);
  RenderSettings r = job.config.render;
  r.resolution = {320, 240};
  r.samples = 4;
  RenderOptions options;
  options.keepDom = true;
  options.rasteriser = RenderInput::Rasteriser::kCpu;
  const RenderOutput cpu = render(gl(), coupe, &head, job.config.visuality, r, {}, options);
  options.rasteriser = RenderInput::Rasteriser::kDevice;
  const RenderOutput device = render(gl(), coupe, &head, job.config.visuality, r, {}, options);
  EXPECT_FALSE(cpu.rasterisedOnDevice);
  EXPECT_TRUE(device.rasterisedOnDevice);
  EXPECT_GT(cpu.hairFragments, 50000u);
  EXPECT_EQ(device.hairFragments, cpu.hairFragments);
  ASSERT_EQ(device.beauty.channels, cpu.beauty.channels);
  for (size_t c = 0; c < cpu.beauty.channels.size(); ++c)
    EXPECT_TRUE(device.beauty.planes[c] == cpu.beauty.planes[c]) << cpu.beauty.channels[c];
  for (size_t c = 0; c < cpu.dom.channels.size(); ++c)
    EXPECT_TRUE(device.dom.planes[c] == cpu.dom.planes[c]) << cpu.dom.channels[c];
}

}  // namespace
}  // namespace hairgen
