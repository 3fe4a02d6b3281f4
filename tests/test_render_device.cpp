// The device's plumbing (issue 34 item 5): the readback through a pixel-pack buffer gives the floats a
// plain read of the whole texture gives, and one context kept for a sequence compiles its programs
// once and renders each frame as a fresh context would.
#include <gtest/gtest.h>

#include <cstring>

#include "libcore/render/gl_context.h"
#include "libcore/render/gl_resources.h"
#include "libcore/render/readback.h"
#include "stages/render.h"

namespace hairgen {
namespace {

// The context of these tests, current on the test's thread (another test file's may have been made
// current since).
GlContext& context() {
  static GlContext gl;
  gl.makeCurrent();
  return gl;
}

// `w`×`h` texels of `format` holding texel i's channel c = a value no two texels share, negative ones
// and a denormal among them, rows bottom to top as OpenGL stores them.
Texture filledTexture(GLenum format, int w, int h, std::vector<float>& rgba) {
  rgba.resize(size_t(w) * h * 4);
  for (size_t i = 0; i < rgba.size(); ++i) rgba[i] = (float(i) - 37.0f) * 0.37f;
  rgba[5] = 1e-40f;
  Texture t(format, w, h);
  glTextureSubImage2D(t.id, 0, 0, 0, w, h, GL_RGBA, GL_FLOAT, rgba.data());
  return t;
}

// What readBack did before pixel-pack buffers: the whole texture as RGBA floats, split into planes
// with the rows turned top to bottom.
std::vector<std::vector<float>> plainRead(const Texture& t) {
  std::vector<float> rgba(size_t(t.width) * t.height * 4);
  glGetTextureImage(t.id, 0, GL_RGBA, GL_FLOAT, GLsizei(rgba.size() * sizeof(float)), rgba.data());
  std::vector<std::vector<float>> planes(4, std::vector<float>(size_t(t.width) * t.height));
  for (int c = 0; c < 4; ++c)
    for (int y = 0; y < t.height; ++y)
      for (int x = 0; x < t.width; ++x)
        planes[size_t(c)][size_t(t.height - 1 - y) * t.width + x] = rgba[(size_t(y) * t.width + x) * 4 + c];
  return planes;
}

bool sameBits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

// Every channel of textures of the formats the passes draw (full floats, half floats, one channel), of
// sizes no power of two and rows no multiple of 64, read in one call either way (a GPU's, llvmpipe's):
// the bits of the plain read.
TEST(Readback, PixelPackBufferGivesThePlainReadsFloats) {
  context();
  std::vector<float> data;
  const Texture rgba32(filledTexture(GL_RGBA32F, 37, 131, data));
  const Texture rgba16(filledTexture(GL_RGBA16F, 20, 9, data));
  const Texture r32(filledTexture(GL_R32F, 5, 3, data));
  // Each layout twice: the second round reuses the context's kept buffer.
  for (ReadbackLayout layout : {ReadbackLayout::kChannels, ReadbackLayout::kWholeTextures,
                                ReadbackLayout::kChannels, ReadbackLayout::kWholeTextures}) {
    SCOPED_TRACE(layout == ReadbackLayout::kChannels ? "channel by channel" : "whole textures");
    std::vector<std::vector<float>> planes(9);
    std::vector<PlaneRead> reads;
    for (int c = 0; c < 4; ++c) reads.push_back({&rgba32, c, &planes[size_t(c)]});
    for (int c = 0; c < 4; ++c) reads.push_back({&rgba16, c, &planes[size_t(4 + c)]});
    reads.push_back({&r32, 0, &planes[8]});
    readPlanes(reads, layout);
    ASSERT_EQ(glGetError(), GLenum(GL_NO_ERROR));
    const auto expect32 = plainRead(rgba32), expect16 = plainRead(rgba16), expectR = plainRead(r32);
    for (int c = 0; c < 4; ++c) {
      EXPECT_TRUE(sameBits(planes[size_t(c)], expect32[size_t(c)])) << "RGBA32F channel " << c;
      EXPECT_TRUE(sameBits(planes[size_t(4 + c)], expect16[size_t(c)])) << "RGBA16F channel " << c;
    }
    EXPECT_TRUE(sameBits(planes[8], expectR[0])) << "R32F";
    EXPECT_EQ(planes[0][0], (float(130 * 37 * 4) - 37.0f) * 0.37f)
        << "a plane's first row is the texture's last (OpenGL's top)";
  }
}

// A coupe of crossing strands in front of the camera, moved by `shift` metres along x.
Strands crossing(float shift) {
  Strands s;
  for (int i = 0; i < 40; ++i) {
    std::vector<glm::vec3> p;
    for (int j = 0; j < 12; ++j)
      p.push_back({-0.04f + 0.007f * float(j) + shift, -0.03f + 0.0015f * float(i) + 0.002f * float(j % 3),
                   0.001f * float(i % 5)});
    s.addStrand(p);
  }
  return s;
}

RenderSettings smallView(int samples) {
  RenderSettings r;
  r.resolution = {48, 40};
  r.cameraAuto = false;
  r.cameraPosition = {0.0, 0.0, 0.3};
  r.cameraTarget = {0.0, 0.0, 0.0};
  r.lightPosition = {0.1, 0.3, 0.2};
  r.samples = samples;
  return r;
}

bool sameImage(const Image& a, const Image& b) {
  if (a.channels != b.channels || a.width != b.width || a.height != b.height) return false;
  for (size_t c = 0; c < a.planes.size(); ++c)
    if (!sameBits(a.planes[c], b.planes[c])) return false;
  return true;
}

// A second frame on the same context compiles no program and makes no object it did not make for the
// first (the context keeps them); a frame with other settings (sub-pixels: ribbons, the screen door)
// adds its own programs; and each frame's image is the one a fresh context renders.
TEST(KeptObjects, ASequenceCompilesOnceAndRendersAsAFreshContext) {
  RenderOptions options;
  options.domResolution = 256;
  options.keepDom = true;
  std::vector<RenderOutput> sequence;
  size_t afterFirst = 0, afterSecond = 0;
  {
    GlContext gl;  // a context of this test's own, current here until it goes
    for (int frame = 0; frame < 3; ++frame) {
      const Strands hair = crossing(0.002f * float(frame));
      sequence.push_back(render(gl, hair, nullptr, {}, smallView(frame == 2 ? 4 : 1), {}, options));
      if (frame == 0) afterFirst = gl.keptCount();
      if (frame == 1) afterSecond = gl.keptCount();
    }
    EXPECT_GT(afterFirst, 0u) << "the first frame's programs are kept";
    EXPECT_EQ(afterSecond, afterFirst) << "the second frame made what the first had kept again";
    // The rasteriser's fragments are shaded one sample each at any Samples: no programs of their own.
    EXPECT_EQ(gl.keptCount(), afterSecond) << "sub-pixels compiled programs of their own";
  }
  for (int frame = 0; frame < 3; ++frame) {
    GlContext fresh;
    const Strands hair = crossing(0.002f * float(frame));
    const RenderOutput alone = render(fresh, hair, nullptr, {}, smallView(frame == 2 ? 4 : 1), {}, options);
    EXPECT_TRUE(sameImage(alone.beauty, sequence[size_t(frame)].beauty)) << "frame " << frame;
    EXPECT_TRUE(sameImage(alone.dom, sequence[size_t(frame)].dom)) << "frame " << frame << "'s maps";
  }
  context();  // the tests after this one find a context current
}

// A context opened on another thread is current on none until makeCurrent, then renders.
TEST(KeptObjects, AContextOpenedInTheBackgroundRendersOnThisThread) {
  std::future<std::unique_ptr<GlContext>> opening = GlContext::openInBackground();
  std::unique_ptr<GlContext> gl = opening.get();
  ASSERT_TRUE(gl);
  gl->makeCurrent();
  EXPECT_EQ(GlContext::current(), gl.get());
  const RenderOutput out = render(*gl, crossing(0.0f), nullptr, {}, smallView(1), {}, {});
  float covered = 0.0f;
  for (float a : out.beauty.plane("A")) covered += a;
  // 40 strands of 80 µm, 7 cm long, at 0.7 opacity cover about 7 pixels' worth of the image.
  EXPECT_GT(covered, 3.0f) << "the strands were drawn";
  gl.reset();
  EXPECT_EQ(GlContext::current(), nullptr);
  context();
}

}  // namespace
}  // namespace hairgen
