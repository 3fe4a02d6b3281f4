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

#include "libcore/render/gl_context.h"
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

// ---------------------------------------------------------------------------------------------- GLSL

// Hair points and tangents arrive as vertex attributes for lines (one vertex per point), or from
// storage buffers for ribbons (two vertices per point; RIBBON defined).
constexpr const char* kHairVertex = R"(
#ifdef RIBBON
layout(std430, binding = 0) readonly buffer Points { float pointData[]; };
layout(std430, binding = 1) readonly buffer Tangents { float tangentData[]; };
layout(std430, binding = 2) readonly buffer Colours { float colourData[]; };
layout(std430, binding = 3) readonly buffer Normals { float normalData[]; };
uniform int uHasColour;
uniform int uHasNormal;
#else
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aTangent;
layout(location = 2) in vec3 aColour;  // (1, 1, 1) when the cache has no colours
layout(location = 3) in vec3 aNormal;  // (0, 0, 0) when the cache has no normals
#endif
uniform mat4 uView;
uniform mat4 uProj;
uniform vec2 uViewport;   // pixels
uniform float uFocalPx;   // pixels per metre at one metre of depth
uniform float uWidth;     // strand diameter, metres
uniform float uOpacity;
uniform float uMinWidth;  // pixels: the narrowest ribbon
out vec3 vWorld;
out vec3 vTangent;
out vec3 vColour;
out vec3 vNormal;
out float vAlpha;
out float vDepth;         // metres along the view axis
void main() {
#ifdef RIBBON
  int i = gl_VertexID >> 1;
  vec3 p = vec3(pointData[3 * i], pointData[3 * i + 1], pointData[3 * i + 2]);
  vec3 t = vec3(tangentData[3 * i], tangentData[3 * i + 1], tangentData[3 * i + 2]);
  vColour = uHasColour != 0 ? vec3(colourData[3 * i], colourData[3 * i + 1], colourData[3 * i + 2]) : vec3(1.0);
  vNormal = uHasNormal != 0 ? vec3(normalData[3 * i], normalData[3 * i + 1], normalData[3 * i + 2]) : vec3(0.0);
#else
  vec3 p = aPosition;
  vec3 t = aTangent;
  vColour = aColour;
  vNormal = aNormal;
#endif
  vec4 view = uView * vec4(p, 1.0);
  vec4 clip = uProj * view;
  float depth = -view.z;
#ifdef RIBBON
  float side = (gl_VertexID & 1) == 0 ? -1.0 : 1.0;
  vec4 ahead = uProj * (view + uView * vec4(1e-3 * t, 0.0));
  vec2 d = (ahead.xy / ahead.w - clip.xy / clip.w) * uViewport;
  float len = length(d);
  vec2 across = len > 1e-9 ? vec2(-d.y, d.x) / len : vec2(1.0, 0.0);
  float widthPx = uWidth * uFocalPx / max(depth, 1e-6);
  clip.xy += across * (side * 0.5 * max(widthPx, uMinWidth)) * 2.0 / uViewport * clip.w;
#endif
  gl_Position = clip;
  vWorld = p;
  vTangent = t;
  vAlpha = uOpacity;
  vDepth = depth;
}
)";

constexpr const char* kHeadVertex = R"(#version 450 core
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aNormal;
uniform mat4 uView;
uniform mat4 uProj;
out vec3 vWorld;
out vec3 vNormal;
out float vDepth;
void main() {
  vec4 view = uView * vec4(aPosition, 1.0);
  gl_Position = uProj * view;
  vWorld = aPosition;
  vNormal = aNormal;
  vDepth = -view.z;
}
)";

// Distance along the light's axis, for both depth maps.
constexpr const char* kDepthFragment = R"(#version 450 core
in float vDepth;
layout(location = 0) out float oDepth;
void main() { oDepth = vDepth; }
)";

// The deep opacity map: a fragment adds its opacity to its layer and every layer behind it; one past
// the last layer counts in the last.
constexpr const char* kOpacityFragment = R"(#version 450 core
in float vDepth;
in float vAlpha;
uniform sampler2D uStart;
uniform vec4 uLayers;
layout(location = 0) out vec4 oOpacity;
void main() {
  float z0 = texelFetch(uStart, ivec2(gl_FragCoord.xy), 0).r;
  vec4 ends = z0 + vec4(uLayers.x, uLayers.x + uLayers.y, uLayers.x + uLayers.y + uLayers.z,
                        uLayers.x + uLayers.y + uLayers.z + uLayers.w);
  float a = vAlpha;
  oOpacity = vec4(vDepth < ends.x ? a : 0.0, vDepth < ends.y ? a : 0.0, vDepth < ends.z ? a : 0.0, a);
}
)";

