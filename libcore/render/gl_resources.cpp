#include "libcore/render/gl_resources.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <limits>
#include <utility>

#include <glm/gtc/type_ptr.hpp>

#include "libcore/render/custom_shaders.h"
#include "libcore/render/gl_context.h"
#include "libcore/render/line_decimation.h"
#include "libcore/render/shader_interface.h"
#include "libcore/util/error.h"
#include "libcore/util/huge_pages.h"

namespace hairgen {

void renderFailure(const std::string& what) {
  throw Error(ExitCode::kWorkFailed, {}, "rendering: " + what);
}

void checkGl(const char* where) {
  GLenum e = glGetError();
  if (e != GL_NO_ERROR) {
    char code[16];
    std::snprintf(code, sizeof code, "0x%04x", e);
    renderFailure(std::string("OpenGL error ") + code + " in " + where);
  }
}

void clearGlErrors() {
  while (glGetError() != GL_NO_ERROR) {
  }
}

// ------------------------------------------------------------------------------------------ Program

namespace {

std::string infoLog(GLuint object, bool program) {
  GLint length = 0;
  if (program)
    glGetProgramiv(object, GL_INFO_LOG_LENGTH, &length);
  else
    glGetShaderiv(object, GL_INFO_LOG_LENGTH, &length);
  std::string log(size_t(std::max(length, 1)), '\0');
  if (program)
    glGetProgramInfoLog(object, length, nullptr, log.data());
  else
    glGetShaderInfoLog(object, length, nullptr, log.data());
  return log.c_str();
}

// "HairFrag for ribbons, named at setup.txt:9"
std::string origin(const StageSource& s) {
  std::string text = s.key;
  if (*s.variant) text += std::string(" ") + s.variant;
  if (!s.custom->namedAt.empty()) text += ", named at " + s.custom->namedAt;
  return text;
}

std::function<void(GLenum, const StageSource&, const char*)> gWatchStages;

GLuint compileStage(GLenum type, const StageSource& source, const char* program) {
  if (gWatchStages) gWatchStages(type, source, program);
  GLuint s = glCreateShader(type);
  const char* text = source.text.c_str();
  glShaderSource(s, 1, &text, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (ok) return s;
  const std::string log = infoLog(s, false);
  glDeleteShader(s);
  const CompilerMessage error = firstCompilerError(log);
  if (source.custom)
    throw InputError({source.custom->file, error.line}, error.text + " (compiling " + origin(source) + ")");
  renderFailure(std::string("compiling the ") + program + " program's " +
                (type == GL_VERTEX_SHADER    ? "vertex"
                 : type == GL_COMPUTE_SHADER ? "compute"
                                             : "fragment") +
                " stage: line " + std::to_string(error.line) + ": " + error.text);
}

// The compiled `stages` linked into a program, and deleted: the program, or 0 with the linker's first
// error in `error`.
GLuint linkStages(std::initializer_list<GLuint> stages, CompilerMessage& error) {
  const GLuint linked = glCreateProgram();
  for (const GLuint s : stages) glAttachShader(linked, s);
  glLinkProgram(linked);
  for (const GLuint s : stages) glDeleteShader(s);
  GLint ok = 0;
  glGetProgramiv(linked, GL_LINK_STATUS, &ok);
  if (ok) return linked;
  error = firstCompilerError(infoLog(linked, true));
  glDeleteProgram(linked);
  return 0;
}

}  // namespace

namespace {

// A linked program kept by the context (GlContext::kept) for every Program made from the same GLSL.
struct LinkedProgram {
  GLuint id = 0;
  ~LinkedProgram() { glDeleteProgram(id); }
};

}  // namespace

namespace {

// A program linked by `link()` once per context: kept there under `key`, the text of its stages, which
// is all a program is made from (a custom stage's file and Setup line only name it in errors, and an
// error keeps nothing). With no GlContext current, linked for the caller alone (`owned`).
template <class Link>
GLuint linkedOnce(const std::string& key, Link&& link, bool& owned) {
  GlContext* gl = GlContext::current();
  if (!gl) {
    owned = true;
    return link();
  }
  return gl
      ->kept<LinkedProgram>(key,
                            [&] {
                              auto linked = std::make_unique<LinkedProgram>();
                              linked->id = link();
                              return linked;
                            })
      .id;
}

}  // namespace

void watchStages(std::function<void(GLenum, const StageSource&, const char*)> watch) {
  gWatchStages = std::move(watch);
}

// (In the body: owned_ is initialised after id.)
Program::Program(const StageSource& vertex, const StageSource& fragment, const char* name) {
  id = linkedOnce(
      vertex.text + '\0' + fragment.text, [&] { return link(vertex, fragment, name); }, owned_);
}

Program::Program(const StageSource& compute, const char* name) {
  id = linkedOnce(
      std::string("compute") + '\0' + compute.text, [&] { return linkCompute(compute, name); }, owned_);
}

GLuint Program::linkCompute(const StageSource& compute, const char* name) {
  CompilerMessage error;
  if (const GLuint linked = linkStages({compileStage(GL_COMPUTE_SHADER, compute, name)}, error))
    return linked;
  renderFailure(std::string("linking the ") + name + " program: " + error.text);
}

GLuint Program::link(const StageSource& vertex, const StageSource& fragment, const char* name) {
  const GLuint v = compileStage(GL_VERTEX_SHADER, vertex, name);
  GLuint f = 0;
  try {
    f = compileStage(GL_FRAGMENT_SHADER, fragment, name);
  } catch (...) {
    glDeleteShader(v);
    throw;
  }
  CompilerMessage error;
  if (const GLuint linked = linkStages({v, f}, error)) return linked;
  // A link error is about the two stages together: it names the custom one (the fragment stage's file
  // when both are), and the other.
  const StageSource* blamed = fragment.custom ? &fragment : vertex.custom ? &vertex : nullptr;
  if (!blamed) renderFailure(std::string("linking the ") + name + " program: " + error.text);
  const StageSource& other = blamed == &fragment ? vertex : fragment;
  const std::string otherStage =
      other.custom ? other.custom->file + " (" + origin(other) + ")"
                   : std::string("hairgen's ") + (&other == &vertex ? "vertex" : "fragment") + " stage";
  throw InputError({blamed->custom->file, 0}, error.text + " (linking " + origin(*blamed) + ", with " +
                                                  otherStage + ", into the " + name + " program)");
}

Program::~Program() {
  if (owned_) glDeleteProgram(id);
}

void Program::use() const {
  glUseProgram(id);
}

GLint Program::loc(const char* name) const {
  return glGetUniformLocation(id, name);
}

void Program::set(const char* name, const glm::mat4& m) const {
  glUniformMatrix4fv(loc(name), 1, GL_FALSE, glm::value_ptr(m));
}
void Program::set(const char* name, const glm::vec4& v) const {
  glUniform4fv(loc(name), 1, glm::value_ptr(v));
}
void Program::set(const char* name, const glm::vec3& v) const {
  glUniform3fv(loc(name), 1, glm::value_ptr(v));
}
void Program::set(const char* name, const glm::vec2& v) const {
  glUniform2fv(loc(name), 1, glm::value_ptr(v));
}
void Program::set(const char* name, float v) const {
  glUniform1f(loc(name), v);
}
void Program::set(const char* name, int v) const {
  glUniform1i(loc(name), v);
}
void Program::set(const char* name, const std::vector<int>& v) const {
  glUniform1iv(loc(name), static_cast<GLsizei>(v.size()), v.data());
}

// ------------------------------------------------------------------------- Texture, Framebuffer, Buffer

Texture::Texture(GLenum internalFormat, int w, int h, GLenum filter) : width(w), height(h) {
  glCreateTextures(GL_TEXTURE_2D, 1, &id);
  glTextureStorage2D(id, 1, internalFormat, w, h);
  glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, filter);
  glTextureParameteri(id, GL_TEXTURE_MAG_FILTER, filter);
  glTextureParameteri(id, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(id, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
}

Texture::Texture(Texture&& other) noexcept
    : id(std::exchange(other.id, 0)), width(other.width), height(other.height) {}

Texture::~Texture() {
  if (id) glDeleteTextures(1, &id);
}

Framebuffer::Framebuffer(std::initializer_list<const Texture*> colors, int w, int h, bool withDepth)
    : width(w), height(h) {
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
    renderFailure("framebuffer incomplete");
}

Framebuffer::~Framebuffer() {
  glDeleteFramebuffers(1, &id);
  if (depth) glDeleteRenderbuffers(1, &depth);
}

void Framebuffer::bind() const {
  glBindFramebuffer(GL_FRAMEBUFFER, id);
  glViewport(0, 0, width, height);
}

bool softwareRasteriser() {
  const char* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  if (!renderer) return false;
  const std::string name(renderer);
  return name.find("llvmpipe") != std::string::npos || name.find("softpipe") != std::string::npos;
}

bool hasGlExtension(const char* extension) {
  GLint count = 0;
  glGetIntegerv(GL_NUM_EXTENSIONS, &count);
  for (GLint i = 0; i < count; ++i) {
    const char* name = reinterpret_cast<const char*>(glGetStringi(GL_EXTENSIONS, static_cast<GLuint>(i)));
    if (name && std::strcmp(name, extension) == 0) return true;
  }
  return false;
}

bool contextReadsInPlace() {
  return softwareRasteriser() && hasGlExtension("GL_AMD_pinned_memory");
}

Buffer::Buffer(const void* data, size_t bytes, bool readInPlace) {
  constexpr size_t kLarge = size_t(8) << 20;
  if (readInPlace && data && bytes >= kLarge && contextReadsInPlace()) {
    checkGl("before a buffer read in place");  // so the error tested below is this call's
    // GL_AMD_pinned_memory: storage given at this target is the caller's memory itself, so a coupe is
    // neither copied nor held twice while it is uploaded (the render's peak: README, Performance).
    constexpr GLenum kExternalVirtualMemory = 0x9160;  // GL_EXTERNAL_VIRTUAL_MEMORY_BUFFER_AMD
    glGenBuffers(1, &id);
    glBindBuffer(kExternalVirtualMemory, id);
    glBufferData(kExternalVirtualMemory, static_cast<GLsizeiptr>(bytes), data, GL_STATIC_DRAW);
    glBindBuffer(kExternalVirtualMemory, 0);
    if (glGetError() == GL_NO_ERROR) {
      inPlace = true;
      return;
    }
    clearGlErrors();  // refused (every flag it raised): a copy, as below
    glDeleteBuffers(1, &id);
  }
  glCreateBuffers(1, &id);
  if (!data || bytes < kLarge) {
    glNamedBufferStorage(id, static_cast<GLsizeiptr>(std::max<size_t>(bytes, 4)), bytes ? data : nullptr, 0);
    return;
  }
  // A coupe's points and tangents (hundreds of MB): copied through a mapping, so the driver's fresh
  // memory can be asked for in 2 MiB pages first (llvmpipe faulted it in 4 KiB at a time, most of the
  // upload). Only advice: a GPU driver's mapping may refuse it, and the copy is the same.
  glNamedBufferStorage(id, static_cast<GLsizeiptr>(bytes), nullptr, GL_MAP_WRITE_BIT);
  void* to = glMapNamedBufferRange(id, 0, static_cast<GLsizeiptr>(bytes),
                                   GL_MAP_WRITE_BIT | GL_MAP_INVALIDATE_BUFFER_BIT);
  if (!to) renderFailure("could not map a buffer of " + std::to_string(bytes) + " bytes to fill it");
  adviseHugePages(to, bytes);
  std::memcpy(to, data, bytes);
  if (!glUnmapNamedBuffer(id)) renderFailure("a buffer's contents were lost while it was filled");
}

Buffer::~Buffer() {
  reset();
}

void Buffer::reset() {
  // Deleting a buffer does not wait for the draws queued with it, and memory read in place is the
  // caller's, freed once this returns (a failing pass unwinds through here too).
  if (inPlace && id) glFinish();
  glDeleteBuffers(1, &id);
  id = 0;
  inPlace = false;
}

// ------------------------------------------------------------------------------------------ geometry

HairGeometry::HairGeometry(const Strands& s, const PointArray& tangentData, const Strands* before,
                           bool inPlace)
    : points(s.points.data(), s.points.size() * sizeof(glm::vec3), inPlace),
      tangents(tangentData.data(), tangentData.size() * sizeof(glm::vec3),
               inPlace && &tangentData == &s.tangents),
      colors(s.colors.data(), s.colors.size() * sizeof(glm::vec3), inPlace),
      normals(s.normals.data(), s.normals.size() * sizeof(glm::vec3), inPlace),
      previous(before ? before->points.data() : nullptr,
               before ? before->points.size() * sizeof(glm::vec3) : 0, inPlace),
      hasColors(!s.colors.empty()),
      hasNormals(!s.normals.empty()),
      hasPrevious(before != nullptr) {
  if (before && before->points.size() != s.points.size())
    renderFailure("the previous frame's hair has " + std::to_string(before->points.size()) + " points, not " +
                  std::to_string(s.points.size()));
  std::vector<uint32_t> drawn;  // in strand order until drawInOrder
  for (uint32_t i = 0; i < s.strandCount(); ++i)
    if (s.pointsOf(i) >= 2) drawn.push_back(i);
  drawInOrder(s, drawn);
  glCreateVertexArrays(1, &vao);
  glVertexArrayVertexBuffer(vao, 0, points.id, 0, sizeof(glm::vec3));
  glVertexArrayVertexBuffer(vao, 1, tangents.id, 0, sizeof(glm::vec3));
  glVertexArrayVertexBuffer(vao, 2, colors.id, 0, sizeof(glm::vec3));
  glVertexArrayVertexBuffer(vao, 3, normals.id, 0, sizeof(glm::vec3));
  glVertexArrayVertexBuffer(vao, 4, previous.id, 0, sizeof(glm::vec3));
  for (GLuint a = 0; a < 5; ++a) {
    if ((a == 2 && !hasColors) || (a == 3 && !hasNormals) || (a == 4 && !hasPrevious))
      continue;  // constant attributes, set in draw()
    glEnableVertexArrayAttrib(vao, a);
    glVertexArrayAttribFormat(vao, a, 3, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribBinding(vao, a, a);
  }
}

std::vector<uint32_t> frontToBack(const Strands& s, const glm::dmat4& view) {
  const glm::vec4 row{float(view[0][2]), float(view[1][2]), float(view[2][2]), float(view[3][2])};
  std::vector<std::pair<float, uint32_t>> keys;
  keys.reserve(s.strandCount());
  for (uint32_t i = 0; i < s.strandCount(); ++i) {
    if (s.pointsOf(i) < 2) continue;
    float nearest = std::numeric_limits<float>::infinity();
    for (uint32_t p = s.firstPoint[i]; p < s.firstPoint[i] + s.pointsOf(i); ++p)
      nearest =
          std::min(nearest, -(row.x * s.points[p].x + row.y * s.points[p].y + row.z * s.points[p].z + row.w));
    keys.emplace_back(nearest, i);
  }
  std::sort(keys.begin(), keys.end());
  std::vector<uint32_t> order(keys.size());
  for (size_t i = 0; i < keys.size(); ++i) order[i] = keys[i].second;
  return order;
}

void HairGeometry::drawInOrder(const Strands& s, const std::vector<uint32_t>& order) {
  for (auto* v : {&lineFirsts, &ribbonFirsts}) v->resize(order.size());
  for (auto* v : {&lineCounts, &ribbonCounts}) v->resize(order.size());
  for (size_t i = 0; i < order.size(); ++i) {
    const uint32_t strand = order[i];
    lineFirsts[i] = static_cast<GLint>(s.firstPoint[strand]);
    lineCounts[i] = static_cast<GLsizei>(s.pointsOf(strand));
    ribbonFirsts[i] = static_cast<GLint>(2 * s.firstPoint[strand]);
    ribbonCounts[i] = static_cast<GLsizei>(2 * s.pointsOf(strand));
  }
  // Chunks of whole strands of about kCameraChunkVertices line vertices (a ribbon's has twice as many).
  chunkEnds.clear();
  size_t vertices = 0;
  for (size_t i = 0; i < order.size(); ++i)
    if ((vertices += size_t(lineCounts[i])) >= kCameraChunkVertices || i + 1 == order.size()) {
      chunkEnds.push_back(i + 1);
      vertices = 0;
    }
}

HairGeometry::~HairGeometry() {
  glDeleteVertexArrays(1, &vao);
}

void HairGeometry::release() {
  glDeleteVertexArrays(1, &vao);  // first: a vertex array keeps the buffers it names alive
  vao = 0;
  for (Buffer* b : {&points, &tangents, &colors, &normals, &previous}) b->reset();
}

namespace {

// Draws chunk c of `chunks` for every c, in order, with at most two chunks unfinished at once
// (kChunkVertices).
template <class Draw>
void drawInChunks(size_t chunks, Draw&& draw) {
  GLsync fences[2] = {nullptr, nullptr};
  for (size_t c = 0; c < chunks; ++c) {
    GLsync& oldest = fences[c % 2];
    if (oldest) {
      glClientWaitSync(oldest, GL_SYNC_FLUSH_COMMANDS_BIT, ~GLuint64(0));
      glDeleteSync(oldest);
      oldest = nullptr;
    }
    draw(c);
    if (c + 1 < chunks) oldest = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
  }
  for (GLsync fence : fences)
    if (fence) glDeleteSync(fence);
}

}  // namespace

LineStrips::LineStrips(const std::vector<uint32_t>& indices, size_t chunkVertices)
    : count(static_cast<GLsizei>(indices.size())) {
  size_t start = 0;
  for (size_t i = 0; i < indices.size(); ++i)
    if (indices[i] == kRestartIndex && i + 1 - start >= chunkVertices)
      chunkEnds.push_back(static_cast<GLsizei>(start = i + 1));
  if (start < indices.size()) chunkEnds.push_back(count);
  glCreateBuffers(1, &id);
  glNamedBufferStorage(id, static_cast<GLsizeiptr>(std::max<size_t>(indices.size() * sizeof(uint32_t), 4)),
                       indices.empty() ? nullptr : indices.data(), 0);
}

LineStrips::~LineStrips() {
  glDeleteBuffers(1, &id);
}

void HairGeometry::drawLines(const LineStrips* strips) const {
  if (!strips) return draw(false);
  draw(false, false);
  glVertexArrayElementBuffer(vao, strips->id);
  glEnable(GL_PRIMITIVE_RESTART_FIXED_INDEX);
  drawInChunks(strips->chunkEnds.size(), [&](size_t c) {
    const GLsizei first = c > 0 ? strips->chunkEnds[c - 1] : 0;
    glDrawElements(GL_LINE_STRIP, strips->chunkEnds[c] - first, GL_UNSIGNED_INT,
                   reinterpret_cast<const void*>(uintptr_t(first) * sizeof(uint32_t)));
  });
  glDisable(GL_PRIMITIVE_RESTART_FIXED_INDEX);
}

void HairGeometry::draw(bool ribbon, bool drawing) const {
  glBindVertexArray(vao);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, points.id);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, tangents.id);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, colors.id);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, normals.id);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, previous.id);
  if (!hasColors) glVertexAttrib3f(2, 1.0f, 1.0f, 1.0f);
  if (!hasNormals) glVertexAttrib3f(3, 0.0f, 0.0f, 0.0f);
  if (lineFirsts.empty() || !drawing) return;
  drawInChunks(chunkEnds.size(), [&](size_t c) {
    const size_t first = c > 0 ? chunkEnds[c - 1] : 0;
    const GLsizei strands = static_cast<GLsizei>(chunkEnds[c] - first);
    if (ribbon)
      glMultiDrawArrays(GL_TRIANGLE_STRIP, &ribbonFirsts[first], &ribbonCounts[first], strands);
    else
      glMultiDrawArrays(GL_LINE_STRIP, &lineFirsts[first], &lineCounts[first], strands);
  });
}

