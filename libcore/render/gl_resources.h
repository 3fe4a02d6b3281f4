// The OpenGL objects the renderer draws with. Each owns its GL name and deletes it with itself, so a
// failing pass leaves nothing behind; all need a current OpenGL 4.5 core context (GlContext). Failures
// that are hairgen's own throw Error with exit code 1 ("rendering: ...").
#pragma once

#include <functional>
#include <initializer_list>
#include <string>
#include <vector>

#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>
#include <glm/glm.hpp>

#include "libcore/model/mesh.h"
#include "libcore/model/strands.h"

namespace hairgen {

[[noreturn]] void renderFailure(const std::string& what);

// Throws renderFailure naming `where` when OpenGL has recorded an error.
void checkGl(const char* where);

// Forgets the errors recorded before the renderer started.
void clearGlErrors();

struct CustomStage;

// One stage of a program: its complete GLSL (assembleStage's), and for a Setup's file, the file and
// the Setup key that named it, so a compiler error can name them.
struct StageSource {
  std::string text;
  const CustomStage* custom = nullptr;  // null: hairgen's own stage
  const char* key = "";                 // "HairFrag"
  const char* variant = "";             // what the prelude made of it, e.g. "for ribbons"; may be empty
};

// Hands each stage to `watch` as it is handed to OpenGL (once per context and GLSL text, as Program
// compiles it): its type (GL_VERTEX_SHADER, ...), its text and its program's name, a program's stages one
// after the other (vertex, then fragment). An empty function, the default, watches none. Set it before
// any program is made, on the thread that makes them (it is read unguarded). For
// tests/write_stages.cpp, which has every stage and program checked by the Khronos reference compiler:
// GLSL one driver accepts may be GLSL another refuses.
void watchStages(std::function<void(GLenum type, const StageSource& stage, const char* program)> watch);

// A linked program of a vertex and a fragment stage. `name` ("hair shading") is for messages. A custom
// stage that fails to compile, or a program with one that fails to link, throws InputError at the
// custom file and the line the compiler names, on one line; hairgen's own stages failing throw Error.
// With a GlContext current (GlContext::current), the program is compiled once per context: kept there
// and shared by every Program of the same GLSL (a sequence's frames compile nothing after the first).
// A pass sets the uniforms it reads before it draws, each frame the same ones, so a program a frame
// before used draws as a fresh one would.
class Program {
 public:
  Program(const StageSource& vertex, const StageSource& fragment, const char* name);
  // A program of one compute stage, hairgen's own (a failure throws Error), kept by the context alike.
  Program(const StageSource& compute, const char* name);
  ~Program();
  Program(const Program&) = delete;
  Program& operator=(const Program&) = delete;

  void use() const;
  // A uniform's location; −1 when the program has no such uniform (setting it then does nothing).
  GLint loc(const char* name) const;
  void set(const char* name, const glm::mat4& m) const;
  void set(const char* name, const glm::vec4& v) const;
  void set(const char* name, const glm::vec3& v) const;
  void set(const char* name, const glm::vec2& v) const;
  void set(const char* name, float v) const;
  void set(const char* name, int v) const;
  void set(const char* name, const std::vector<int>& v) const;

  GLuint id = 0;

 private:
  static GLuint link(const StageSource& vertex, const StageSource& fragment, const char* name);
  static GLuint linkCompute(const StageSource& compute, const char* name);
  bool owned_ = false;  // deleted with this Program (no GlContext to keep it)
};

// A 2D texture of one level, clamped at its edges.
struct Texture {
  Texture(GLenum internalFormat, int width, int height, GLenum filter = GL_NEAREST);
  ~Texture();
  Texture(Texture&& other) noexcept;
  Texture(const Texture&) = delete;
  Texture& operator=(const Texture&) = delete;
  Texture& operator=(Texture&&) = delete;

  GLuint id = 0;
  int width = 0, height = 0;  // texels
};

// Draws into `colors` (attachments 0, 1, ...), with a 24-bit depth buffer when asked.
struct Framebuffer {
  Framebuffer(std::initializer_list<const Texture*> colors, int width, int height, bool withDepth);
  ~Framebuffer();
  Framebuffer(const Framebuffer&) = delete;
  Framebuffer& operator=(const Framebuffer&) = delete;
  // Binds it for drawing, the viewport its whole size.
  void bind() const;

  GLuint id = 0, depth = 0;
  int width = 0, height = 0;
};

// Whether the current context rasterises in software (Mesa's llvmpipe or softpipe: its GL_RENDERER).
bool softwareRasteriser();

// Whether the current context has the OpenGL extension `extension` ("GL_ARB_gpu_shader_int64").
bool hasGlExtension(const char* extension);

// Whether the current context reads a large array in place, where it lies in the program's memory: a
// software rasteriser with GL_AMD_pinned_memory (llvmpipe). Not a GPU, even one whose driver has the
// extension (AMD's): it would read pinned host memory across the bus in every pass.
bool contextReadsInPlace();

// A buffer holding `bytes` of `data` (at least 4 bytes, so an empty array still binds). With
// `readInPlace` and a context that reads in place, a large array is not copied: the buffer reads
// `data` where it lies, which must then stay alive and unchanged until the buffer is deleted
// (`inPlace` says so). Otherwise the buffer is immutable and holds a copy.
struct Buffer {
  Buffer(const void* data, size_t bytes, bool readInPlace = false);
  ~Buffer();
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;
  void reset();  // deletes it now, after the draws that read it in place have finished