// Shared by the hair and head shading fragments: the light that reaches a world point.
constexpr const char* kShadowFunction = R"(
uniform mat4 uLightView;
uniform mat4 uLightProj;
uniform sampler2D uStart;
uniform sampler2D uHeadDepth;
uniform sampler2D uOpacityMap;
uniform vec4 uLayers;
uniform float uHeadBias;
// `bias`: metres toward the light, so a surface does not shadow itself through the maps' resolution.
float lightArriving(vec3 world, float bias) {
  vec4 lv = uLightView * vec4(world, 1.0);
  float z = -lv.z - bias;
  vec4 c = uLightProj * lv;
  vec2 uv = c.xy / c.w * 0.5 + 0.5;
  if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) return 1.0;
  if (z > texture(uHeadDepth, uv).r + uHeadBias) return 0.25;  // the head is in the way: opaque
  // Over the 2×2 texels around the point: where the hair begins nearest, and each layer's largest
  // opacity, so a strand one texel wide still shadows what lies behind it.
  vec4 starts = textureGather(uStart, uv, 0);
  float z0 = min(min(starts.x, starts.y), min(starts.z, starts.w));
  vec4 g0 = textureGather(uOpacityMap, uv, 0), g1 = textureGather(uOpacityMap, uv, 1);
  vec4 g2 = textureGather(uOpacityMap, uv, 2), g3 = textureGather(uOpacityMap, uv, 3);
  vec4 op = vec4(max(max(g0.x, g0.y), max(g0.z, g0.w)), max(max(g1.x, g1.y), max(g1.z, g1.w)),
                 max(max(g2.x, g2.y), max(g2.z, g2.w)), max(max(g3.x, g3.y), max(g3.z, g3.w)));
  vec4 ends = z0 + vec4(uLayers.x, uLayers.x + uLayers.y, uLayers.x + uLayers.y + uLayers.z,
                        uLayers.x + uLayers.y + uLayers.z + uLayers.w);
  float s;
  if (z <= z0) s = 0.0;
  else if (z < ends.x) s = mix(0.0, op.r, (z - z0) / uLayers.x);
  else if (z < ends.y) s = mix(op.r, op.g, (z - ends.x) / uLayers.y);
  else if (z < ends.z) s = mix(op.g, op.b, (z - ends.y) / uLayers.z);
  else if (z < ends.w) s = mix(op.b, op.a, (z - ends.z) / uLayers.w);
  else s = op.a;
  return 1.0 - 0.75 * clamp(s, 0.0, 1.0);
}
)";

