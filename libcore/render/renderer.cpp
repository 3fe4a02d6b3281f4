// Hair rendering with deep opacity maps (Yuksel & Keyser 2008, as the thesis uses them in §4.1.6).
//
// Strands are read by the vertex shader from storage buffers. A strand that is thinner than about a
// pixel everywhere in the view (real hair, unless the camera is very close) is drawn as a line strip;
// a wider one as a camera-facing ribbon StrandWidth wide (two vertices per point, a triangle strip).
// Either way a strand is at least one pixel wide with StrandOpacity as its opacity.
//
// Antialiasing is supersampling: Samples = k² renders the shading pass at k times the resolution
// (k = round(√Samples)), ribbons k sub-pixels wide, and a strand's opacity becomes screen-door
// coverage of each k×k block (an ordered threshold per sub-pixel: order-independent, no sorting, the
// same result on every run). A resolve pass box-filters each block: colour, hair opacity and shadow
// are averaged, Z is the nearest. (llvmpipe's multisampled lines cost four times as much.)
#include "libcore/render/renderer.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "glsl/embedded_glsl.h"
#include "libcore/render/gl_context.h"
#include "libcore/render/shader_interface.h"
#include "libcore/util/error.h"
#include "libcore/util/stopwatch.h"

namespace hairgen {

namespace {

[[noreturn]] void fail(const std::string& what) {
  throw Error(ExitCode::kWorkFailed, {}, "rendering: " + what);
}

void checkGl(const char* where) {
  GLenum e = glGetError();
  if (e != GL_NO_ERROR) {
    char code[16];
    std::snprintf(code, sizeof code, "0x%04x", e);
    fail(std::string("OpenGL error ") + code + " in " + where);
  }
}

// ------------------------------------------------------------------------------------ GL resources

class Shader {
 public:
  Shader(const std::string& vertex, const std::string& fragment, const char* name) {
    auto compile = [&](GLenum type, const std::string& text) {
      GLuint s = glCreateShader(type);
      const char* src = text.c_str();
      glShaderSource(s, 1, &src, nullptr);
      glCompileShader(s);
      GLint ok = 0;
      glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
      if (!ok) {
        char log[4096];
        glGetShaderInfoLog(s, sizeof log, nullptr, log);
        fail(std::string("compiling the ") + name + " shader: " + log);
      }
      return s;
    };
    GLuint v = compile(GL_VERTEX_SHADER, vertex), f = compile(GL_FRAGMENT_SHADER, fragment);
    id = glCreateProgram();
    glAttachShader(id, v);
    glAttachShader(id, f);
    glLinkProgram(id);
    glDeleteShader(v);
    glDeleteShader(f);
    GLint ok = 0;
    glGetProgramiv(id, GL_LINK_STATUS, &ok);
    if (!ok) {
      char log[4096];
      glGetProgramInfoLog(id, sizeof log, nullptr, log);
      fail(std::string("linking the ") + name + " shader: " + log);
    }
  }
  ~Shader() { glDeleteProgram(id); }
  GLuint id = 0;
  Shader(const Shader&) = delete;
  Shader& operator=(const Shader&) = delete;
  void use() const { glUseProgram(id); }
  GLint loc(const char* n) const { return glGetUniformLocation(id, n); }
  void set(const char* n, const glm::mat4& m) const {
    glUniformMatrix4fv(loc(n), 1, GL_FALSE, glm::value_ptr(m));
  }
  void set(const char* n, const glm::vec4& v) const { glUniform4fv(loc(n), 1, glm::value_ptr(v)); }
  void set(const char* n, const glm::vec3& v) const { glUniform3fv(loc(n), 1, glm::value_ptr(v)); }
  void set(const char* n, const glm::vec2& v) const { glUniform2fv(loc(n), 1, glm::value_ptr(v)); }
  void set(const char* n, float v) const { glUniform1f(loc(n), v); }
  void set(const char* n, int v) const { glUniform1i(loc(n), v); }
};

struct Texture {
  GLuint id = 0;
  Texture(GLenum internal, int w, int h, GLenum filter = GL_NEAREST) {
    glCreateTextures(GL_TEXTURE_2D, 1, &id);
    glTextureStorage2D(id, 1, internal, w, h);
    glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, filter);
    glTextureParameteri(id, GL_TEXTURE_MAG_FILTER, filter);
    glTextureParameteri(id, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(id, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  }
  ~Texture() { glDeleteTextures(1, &id); }
  Texture(const Texture&) = delete;
  Texture& operator=(const Texture&) = delete;
};

struct Framebuffer {
  GLuint id = 0, depth = 0;
  Framebuffer(std::initializer_list<const Texture*> colors, int w, int h, bool withDepth) {
    glCreateFramebuffers(1, &id);
    std::vector<GLenum> buffers;
    GLenum i = 0;
    for (const Texture* t : colors) {
      glNamedFramebufferTexture(id, GL_COLOR_ATTACHMENT0 + i, t->id, 0);
      buffers.push_back(GL_COLOR_ATTACHMENT0 + i++);
    }
    glNamedFramebufferDrawBuffers(id, static_cast<GLsizei>(buffers.size()), buffers.data());
    if (withDepth) {
      glCreateRenderbuffers(1, &depth);
      glNamedRenderbufferStorage(depth, GL_DEPTH_COMPONENT24, w, h);
      glNamedFramebufferRenderbuffer(id, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth);
    }
    if (glCheckNamedFramebufferStatus(id, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      fail("framebuffer incomplete");
  }
  ~Framebuffer() {
    glDeleteFramebuffers(1, &id);
    if (depth) glDeleteRenderbuffers(1, &depth);
  }
  Framebuffer(const Framebuffer&) = delete;
  Framebuffer& operator=(const Framebuffer&) = delete;
  void bind(int w, int h) const {
    glBindFramebuffer(GL_FRAMEBUFFER, id);
    glViewport(0, 0, w, h);
  }
};

struct Buffer {
  GLuint id = 0;
  Buffer(const void* data, size_t bytes) {
    glCreateBuffers(1, &id);
    glNamedBufferStorage(id, static_cast<GLsizeiptr>(std::max<size_t>(bytes, 4)), bytes ? data : nullptr, 0);
  }
  ~Buffer() { glDeleteBuffers(1, &id); }
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;
};

// Hair on the GPU: points and tangents in storage buffers; per strand a line strip (one vertex per
// point) or a triangle strip (two).
struct HairGeometry {
  Buffer points, tangents, colors, normals;
  bool hasColors, hasNormals;
  std::vector<GLint> lineFirsts, ribbonFirsts;
  std::vector<GLsizei> lineCounts, ribbonCounts;
  GLuint vao = 0;
  HairGeometry(const Strands& s, const std::vector<glm::vec3>& tangentData)
      : points(s.points.data(), s.points.size() * sizeof(glm::vec3)),
        tangents(tangentData.data(), tangentData.size() * sizeof(glm::vec3)),
        colors(s.colors.data(), s.colors.size() * sizeof(glm::vec3)),
        normals(s.normals.data(), s.normals.size() * sizeof(glm::vec3)),
        hasColors(!s.colors.empty()),
        hasNormals(!s.normals.empty()) {
    for (size_t i = 0; i < s.strandCount(); ++i) {
      if (s.pointsOf(i) < 2) continue;
      lineFirsts.push_back(static_cast<GLint>(s.firstPoint[i]));
      lineCounts.push_back(static_cast<GLsizei>(s.pointsOf(i)));
      ribbonFirsts.push_back(static_cast<GLint>(2 * s.firstPoint[i]));
      ribbonCounts.push_back(static_cast<GLsizei>(2 * s.pointsOf(i)));
    }
    glCreateVertexArrays(1, &vao);
    glVertexArrayVertexBuffer(vao, 0, points.id, 0, sizeof(glm::vec3));
    glVertexArrayVertexBuffer(vao, 1, tangents.id, 0, sizeof(glm::vec3));
    glVertexArrayVertexBuffer(vao, 2, colors.id, 0, sizeof(glm::vec3));
    glVertexArrayVertexBuffer(vao, 3, normals.id, 0, sizeof(glm::vec3));
    for (GLuint a = 0; a < 4; ++a) {
      if ((a == 2 && !hasColors) || (a == 3 && !hasNormals)) continue;  // constant attributes, set in draw()
      glEnableVertexArrayAttrib(vao, a);
      glVertexArrayAttribFormat(vao, a, 3, GL_FLOAT, GL_FALSE, 0);
      glVertexArrayAttribBinding(vao, a, a);
    }
  }
  ~HairGeometry() { glDeleteVertexArrays(1, &vao); }
  void draw(bool ribbon) const;
};

struct HeadGeometry {
  GLuint vao = 0, vbo = 0, ebo = 0;
  GLsizei indexCount = 0;
  explicit HeadGeometry(const Mesh& m) {
    std::vector<float> interleaved;
    interleaved.reserve(m.positions.size() * 6);
    for (size_t i = 0; i < m.positions.size(); ++i) {
      const glm::vec3 n = i < m.normals.size() ? m.normals[i] : glm::vec3(0, 1, 0);
      interleaved.insert(interleaved.end(),
                         {m.positions[i].x, m.positions[i].y, m.positions[i].z, n.x, n.y, n.z});
    }
    glCreateBuffers(1, &vbo);
    glNamedBufferStorage(vbo, static_cast<GLsizeiptr>(std::max<size_t>(interleaved.size() * 4, 4)),
                         interleaved.data(), 0);
    glCreateBuffers(1, &ebo);
    glNamedBufferStorage(ebo, static_cast<GLsizeiptr>(std::max<size_t>(m.triangles.size() * 12, 4)),
                         m.triangles.data(), 0);
    indexCount = static_cast<GLsizei>(m.triangles.size() * 3);
    glCreateVertexArrays(1, &vao);
    glVertexArrayVertexBuffer(vao, 0, vbo, 0, 6 * sizeof(float));
    glVertexArrayElementBuffer(vao, ebo);
    glEnableVertexArrayAttrib(vao, 0);
    glEnableVertexArrayAttrib(vao, 1);
    glVertexArrayAttribFormat(vao, 0, 3, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribFormat(vao, 1, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float));
    glVertexArrayAttribBinding(vao, 0, 0);
    glVertexArrayAttribBinding(vao, 1, 0);
  }
  ~HeadGeometry() {
    glDeleteVertexArrays(1, &vao);
    glDeleteBuffers(1, &vbo);
    glDeleteBuffers(1, &ebo);
  }
  void draw() const {
    glBindVertexArray(vao);
    glDrawElements(GL_TRIANGLES, indexCount, GL_UNSIGNED_INT, nullptr);
  }
};

void HairGeometry::draw(bool ribbon) const {
  glBindVertexArray(vao);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, points.id);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, tangents.id);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, colors.id);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, normals.id);
  if (!hasColors) glVertexAttrib3f(2, 1.0f, 1.0f, 1.0f);
  if (!hasNormals) glVertexAttrib3f(3, 0.0f, 0.0f, 0.0f);
  if (lineFirsts.empty()) return;
  if (ribbon)
    glMultiDrawArrays(GL_TRIANGLE_STRIP, ribbonFirsts.data(), ribbonCounts.data(),
                      static_cast<GLsizei>(ribbonFirsts.size()));
  else
    glMultiDrawArrays(GL_LINE_STRIP, lineFirsts.data(), lineCounts.data(),
                      static_cast<GLsizei>(lineFirsts.size()));
}

// ------------------------------------------------------------------------------------- the passes

struct View {
  glm::dmat4 view{1.0}, proj{1.0};
  double focalPx = 1.0;  // pixels per metre at one metre
  int width = 1, height = 1;
};

struct Sphere {
  glm::dvec3 centre{0.0};
  double radius = 0.0;
};

Sphere boundingSphere(const Strands& hair, const Mesh* head) {
  std::vector<glm::vec3> corners;
  for (const std::vector<glm::vec3>* points : {&hair.points, head ? &head->positions : nullptr})
    if (points && !points->empty()) {
      const Bounds b = bounds(*points);
      corners.insert(corners.end(), {b.min, b.max});
    }
  if (corners.empty()) return {glm::dvec3(0.0), 0.1};
  const Bounds box = bounds(corners);
  const glm::dvec3 lo(box.min), hi(box.max);
  return {(lo + hi) * 0.5, std::max(glm::length(hi - lo) * 0.5, 1e-3)};
}

glm::dvec3 anyUp(const glm::dvec3& forward, const glm::dvec3& preferred) {
  return std::abs(glm::dot(glm::normalize(forward), glm::normalize(preferred))) > 0.999 ? glm::dvec3(0, 0, 1)
                                                                                        : preferred;
}

View cameraView(const RenderSettings& r, const Sphere& scene) {
  View v;
  v.width = r.resolution.x;
  v.height = r.resolution.y;
  glm::dvec3 forward = r.cameraTarget - r.cameraPosition;
  v.view = glm::lookAt(r.cameraPosition, r.cameraTarget, anyUp(forward, r.cameraUp));
  double distance = glm::length(scene.centre - r.cameraPosition);
  double nearPlane = std::max(distance - scene.radius, 1e-3 * std::max(distance, 1e-3));
  double farPlane = distance + scene.radius * 1.01 + 1e-3;
  double fov = glm::radians(r.fieldOfView);
  v.proj = glm::perspective(fov, double(v.width) / v.height, nearPlane, farPlane);
  v.focalPx = 0.5 * v.height / std::tan(0.5 * fov);
  return v;
}

View lightView(const RenderSettings& r, const Sphere& scene, int size) {
  View v;
  v.width = v.height = size;
  glm::dvec3 forward = scene.centre - r.lightPosition;
  double distance = glm::length(forward);
  v.view = glm::lookAt(r.lightPosition, scene.centre, anyUp(forward, glm::dvec3(0, 1, 0)));
  double fov =
      distance > scene.radius * 1.05 ? 2.0 * std::asin(scene.radius / distance) * 1.02 : glm::radians(120.0);
  double nearPlane = std::max(distance - scene.radius * 1.01, 1e-3 * std::max(distance, 1e-3));
  v.proj = glm::perspective(fov, 1.0, nearPlane, distance + scene.radius * 1.01 + 1e-3);
  v.focalPx = 0.5 * size / std::tan(0.5 * fov);
  return v;
}

void setView(const Shader& s, const View& v) {
  s.set("uView", glm::mat4(v.view));
  s.set("uProj", glm::mat4(v.proj));
}

void setHairWidth(const Shader& s, const View& v, const RenderSettings& r) {
  s.set("uViewport", glm::vec2(v.width, v.height));
  s.set("uFocalPx", float(v.focalPx));
  s.set("uWidth", float(r.strandWidth));
  s.set("uOpacity", float(r.strandOpacity));
}

// Reads `count` float channels of a single-sample RGBA32F texture into planes, rows top to bottom.
void readPlanes(GLuint texture, int w, int h, std::vector<std::vector<float>*> planes) {
  std::vector<float> rgba(size_t(w) * h * 4);
  glGetTextureImage(texture, 0, GL_RGBA, GL_FLOAT, static_cast<GLsizei>(rgba.size() * sizeof(float)),
                    rgba.data());
  for (size_t c = 0; c < planes.size(); ++c) {
    if (!planes[c]) continue;
    planes[c]->resize(size_t(w) * h);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) (*planes[c])[size_t(h - 1 - y) * w + x] = rgba[(size_t(y) * w + x) * 4 + c];
  }
}