HeadGeometry::HeadGeometry(const Mesh& m, const Mesh* before) {
  if (before && before->positions.size() != m.positions.size())
    renderFailure("the previous frame's head has " + std::to_string(before->positions.size()) +
                  " vertices, not " + std::to_string(m.positions.size()));
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
  if (before) {
    glCreateBuffers(1, &previousVbo);
    glNamedBufferStorage(previousVbo,
                         static_cast<GLsizeiptr>(std::max<size_t>(before->positions.size() * 12, 4)),
                         before->positions.data(), 0);
    glVertexArrayVertexBuffer(vao, 1, previousVbo, 0, 3 * sizeof(float));
    glEnableVertexArrayAttrib(vao, 2);
    glVertexArrayAttribFormat(vao, 2, 3, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribBinding(vao, 2, 1);
  }
}

HeadGeometry::~HeadGeometry() {
  glDeleteVertexArrays(1, &vao);
  glDeleteBuffers(1, &vbo);
  glDeleteBuffers(1, &ebo);
  if (previousVbo) glDeleteBuffers(1, &previousVbo);
}

void HeadGeometry::draw() const {
  glBindVertexArray(vao);
  glDrawElements(GL_TRIANGLES, indexCount, GL_UNSIGNED_INT, nullptr);
}

}  // namespace hairgen