constexpr const char* kHairFragment = R"(
in vec3 vWorld;
in vec3 vTangent;
in vec3 vColour;
in vec3 vNormal;
in float vAlpha;
in float vDepth;
uniform vec3 uEye;
uniform vec3 uLightPosition;
uniform vec3 uLightColor;
uniform float uAmbient;
uniform vec3 uAmbientColor;
uniform vec3 uDiffuseColor;
uniform vec3 uSpecularColor;
uniform float uGlossiness;
uniform int uModel;       // 0 Kajiya-Kay, 1 the thesis' variant, 2 Anjyo, 3 volumetric
uniform float uBlend;     // volumetric: its share against Kajiya-Kay
uniform int uBlock;       // k: sub-pixels per pixel side
uniform int uOrder[64];   // the screen door's threshold rank of each sub-pixel of a block, row by row
layout(location = 0) out vec4 oColor;
layout(location = 1) out vec4 oData;  // Z, hair opacity, shadow
void main() {
  if (uBlock > 1) {
    // Screen door: the sub-pixel of rank j in its k×k block keeps the fragment when alpha > (j + 0.5)/k²,
    // so a block's coverage is alpha to within 1/k².
    ivec2 q = ivec2(gl_FragCoord.xy) % uBlock;
    int j = uOrder[q.y * uBlock + q.x];
    if (vAlpha <= (float(j) + 0.5) / float(uBlock * uBlock)) discard;
  }
  vec3 t = normalize(vTangent);
  vec3 l = normalize(uLightPosition - vWorld);
  vec3 e = normalize(uEye - vWorld);
  float tl = dot(t, l), te = dot(t, e);
  float sinTL = sqrt(max(0.0, 1.0 - tl * tl)), sinTE = sqrt(max(0.0, 1.0 - te * te));
  float diffuse = sinTL, specular;
  if (uModel == 2) {
    float th = dot(t, normalize(l + e));
    specular = pow(max(1.0 - th * th, 0.0), 0.5 * uGlossiness);
    diffuse = 0.0;
  } else {
    float cone = uModel == 1 ? abs(tl) * abs(te) + sinTL * sinTE : -tl * te + sinTL * sinTE;
    specular = pow(max(cone, 0.0), uGlossiness);
  }
  float shadow = lightArriving(vWorld, 0.001);
  vec3 colour = uAmbient * uAmbientColor * vColour +
                shadow * uLightColor * (uDiffuseColor * vColour * diffuse + uSpecularColor * specular);
  if (uModel == 3) {
    // The strand as a point of the hair's surface, lit about the volume normal.
    vec3 n = dot(vNormal, vNormal) > 0.0 ? normalize(vNormal) : vec3(0.0);
    float surfaceDiffuse = max(dot(n, l), 0.0);
    float phong = pow(max(dot(reflect(-l, n), e), 0.0), uGlossiness);
    vec3 volumetric = uAmbient * uAmbientColor * vColour +
                      shadow * uLightColor * (uDiffuseColor * vColour * surfaceDiffuse + uSpecularColor * phong);
    colour = mix(colour, volumetric, uBlend);
  }
  oColor = vec4(colour, vAlpha);
  oData = vec4(vDepth, 1.0, shadow, 0.0);
}
)";

constexpr const char* kHeadFragment = R"(
in vec3 vWorld;
in vec3 vNormal;
in float vDepth;
uniform vec3 uLightPosition;
uniform vec3 uLightColor;
uniform float uAmbient;
uniform vec3 uHeadColor;
layout(location = 0) out vec4 oColor;
layout(location = 1) out vec4 oData;  // Z, hair opacity, shadow
void main() {
  vec3 n = normalize(vNormal);
  vec3 l = normalize(uLightPosition - vWorld);
  // Looked up a little off the surface, so the head does not shadow itself where it faces the light.
  float shadow = lightArriving(vWorld + 0.002 * n, 0.0);
  vec3 colour = uAmbient * uHeadColor + shadow * uLightColor * uHeadColor * max(dot(n, l), 0.0);
  oColor = vec4(colour, 1.0);
  oData = vec4(vDepth, 0.0, shadow, 0.0);
}
)";

constexpr const char* kFullscreenVertex = R"(#version 450 core
void main() {
  vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
  gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
)";