// Threshold ranks for a k×k block that spread each coverage level evenly: Bayer's matrices for powers
// of two, a magic-square order for 3, a sheared order otherwise (k ≤ 8).
std::vector<int> ditherOrder(int k) {
  std::vector<int> order(size_t(k) * k);
  if ((k & (k - 1)) == 0) {
    for (int y = 0; y < k; ++y)
      for (int x = 0; x < k; ++x) {
        int v = 0;
        for (int bit = k >> 1, weight = 1; bit > 0; bit >>= 1, weight <<= 2) {
          bool bx = x & bit, by = y & bit;
          v += weight * ((bx != by ? 2 : 0) + (by ? 1 : 0));
        }
        order[size_t(y) * k + x] = v;
      }
    // v was built least-significant level last; reverse the base-4 digits so the coarsest level leads.
    int levels = 0;
    for (int t = k; t > 1; t >>= 1) ++levels;
    for (int& v : order) {
      int r = 0;
      for (int l = 0; l < levels; ++l) r = r * 4 + ((v >> (2 * l)) & 3);
      v = r;
    }
  } else if (k == 3) {
    order = {0, 7, 3, 6, 5, 2, 4, 1, 8};
  } else {
    for (int y = 0; y < k; ++y)
      for (int x = 0; x < k; ++x) order[size_t(y) * k + x] = ((x + y * k) * (k + 1)) % (k * k);
  }
  return order;
}

