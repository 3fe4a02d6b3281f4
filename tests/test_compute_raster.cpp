// hairgen's rasteriser as GLSL compute passes (compute_raster.h) against the CPU's (light_maps.h,
// camera_fragments.h) on this machine's OpenGL (llvmpipe in CI): the same integer maps and the same kept
// fragments, to the bit, for hair crossing every way, strands thinner and wider than a pixel, segments
// seen end on, strands running off the image, behind a head's depth, the camera's rows in slabs, sums
// past a word, segments handed to the device in a shuffled order, and strands past a software
// rasteriser's loop budget; and the device's prefix sums against the host's.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include <glm/gtc/matrix_transform.hpp>

#include "libcore/io/obj_io.h"
#include "libcore/render/camera_fragments.h"
#include "libcore/render/compute_raster.h"
#include "libcore/render/gl_context.h"
#include "libcore/render/light_maps.h"
#include "stages/render.h"
#include "tests/test_util.h"

namespace hairgen {
namespace {

GlContext& gl() {
  static GlContext context;
  return context;
}

// A device with no int64 in its shaders, or whose floating point rounds otherwise, has no compute
// rasteriser to compare: the renderer uses the CPU's there.
#define SKIP_WITHOUT_COMPUTE_RASTER()                                                                 \
  do {                                                                                                \
    ASSERT_TRUE(gl().current());                                                                      \
    if (!computeRasterAvailable()) GTEST_SKIP() << "this device cannot run hairgen's compute passes"; \
  } while (false)

// The projection with its segments in a shuffled order: the device must not depend on the order its
// invocations run in, which this stands in for (llvmpipe runs them almost in order).
DeviceProjection shuffled(raster::Projection p, unsigned seed) {
  std::shuffle(p.segments.begin(), p.segments.end(), std::mt19937(seed));
  return DeviceProjection(p);
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

// Every pass compiles and links on this device, at the kept counts a pixel can have: where one does not,
// a render on `auto` would quietly draw on the CPU (computePassesFailure), so CI says so here.
TEST(ComputeRaster, EveryPassBuildsOnThisDevice) {
  SKIP_WITHOUT_COMPUTE_RASTER();
  for (int kept : {1, kKeptFragments, 255}) EXPECT_EQ(computePassesFailure(kept), "") << kept << " kept";
}

// The device's prefix sums (the camera's lists' places) are the host's, modulo 2^32: for one word,
// within one block, just past it, and over two levels of blocks; words past a word's range (the sums
// wrap), a limit on each word, and the largest word found alongside.
TEST(ComputeRaster, PrefixSumsAreTheHostsModulo2To32) {
  SKIP_WITHOUT_COMPUTE_RASTER();
  std::mt19937 random(5);
  const PrefixSum prefixSum;
  const size_t block = PrefixSum::kBlock;
  for (const size_t count : {size_t(0), size_t(1), block - 1, block, block + 1, 300 * block + 17}) {
    std::vector<uint32_t> words(count);
    for (uint32_t& w : words) w = random() % 8 == 0 ? uint32_t(random()) : uint32_t(random() % 40);
    const DeviceBuffer in(count * sizeof(uint32_t), words.data()), out((count + 1) * sizeof(uint32_t)),
        limited((count + 1) * sizeof(uint32_t)), deepest(sizeof(uint32_t));
    deepest.clear(0);
    prefixSum(in, count, out, UINT32_MAX, &deepest);
    prefixSum(in, count, limited, 7);
    std::vector<uint32_t> sums(count + 1), limitedSums(count + 1);
    for (size_t i = 0; i < count; ++i) {
      sums[i + 1] = sums[i] + words[i];  // unsigned: modulo 2^32
      limitedSums[i + 1] = limitedSums[i] + std::min(words[i], 7u);
    }
    SCOPED_TRACE(count);
    EXPECT_TRUE(out.read<uint32_t>(count + 1) == sums);
    EXPECT_TRUE(limited.read<uint32_t>(count + 1) == limitedSums);
    EXPECT_EQ(deepest.read<uint32_t>(1)[0], count ? *std::max_element(words.begin(), words.end()) : 0u);
    if (count > 1000) {
      EXPECT_GT(std::accumulate(words.begin(), words.end(), uint64_t(0)), uint64_t(UINT32_MAX))
          << "the sums pass 2^32";
    }
  }
}

// The light's maps: the integers and the textures the shadow lookup reads.
TEST(ComputeRaster, TheLightsMapsAreTheCpusBits) {
  SKIP_WITHOUT_COMPUTE_RASTER();
  const Strands hair = tangle(600, 7);
  for (const double width : {0.00008, 0.0015}) {
    const View light = perspective(256, 256);
    const HairLightMaps cpu = rasteriseLightMaps(hair, light, width, kLayers);
    const DeviceProjection device = shuffled(raster::project(hair, light, width), 3);
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
  SKIP_WITHOUT_COMPUTE_RASTER();
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
          const DeviceProjection device = shuffled(raster::project(hair, camera, width), kept);
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

// 70,000 strands 4 texels wide over the same few rows: each texel's sums pass 2^32 (65,536 whole
// texels), which the CPU's sums saturate at and the device flags; the camera's tails saturate alike. A
// software rasteriser cannot sort 70,000 fragments of a pixel within its loop budget (compute_raster.h:
// withinLoopBudget): there the camera's fragments are the CPU's, and the device must say so.
TEST(ComputeRaster, SumsPastAWordSaturateAsTheCpusDo) {
  SKIP_WITHOUT_COMPUTE_RASTER();
  Strands pile;
  for (int i = 0; i < 70000; ++i) {
    const float y = 4.0f + 0.00001f * float(i % 100), z = -1.0f - 0.000001f * float(i);
    pile.addStrand({{0.5f, y, z}, {7.5f, y + 0.5f, z}});  // rows 2.25 to 6.25 at 4 texels wide
  }
  View v;
  v.width = v.height = 8;
  v.proj = glm::ortho(0.0, 8.0, 0.0, 8.0, -100.0, 100.0);
  const HairLightMaps cpu = rasteriseLightMaps(pile, v, 4.0, kLayers);
  EXPECT_EQ(cpu.layers[4 * 8 + 3].w, UINT32_MAX) << "the pile passes a word";
  const DeviceProjection device(raster::project(pile, v, 4.0));
  const Texture start(GL_R32F, 8, 8), opacity(GL_RGBA32F, 8, 8);
  HairLightMaps gpu;
  computeLightMaps(device, kLayers, 1.0, 1.0e10f, start, opacity, &gpu);
  EXPECT_TRUE(gpu.start == cpu.start);
  EXPECT_TRUE(gpu.layers == cpu.layers);
  const CameraFragments cpuFragments = cameraFragments(raster::projectIntoBands(pile, v, 4.0), 8);
  EXPECT_EQ(cpuFragments.tail[4 * 8 + 3], UINT32_MAX) << "the tail passes a word";
  const std::optional<DeviceFragments> drawn = computeCameraFragments(device, 8, nullptr);
  if (softwareRasteriser()) {
    EXPECT_FALSE(drawn) << "past llvmpipe's loop budget";
    return;
  }
  ASSERT_TRUE(drawn);
  const CameraFragments gpuFragments = drawn->read(8, 8);
  EXPECT_TRUE(gpuFragments.first == cpuFragments.first);
  EXPECT_TRUE(gpuFragments.tail == cpuFragments.tail);
  EXPECT_TRUE(gpuFragments.words == cpuFragments.words);
}

// A whole render, coupe 3 at a fifth of its density on its head at 320×240 with 4 samples, the light's
// maps kept: the rasteriser on the device gives the image and maps the CPU's does, every channel to the
// bit (on llvmpipe the shading around them is the same code too).
TEST(ComputeRaster, ARenderIsTheSameBitsWhereverTheRasteriserRuns) {
  SKIP_WITHOUT_COMPUTE_RASTER();
  test::Job job = test::loadJob("thesis/coupe3/setup.txt", SetupUse::kRender);
  const Strands coupe = test::coupeOf(job, 20);
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

// Strands so wide that a segment's texels pass a software rasteriser's loop budget (withinLoopBudget):
// there the CPU draws them, the device elsewhere, and the image is the same bits either way.
TEST(ComputeRaster, ARenderPastTheLoopBudgetIsTheSameBits) {
  SKIP_WITHOUT_COMPUTE_RASTER();
  test::Job job = test::loadJob("thesis/coupe3/setup.txt", SetupUse::kRender);
  Strands wide;
  for (int i = 0; i < 4; ++i) {
    const float y = 0.05f * float(i) - 0.08f;
    wide.addStrand({{-0.4f, y, 0.0f}, {0.0f, y + 0.01f, 0.02f}, {0.4f, y, 0.0f}});
  }
  RenderSettings r = job.config.render;
  r.resolution = {320, 240};
  r.strandWidth = 0.2;  // metres: a segment's texels past the budget, in the light's view and the camera's
  RenderOptions options;
  options.keepDom = true;
  options.force = true;  // sheets, not hairs, on purpose
  options.rasteriser = RenderInput::Rasteriser::kCpu;
  const RenderOutput cpu = render(gl(), wide, nullptr, job.config.visuality, r, {}, options);
  options.rasteriser = RenderInput::Rasteriser::kDevice;
  const RenderOutput device = render(gl(), wide, nullptr, job.config.visuality, r, {}, options);
  EXPECT_GT(cpu.hairFragments, 10000u);
  EXPECT_EQ(device.rasterisedOnDevice, !softwareRasteriser());
  ASSERT_EQ(device.beauty.channels, cpu.beauty.channels);
  for (size_t c = 0; c < cpu.beauty.channels.size(); ++c)
    EXPECT_TRUE(device.beauty.planes[c] == cpu.beauty.planes[c]) << cpu.beauty.channels[c];
  for (size_t c = 0; c < cpu.dom.channels.size(); ++c)
    EXPECT_TRUE(device.dom.planes[c] == cpu.dom.planes[c]) << cpu.dom.channels[c];
}

}  // namespace
}  // namespace hairgen