// Box-filters each k×k block of sub-pixels: colour, hair opacity and shadow averaged, Z the nearest.
constexpr const char* kResolveFragment = R"(#version 450 core
uniform sampler2D uColor;
uniform sampler2D uData;
uniform int uBlock;
layout(location = 0) out vec4 oColor;
layout(location = 1) out vec4 oData;
void main() {
  ivec2 p = ivec2(gl_FragCoord.xy) * uBlock;
  vec4 colour = vec4(0.0);
  float z = 3.0e38, opacity = 0.0, shadow = 0.0;
  for (int y = 0; y < uBlock; ++y)
    for (int x = 0; x < uBlock; ++x) {
      colour += texelFetch(uColor, p + ivec2(x, y), 0);
      vec4 data = texelFetch(uData, p + ivec2(x, y), 0);
      z = min(z, data.x);
      opacity += data.y;
      shadow += data.z;
    }
  float n = float(uBlock * uBlock);
  oColor = colour / n;
  oData = vec4(z, opacity / n, shadow / n, 0.0);
}
)";

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
  Framebuffer(std::initializer_list<const Texture*> colours, int w, int h, bool withDepth) {
    glCreateFramebuffers(1, &id);
    std::vector<GLenum> buffers;
    GLenum i = 0;
    for (const Texture* t : colours) {
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
  Buffer points, tangents, colours, normals;
  bool hasColours, hasNormals;
  std::vector<GLint> lineFirsts, ribbonFirsts;
  std::vector<GLsizei> lineCounts, ribbonCounts;
  GLuint vao = 0;
  HairGeometry(const Strands& s, const std::vector<glm::vec3>& tangentData)
      : points(s.points.data(), s.points.size() * sizeof(glm::vec3)),
        tangents(tangentData.data(), tangentData.size() * sizeof(glm::vec3)),
        colours(s.colors.data(), s.colors.size() * sizeof(glm::vec3)),
        normals(s.normals.data(), s.normals.size() * sizeof(glm::vec3)),
        hasColours(!s.colors.empty()),
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
    glVertexArrayVertexBuffer(vao, 2, colours.id, 0, sizeof(glm::vec3));
    glVertexArrayVertexBuffer(vao, 3, normals.id, 0, sizeof(glm::vec3));
    for (GLuint a = 0; a < 4; ++a) {
      if ((a == 2 && !hasColours) || (a == 3 && !hasNormals)) continue;  // constant attributes, set in draw()
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
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, colours.id);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, normals.id);
  if (!hasColours) glVertexAttrib3f(2, 1.0f, 1.0f, 1.0f);
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
  const std::string v450 = "#version 450 core\n";
  Shader hairDepth(v450 + kHairVertex, kDepthFragment, "hair depth");
  Shader headDepth(kHeadVertex, kDepthFragment, "head depth");
  Shader opacity(v450 + kHairVertex, kOpacityFragment, "deep opacity");
  // Lines where every strand is at most a pixel and a half wide (at the scene's nearest point) and
  // there are no sub-pixels; ribbons otherwise.
  const double nearest = std::max(glm::length(scene.centre - r.cameraPosition) - scene.radius, 1e-3);
  const bool ribbons = block > 1 || r.strandWidth * camera.focalPx / nearest > 1.5;
  Shader hairShade(v450 + (ribbons ? "#define RIBBON\n" : "") + kHairVertex,
                   v450 + kShadowFunction + kHairFragment, "hair shading");
  Shader headShade(kHeadVertex, v450 + kShadowFunction + kHeadFragment, "head shading");
  Shader resolve(kFullscreenVertex, kResolveFragment, "resolve");
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
    opacity.set("uStart", 0);
    glBindTextureUnit(0, startZ.id);
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
  Texture colour(GL_RGBA16F, sw, sh), data(GL_RGBA32F, sw, sh);
  {
    Framebuffer fb({&colour, &data}, sw, sh, true);
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
      s.set("uHeadBias", 0.003f);
      s.set("uStart", 0);
      s.set("uHeadDepth", 1);
      s.set("uOpacityMap", 2);
      s.set("uLightPosition", glm::vec3(r.lightPosition));
      s.set("uLightColor", glm::vec3(r.lightColor));
      s.set("uAmbient", float(r.ambientIntensity));
    };
    glBindTextureUnit(0, startZ.id);
    glBindTextureUnit(1, headZ.id);
    glBindTextureUnit(2, opacityMap.id);
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
    hairShade.set("uModel", r.shadingModel == ShadingModel::kThesis       ? 1
                            : r.shadingModel == ShadingModel::kAnjyo      ? 2
                            : r.shadingModel == ShadingModel::kVolumetric ? 3
                                                                          : 0);
    hairShade.set("uBlend", float(r.volumetricBlend));
    hairShade.set("uHasColour", hair.colors.empty() ? 0 : 1);
    hairShade.set("uHasNormal", hair.normals.empty() ? 0 : 1);
    hairGeometry.draw(ribbons);
  }
  Texture resolvedColour(GL_RGBA32F, w, h), resolvedData(GL_RGBA32F, w, h);
  {
    Framebuffer fb({&resolvedColour, &resolvedData}, w, h, false);
    fb.bind(w, h);
    glDisable(GL_DEPTH_TEST);
    resolve.use();
    resolve.set("uBlock", block);
    resolve.set("uColor", 0);
    resolve.set("uData", 1);
    glBindTextureUnit(0, colour.id);
    glBindTextureUnit(1, data.id);
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
  readPlanes(resolvedColour.id, w, h, {&b.planes[0], &b.planes[1], &b.planes[2], &b.planes[3]});
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