// A pass's time: the GPU's queue drained first, so the time is the pass's and not the next one's.
double seconds(Stopwatch& clock) {
  glFinish();
  return clock.lap();
}

}  // namespace

RenderOutput renderHair(GlContext&, const RenderInput& in) {
  const RenderSettings& r = in.settings;
  const Strands& hair = *in.hair;
  RenderOutput out;
  Stopwatch clock;
  while (glGetError() != GL_NO_ERROR) {
  }

  GLint maxSize = 4096;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &maxSize);
  int block = std::max(1, int(std::lround(std::sqrt(double(r.samples)))));
  block = std::min(block, 8);
  while (block > 1 && std::max(r.resolution.x, r.resolution.y) * block > maxSize) --block;
  out.samples = block * block;

  const Sphere scene = boundingSphere(hair, in.head);
  const View camera = cameraView(r, scene);
  const View light = lightView(r, scene, in.domResolution);
  out.worldToCamera = camera.view;
  out.worldToNdc = camera.proj * camera.view;
  out.worldToLight = light.proj * light.view;

  const HairGeometry hairGeometry(hair, tangentsOf(hair));
  std::unique_ptr<HeadGeometry> headGeometry;
  if (in.head && !in.head->triangles.empty()) headGeometry = std::make_unique<HeadGeometry>(*in.head);
  auto stage = [](const char* body, StagePrelude prelude = {}) { return assembleStage(prelude, body); };
  Shader hairDepth(stage(glsl::kHairVertex), stage(glsl::kDepthFragment), "hair depth");
  Shader headDepth(stage(glsl::kHeadVertex), stage(glsl::kDepthFragment), "head depth");
  Shader opacity(stage(glsl::kHairVertex), stage(glsl::kOpacityFragment), "deep opacity");
  // Lines where every strand is at most a pixel and a half wide (at the scene's nearest point) and
  // there are no sub-pixels; ribbons otherwise.
  const double nearest = std::max(glm::length(scene.centre - r.cameraPosition) - scene.radius, 1e-3);
  const bool ribbons = block > 1 || r.strandWidth * camera.focalPx / nearest > 1.5;
  Shader hairShade(
      stage(glsl::kHairVertex, {.ribbon = ribbons}),
      stage(glsl::kHairFragment, {.ribbon = ribbons, .shadowFunction = true, .screenDoor = true}),
      "hair shading");
  Shader headShade(stage(glsl::kHeadVertex), stage(glsl::kHeadFragment, {.shadowFunction = true}),
                   "head shading");
  Shader resolve(stage(glsl::kFullscreenVertex), stage(glsl::kResolveFragment), "resolve");
  checkGl("setting up");
  out.timings.upload = seconds(clock);

  // Pass 1: from the light, where the head is (an opaque occluder) and where the hair begins.
  const int n = in.domResolution;
  const float far[4] = {kBackgroundZ, kBackgroundZ, kBackgroundZ, kBackgroundZ};
  const float one = 1.0f;
  Texture headZ(GL_R32F, n, n), startZ(GL_R32F, n, n);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDisable(GL_CULL_FACE);
  {
    Framebuffer fb({&headZ}, n, n, true);
    fb.bind(n, n);
    glClearBufferfv(GL_COLOR, 0, far);
    glClearBufferfv(GL_DEPTH, 0, &one);
    if (headGeometry) {
      headDepth.use();
      setView(headDepth, light);
      headGeometry->draw();
    }
  }
  {
    Framebuffer fb({&startZ}, n, n, true);
    fb.bind(n, n);
    glClearBufferfv(GL_COLOR, 0, far);
    glClearBufferfv(GL_DEPTH, 0, &one);
    hairDepth.use();
    setView(hairDepth, light);
    setHairWidth(hairDepth, light, r);
    hairGeometry.draw(false);
  }
  checkGl("the light's depth pass");
  out.timings.lightDepth = seconds(clock);

  // Pass 2: the deep opacity map, four layers from where the hair begins, added up.
  Texture opacityMap(GL_RGBA32F, n, n, GL_LINEAR);
  {
    Framebuffer fb({&opacityMap}, n, n, false);
    fb.bind(n, n);
    const float zero[4] = {0, 0, 0, 0};
    glClearBufferfv(GL_COLOR, 0, zero);
    glDisable(GL_DEPTH_TEST);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    opacity.use();
    setView(opacity, light);
    setHairWidth(opacity, light, r);
    opacity.set("uLayers", glm::vec4(r.layerSizes));
    glBindTextureUnit(kUnitHairStart, startZ.id);
    hairGeometry.draw(false);
    glDisable(GL_BLEND);
  }
  checkGl("the deep opacity pass");
  out.timings.opacity = seconds(clock);

  // Pass 3: shading from the camera, then the resolve.
  const int w = camera.width, h = camera.height, sw = w * block, sh = h * block;
  View fine = camera;  // the same camera on the sub-pixel grid
  fine.width = sw;
  fine.height = sh;
  fine.focalPx = camera.focalPx * block;
  Texture color(GL_RGBA16F, sw, sh), data(GL_RGBA32F, sw, sh);
  {
    Framebuffer fb({&color, &data}, sw, sh, true);
    fb.bind(sw, sh);
    const float background[4] = {float(r.background.x), float(r.background.y), float(r.background.z), 0.0f};
    const float nothing[4] = {kBackgroundZ, 0.0f, 1.0f, 0.0f};
    glClearBufferfv(GL_COLOR, 0, background);
    glClearBufferfv(GL_COLOR, 1, nothing);
    glClearBufferfv(GL_DEPTH, 0, &one);
    glEnable(GL_DEPTH_TEST);
    auto shadowUniforms = [&](const Shader& s) {
      s.set("uLightView", glm::mat4(light.view));
      s.set("uLightProj", glm::mat4(light.proj));
      s.set("uLayers", glm::vec4(r.layerSizes));
      s.set("uLightPosition", glm::vec3(r.lightPosition));
      s.set("uLightColor", glm::vec3(r.lightColor));
      s.set("uAmbient", float(r.ambientIntensity));
    };
    glBindTextureUnit(kUnitHairStart, startZ.id);
    glBindTextureUnit(kUnitHeadDepth, headZ.id);
    glBindTextureUnit(kUnitOpacityMap, opacityMap.id);
    if (headGeometry) {
      headShade.use();
      setView(headShade, fine);
      shadowUniforms(headShade);
      headShade.set("uHeadColor", glm::vec3(r.headColor));
      headGeometry->draw();
    }
    hairShade.use();
    setView(hairShade, fine);
    setHairWidth(hairShade, fine, r);
    hairShade.set("uMinWidth", float(block));
    hairShade.set("uBlock", block);
    const std::vector<int> order = ditherOrder(block);
    glUniform1iv(hairShade.loc("uOrder"), static_cast<GLsizei>(order.size()), order.data());
    shadowUniforms(hairShade);
    hairShade.set("uEye", glm::vec3(r.cameraPosition));
    hairShade.set("uAmbientColor", glm::vec3(in.visuality.ambientColor));
    hairShade.set("uDiffuseColor", glm::vec3(in.visuality.diffuseColor));
    hairShade.set("uSpecularColor", glm::vec3(in.visuality.specularColor));
    hairShade.set("uGlossiness", float(in.visuality.glossiness));
    hairShade.set("uModel", static_cast<int>(r.shadingModel));
    hairShade.set("uBlend", float(r.volumetricBlend));
    hairShade.set("uHasColor", hair.colors.empty() ? 0 : 1);
    hairShade.set("uHasNormal", hair.normals.empty() ? 0 : 1);
    hairGeometry.draw(ribbons);
  }
  Texture resolvedColor(GL_RGBA32F, w, h), resolvedData(GL_RGBA32F, w, h);
  {
    Framebuffer fb({&resolvedColor, &resolvedData}, w, h, false);
    fb.bind(w, h);
    glDisable(GL_DEPTH_TEST);
    resolve.use();
    resolve.set("uBlock", block);
    glBindTextureUnit(kUnitSubpixelColor, color.id);
    glBindTextureUnit(kUnitSubpixelData, data.id);
    glBindVertexArray(hairGeometry.vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
  }
  checkGl("the shading pass");
  out.timings.shading = seconds(clock);

  Image& b = out.beauty;
  b.width = w;
  b.height = h;
  b.channels = {"R", "G", "B", "A", "Z", "opacity", "shadow"};
  b.planes.resize(b.channels.size());
  readPlanes(resolvedColor.id, w, h, {&b.planes[0], &b.planes[1], &b.planes[2], &b.planes[3]});
  readPlanes(resolvedData.id, w, h, {&b.planes[4], &b.planes[5], &b.planes[6]});
  if (in.keepDom) {
    Image& d = out.dom;
    d.width = d.height = n;
    d.channels = {"Z", "layer1", "layer2", "layer3", "layer4"};
    d.planes.resize(5);
    readPlanes(startZ.id, n, n, {&d.planes[0]});
    readPlanes(opacityMap.id, n, n, {&d.planes[1], &d.planes[2], &d.planes[3], &d.planes[4]});
  }
  checkGl("reading the images back");
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  out.timings.readback = seconds(clock);
  return out;
}

}  // namespace hairgen