  GLuint id = 0;
  bool inPlace = false;
};

// The strands of two points or more, those nearest `view`'s eye first (by their nearest point): drawn
// so, a depth test made before shading skips more of what lies behind; the order changes no result but
// ties of equal depth.
std::vector<uint32_t> frontToBack(const Strands& strands, const glm::dmat4& view);

// A pass draws its hair in chunks of about this many vertices, waiting for the chunk before the last
// one drawn to finish before it draws the next (a fence): llvmpipe bins a draw into scenes and queues
// scenes while its rasterisers lag behind, so one draw of the whole coupe held hundreds of MB of
// binned scenes at once. Two chunks in flight keep binning and rasterising going side by side. The
// camera's passes bin more per line (their varyings) and draw in smaller chunks. (150,000 strands at
// 1080p, README Performance: smaller chunks than these saved little more memory and cost time.)
constexpr size_t kChunkVertices = size_t(1) << 18, kCameraChunkVertices = size_t(1) << 17;

// Line strips through some of a coupe's points (line_decimation.h: point indices, kRestartIndex
// between strips) in an index buffer, for HairGeometry::drawLines.
struct LineStrips {
  explicit LineStrips(const std::vector<uint32_t>& indices, size_t chunk = kChunkVertices);
  ~LineStrips();
  LineStrips(const LineStrips&) = delete;
  LineStrips& operator=(const LineStrips&) = delete;

  GLuint id = 0;
  GLsizei count = 0;
  std::vector<GLsizei> chunkEnds;  // where each of drawLines' chunks of whole strips ends (kChunkVertices)
};

// Hair on the GPU: points, tangents, colors and normals (where the strands have them) both as vertex
// attributes 0-3 and as storage buffers 0-3 (glsl/hair_vertex.glsl reads one or the other); per strand
// a line strip (one vertex per point) or a triangle strip (two). Strands of fewer than 2 points are
// not drawn. With the previous frame's points (the motion pass), those too, as attribute 4 and storage
// buffer 4.
struct HairGeometry {
  // `tangents`: one per point. `previous`: null, or the same strands a frame before (as many points).
  // With `inPlace`, the large arrays are read where they lie where the context can (Buffer): the
  // strands (and `previous`) must then stay alive and unchanged until release() or the destructor.
  // `tangents` is read in place only when it is the strands' own.
  HairGeometry(const Strands& strands, const PointArray& tangents, const Strands* previous = nullptr,
               bool inPlace = false);
  ~HairGeometry();
  HairGeometry(const HairGeometry&) = delete;
  HairGeometry& operator=(const HairGeometry&) = delete;
  // Binds the buffers and draws every strand as lines, or as ribbons (with `drawing` false, only binds).
  void draw(bool ribbon, bool drawing = true) const;
  // Draws the strands as `strips` gives them (null: every point, draw(false)).
  void drawLines(const LineStrips* strips) const;
  // Draws the strands in `order` (frontToBack's: every strand of two points or more, once).
  void drawInOrder(const Strands& strands, const std::vector<uint32_t>& order);
  // Deletes the vertex array and the buffers now (nothing may be drawn after).
  void release();

  Buffer points, tangents, colors, normals, previous;
  bool hasColors, hasNormals, hasPrevious;
  // Whether a buffer reads the strands (or the frame before) where they lie.
  bool readsStrandsInPlace() const {
    return points.inPlace || tangents.inPlace || colors.inPlace || normals.inPlace || previous.inPlace;
  }
  std::vector<GLint> lineFirsts, ribbonFirsts;
  std::vector<GLsizei> lineCounts, ribbonCounts;
  std::vector<size_t> chunkEnds;  // where each of draw()'s chunks of strands ends (kCameraChunkVertices)
  GLuint vao = 0;
};

// The head on the GPU: positions as attribute 0, normals as attribute 1 ((0, 1, 0) where the mesh has
// none), triangles indexed; for the motion pass, the previous frame's positions as attribute 2.
struct HeadGeometry {
  // `previous`: null, or the same mesh a frame before (as many vertices).
  explicit HeadGeometry(const Mesh& mesh, const Mesh* previous = nullptr);
  ~HeadGeometry();
  HeadGeometry(const HeadGeometry&) = delete;
  HeadGeometry& operator=(const HeadGeometry&) = delete;
  void draw() const;

  GLuint vao = 0, vbo = 0, ebo = 0, previousVbo = 0;
  GLsizei indexCount = 0;
};

}  // namespace hairgen
