// OBJ reading on top of tinyobjloader. tinyobjloader parses leniently (a malformed number becomes 0),
// so a validating pass runs first and names the file:line of anything hairgen would misread; only the
// statements it checked reach tinyobjloader.
#include "libcore/io/obj_io.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <unordered_set>

#include <tiny_obj_loader.h>

#include "libcore/io/hair_cache.h"
#include "libcore/model/shape_fit.h"
#include "libcore/util/error.h"
#include "libcore/util/file_util.h"
#include "libcore/util/text.h"

namespace hairgen {
namespace {

constexpr double kMaxCoordinate = 1e30;  // beyond this a float loses the geometry
constexpr size_t kMaxFaceCorners = 256;  // a polygon's corners: its triangulation costs their square

std::vector<std::string_view> splitWords(std::string_view line) {
  std::vector<std::string_view> words;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r') ++i;
    if (i > start) words.push_back(line.substr(start, i - start));
  }
  return words;
}

// Checks one "i", "i/j", "i//k" or "i/j/k" face corner against the element counts seen so far.
void checkCorner(std::string_view corner, const FileLoc& where, const size_t counts[3]) {
  static const char* kinds[3] = {"vertex", "texture coordinate", "normal"};
  size_t part = 0, start = 0;
  for (size_t i = 0; i <= corner.size(); ++i) {
    if (i < corner.size() && corner[i] != '/') continue;
    if (part > 2)
      throw InputError(where, "face corner '" + std::string(corner) + "' has more than three parts");
    std::string_view text = corner.substr(start, i - start);
    if (!text.empty() || part == 0) {
      std::optional<int64_t> index = parseInt(text);
      if (!index || *index == 0)
        throw InputError(where, "face corner '" + std::string(corner) + "': '" + std::string(text) +
                                    "' is not a valid index (OBJ indices start at 1; negative counts back)");
      int64_t n = static_cast<int64_t>(counts[part]);
      if (*index > n || *index < -n)
        throw InputError(where, "face corner '" + std::string(corner) + "' refers to " + kinds[part] + " " +
                                    std::to_string(*index) + " but only " + std::to_string(n) +
                                    " are defined above it");
    }
    ++part;
    start = i + 1;
  }
}

// Checks every statement hairgen reads (v, vt, vn, f) and returns them, one a line, for tinyobjloader.
// The rest (objects, groups, materials, lines, skin weights, tags) hairgen does not use, and
// tinyobjloader's parsers of them are lenient to the point of undefined behaviour: a 'vw' joint id of
// 7e32 was converted to int (found by tests/fuzz/fuzz_obj).
// With a `group`, only the faces under a g, o or usemtl line naming it are kept; `names` collects every
// distinct name those lines give, in file order, for the error when none matches (a set beside it keeps
// the collection linear in the file however many names it has).
std::string validate(std::string_view text, const std::string& name, const std::string& group = "",
                     std::vector<std::string>* names = nullptr) {
  std::string checked;
  std::unordered_set<std::string_view> seen;  // views into `text`
  size_t counts[3] = {0, 0, 0};               // v, vt, vn
  bool inGroup = false, inMaterial = false;
  forEachLine(text, [&](std::string_view line, int lineNumber) {
    FileLoc where{name, lineNumber};
    if (line.find('\0') != std::string_view::npos)
      throw InputError(where, "NUL byte in an OBJ file; is this a text file?");
    std::vector<std::string_view> words = splitWords(line);
    if (words.empty() || words[0][0] == '#') return;
    std::string_view tag = words[0];
    if (tag == "g" || tag == "o" || tag == "usemtl") {
      bool match = false;
      for (size_t i = 1; i < words.size(); ++i) {
        match = match || words[i] == group;
        if (names && seen.insert(words[i]).second) names->push_back(std::string(words[i]));
      }
      // A face belongs to its group (g or o) and to its material; either may select it.
      (tag == "usemtl" ? inMaterial : inGroup) = match;
      return;
    }
    auto numbers = [&](size_t minCount, size_t maxCount, const char* what) {
      size_t n = words.size() - 1;
      if (n < minCount || n > maxCount)
        throw InputError(where, std::string("'") + std::string(tag) + "' line has " + std::to_string(n) +
                                    " numbers, expected " + what);
      for (size_t i = 1; i < words.size(); ++i) {
        std::optional<double> value = parseReal(words[i]);
        if (!value) throw InputError(where, "'" + std::string(words[i]) + "' is not a number");
        if (!std::isfinite(*value) || std::abs(*value) > kMaxCoordinate)
          throw InputError(where, "'" + std::string(words[i]) + "' is not a finite coordinate");
      }
    };
    if (tag == "v") {
      numbers(3, 7, "x y z [w] or x y z r g b");
      ++counts[0];
    } else if (tag == "vt") {
      numbers(1, 3, "u [v [w]]");
      ++counts[1];
    } else if (tag == "vn") {
      numbers(3, 3, "x y z");
      double x = *parseReal(words[1]), y = *parseReal(words[2]), z = *parseReal(words[3]);
      // A follicle grows along its normal: a zero one is a broken export, not something to guess.
      if (x * x + y * y + z * z < 1e-24)
        throw InputError(where,
                         "normal of zero length; fix the export, or delete the 'vn' lines (and the //n "
                         "in the faces) to have hairgen compute area-weighted normals");
      ++counts[2];
    } else if (tag == "f") {
      if (words.size() < 4) throw InputError(where, "a face needs at least three corners");
      // tinyobjloader triangulates a polygon by ear clipping, in time that grows with the square of its
      // corners: one face of 200,000 corners took minutes. Scalps and heads are triangles and quads.
      if (words.size() - 1 > kMaxFaceCorners)
        throw InputError(where, "a face of " + std::to_string(words.size() - 1) +
                                    " corners; hairgen reads faces of at most " +
                                    std::to_string(kMaxFaceCorners) + " (triangulate the mesh in its DCC)");
      for (size_t i = 1; i < words.size(); ++i) checkCorner(words[i], where, counts);
      if (!group.empty() && !inGroup && !inMaterial) return;
    } else {
      return;
    }
    checked.append(line);
    checked += '\n';
  });
  return checked;
}

// A wick of roots alone (HairStep's roots10k.obj): every vertex a follicle, its normal from the file or
// pointing away from the least-squares sphere through the points (a scalp is close to one).
Mesh pointCloud(const tinyobj::attrib_t& attrib) {
  Mesh mesh;
  const size_t count = attrib.vertices.size() / 3;
  for (size_t i = 0; i < count; ++i)
    mesh.positions.push_back(
        {attrib.vertices[3 * i], attrib.vertices[3 * i + 1], attrib.vertices[3 * i + 2]});
  if (attrib.normals.size() == attrib.vertices.size()) {
    for (size_t i = 0; i < count; ++i)
      mesh.normals.push_back(glm::normalize(
          glm::vec3(attrib.normals[3 * i], attrib.normals[3 * i + 1], attrib.normals[3 * i + 2])));
    return mesh;
  }
  const glm::dvec3 centre = fitSphere(mesh.positions).centre;
  for (const glm::vec3& p : mesh.positions) {
    glm::dvec3 d = glm::dvec3(p) - centre;
    mesh.normals.push_back(glm::length(d) > 0.0 ? glm::vec3(glm::normalize(d)) : glm::vec3(0, 1, 0));
  }
  return mesh;
}

void applyConversion(Mesh& mesh, const UnitConversion& conversion) {
  if (!conversion.changesCoordinates()) return;
  for (glm::vec3& p : mesh.positions) p = conversion.position(p);
  for (glm::vec3& n : mesh.normals) n = conversion.direction(n);
}

// What a file is when it is not an OBJ: by its first bytes, then by an extension that names another
// format; "" when it may be one.
std::string otherFormat(std::string_view text, const std::filesystem::path& file) {
  struct Magic {
    std::string_view bytes;
    const char* format;
  };
  static constexpr Magic kMagics[] = {
      {"ply\n", "a PLY file"},          {"ply\r", "a PLY file"},         {"HAIR", "a cyHair .hair file"},
      {"glTF", "a binary glTF file"},   {"v/1\x01", "an OpenEXR image"}, {"#usda", "a USD layer"},
      {"PXR-USDC", "a USD crate file"}, {"\x89PNG", "a PNG image"},      {"Kaydara FBX", "an FBX file"},
      {"\xFF\xD8\xFF", "a JPEG image"},
  };
  for (const Magic& m : kMagics)
    if (text.substr(0, m.bytes.size()) == m.bytes) return m.format;
  // Extensions: the hair formats' own table, and the other files a pipeline hands around.
  if (const std::optional<HairFormat> hair = hairFormatFor(file))
    return "a " + std::string(describe(*hair)) + " file (by its extension)";
  static constexpr std::pair<const char*, const char*> kExtensions[] = {
      {".usd", "a USD layer"},      {".usdc", "a USD crate file"}, {".usdz", "a USD package"},
      {".exr", "an OpenEXR image"}, {".fbx", "an FBX file"},       {".abc", "an Alembic archive"},
      {".stl", "an STL mesh"},      {".png", "a PNG image"},
  };
  const std::string extension = toLower(file.extension().string());
  for (const auto& [ext, format] : kExtensions)
    if (extension == ext) return std::string(format) + " (by its extension)";
  return "";
}

void requireObj(std::string_view text, const std::filesystem::path& file, const std::string& role) {
  const std::string format = otherFormat(text, file);
  if (format.empty()) return;
  throw InputError({file.string(), 0}, (role.empty() ? std::string("a mesh") : role) +
                                           " must be an OBJ mesh (.obj), and this is " + format +
                                           "; export it as OBJ");
}

}  // namespace

Mesh parseObj(std::string_view text, const std::string& name, MeshReadStats* statsOut) {
  return parseObj(text, name, MeshReadOptions{}, statsOut);
}

Mesh parseObj(std::string_view text, const std::string& name, const MeshReadOptions& options,
              MeshReadStats* statsOut) {
  text = withoutBom(text);  // tinyobjloader would read "\xEF\xBB\xBFv" as an unknown tag and drop the vertex
  std::vector<std::string> names;
  const std::string checked = validate(text, name, options.group, &names);
  if (!options.group.empty() && std::find(names.begin(), names.end(), options.group) == names.end()) {
    // The first few names, as an error is one line.
    constexpr size_t kNamesListed = 20;
    std::string list;
    for (size_t i = 0; i < std::min(names.size(), kNamesListed); ++i)
      list += (list.empty() ? "" : ", ") + oneLine(names[i]);
    if (names.size() > kNamesListed) list += " and " + std::to_string(names.size() - kNamesListed) + " more";
    throw InputError(
        {name, 0},
        "WickGroup '" + options.group + "' is not a group, object or material of this mesh; " +
            (list.empty() ? std::string("it has none (no g, o or usemtl lines)") : "it has " + list));
  }
  MeshReadStats stats;

  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> materials;
  std::string warn, err;
  std::istringstream stream{checked};
  if (!tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, &stream, nullptr, /*triangulate=*/true))
    throw InputError({name, 0}, "cannot parse OBJ: " + err);

  size_t vertexCount = attrib.vertices.size() / 3;
  if (vertexCount == 0) throw InputError({name, 0}, "the mesh has no vertices");
  size_t faces = 0;
  for (const tinyobj::shape_t& shape : shapes) faces += shape.mesh.num_face_vertices.size();
  if (options.allowPoints && faces == 0 && options.group.empty()) {
    Mesh mesh = pointCloud(attrib);
    applyConversion(mesh, options.conversion);
    if (statsOut) *statsOut = stats;
    return mesh;
  }

  std::vector<glm::vec3> positions(vertexCount);
  for (size_t i = 0; i < vertexCount; ++i)
    positions[i] = {attrib.vertices[3 * i], attrib.vertices[3 * i + 1], attrib.vertices[3 * i + 2]};
  glm::vec3 extent = bounds(positions).max - bounds(positions).min;
  double diagonal2 = glm::dot(glm::dvec3(extent), glm::dvec3(extent));

  std::vector<glm::uvec3> triangles;
  std::vector<glm::dvec3> normalSum(vertexCount, glm::dvec3(0.0));
  std::vector<int> uvIndex(vertexCount, -1);
  bool everyCornerHasNormal = true;
  auto cornerIndex = [&](int raw, size_t count) {
    return static_cast<size_t>(raw) < count ? static_cast<uint32_t>(raw) : UINT32_MAX;
  };
  for (const tinyobj::shape_t& shape : shapes) {
    size_t offset = 0;
    for (unsigned char corners : shape.mesh.num_face_vertices) {
      ++stats.facesRead;
      if (corners != 3) {  // triangulation leaves only faces it could not split (fewer than 3)
        offset += corners;
        ++stats.degenerateDropped;
        continue;
      }
      glm::uvec3 t;
      bool valid = true;
      for (int c = 0; c < 3; ++c) {
        const tinyobj::index_t& idx = shape.mesh.indices[offset + c];
        t[c] = cornerIndex(idx.vertex_index, vertexCount);
        if (t[c] == UINT32_MAX) valid = false;
      }
      if (valid) {
        glm::dvec3 a(positions[t.x]), b(positions[t.y]), c(positions[t.z]);
        double area2 = glm::dot(glm::cross(b - a, c - a), glm::cross(b - a, c - a));
        if (t.x == t.y || t.y == t.z || t.x == t.z || !(area2 > 1e-24 * diagonal2 * diagonal2)) valid = false;
      }
      if (!valid) {
        ++stats.degenerateDropped;
        offset += 3;
        continue;
      }
      for (int c = 0; c < 3; ++c) {
        const tinyobj::index_t& idx = shape.mesh.indices[offset + c];
        uint32_t n = cornerIndex(idx.normal_index, attrib.normals.size() / 3);
        if (n == UINT32_MAX) {
          everyCornerHasNormal = false;
        } else {
          if (idx.normal_index != idx.vertex_index) stats.normalsReindexed = true;
          glm::dvec3 fileNormal(attrib.normals[3 * n], attrib.normals[3 * n + 1], attrib.normals[3 * n + 2]);
          double length = glm::length(fileNormal);
          if (length > 0.0) normalSum[t[c]] += fileNormal / length;
        }
        uint32_t uv = cornerIndex(idx.texcoord_index, attrib.texcoords.size() / 2);
        if (uv != UINT32_MAX && uvIndex[t[c]] < 0) uvIndex[t[c]] = static_cast<int>(uv);
      }
      triangles.push_back(t);
      offset += 3;
    }
  }
  // A polygon with k corners arrives as k-2 triangles; count it once as triangulated.
  if (triangles.empty())
    throw InputError({name, 0}, stats.facesRead == 0
                                    ? "the mesh has no faces; hairgen needs a surface (f lines)"
                                    : "every face of the mesh is degenerate");
  stats.polygonsTriangulated = 0;
  {
    // tinyobjloader does not report the polygons it split; recount from the text.
    size_t pos = 0;
    while (pos < text.size()) {
      size_t end = text.find('\n', pos);
      if (end == std::string_view::npos) end = text.size();
      std::vector<std::string_view> words = splitWords(text.substr(pos, end - pos));
      if (!words.empty() && words[0] == "f" && words.size() > 4) ++stats.polygonsTriangulated;
      pos = end + 1;
    }
  }

  // Keep only vertices some face uses, in their file order.
  std::vector<uint32_t> remap(vertexCount, UINT32_MAX);
  for (const glm::uvec3& t : triangles)
    for (int c = 0; c < 3; ++c) remap[t[c]] = 0;
  Mesh mesh;
  bool anyUv = false;
  for (size_t i = 0; i < vertexCount; ++i) {
    if (remap[i] == UINT32_MAX) {
      ++stats.unreferencedDropped;
      continue;
    }
    remap[i] = static_cast<uint32_t>(mesh.positions.size());
    mesh.positions.push_back(positions[i]);
    anyUv = anyUv || uvIndex[i] >= 0;
  }
  for (glm::uvec3& t : triangles) t = {remap[t.x], remap[t.y], remap[t.z]};
  mesh.triangles = std::move(triangles);

  std::vector<glm::vec3> computed = areaWeightedNormals(mesh.positions, mesh.triangles);
  mesh.normals = computed;
  stats.normalsFromFile = everyCornerHasNormal;
  if (everyCornerHasNormal) {
    for (size_t i = 0; i < vertexCount; ++i) {
      if (remap[i] == UINT32_MAX) continue;
      double length = glm::length(normalSum[i]);
      // Corner normals that cancel (a knife edge) say nothing: keep the geometric normal there.
      if (length > 1e-6) mesh.normals[remap[i]] = glm::vec3(normalSum[i] / length);
    }
  }
  if (anyUv) {
    mesh.uvs.assign(mesh.positions.size(), glm::vec2(0.0f));
    for (size_t i = 0; i < vertexCount; ++i)
      if (remap[i] != UINT32_MAX && uvIndex[i] >= 0)
        mesh.uvs[remap[i]] = {attrib.texcoords[2 * uvIndex[i]], attrib.texcoords[2 * uvIndex[i] + 1]};
  }
  applyConversion(mesh, options.conversion);
  if (statsOut) *statsOut = stats;
  return mesh;
}

Mesh readObj(const std::filesystem::path& file, MeshReadStats* stats) {
  return readObj(file, MeshReadOptions{}, stats);
}

Mesh readObj(const std::filesystem::path& file, const MeshReadOptions& options, MeshReadStats* stats) {
  const std::string text = readFileText(file);
  requireObj(text, file, options.role);
  return parseObj(text, file.string(), options, stats);
}

void writeObj(const Mesh& mesh, std::ostream& out, const std::string& headerComment) {
  std::istringstream comment(headerComment);
  for (std::string line; std::getline(comment, line);) out << "# " << line << "\n";
  auto f = [](float v) { return formatFloat(v); };
  for (const glm::vec3& p : mesh.positions) out << "v " << f(p.x) << " " << f(p.y) << " " << f(p.z) << "\n";
  for (const glm::vec3& n : mesh.normals) out << "vn " << f(n.x) << " " << f(n.y) << " " << f(n.z) << "\n";
  for (const glm::vec2& t : mesh.uvs) out << "vt " << f(t.x) << " " << f(t.y) << "\n";
  bool uv = !mesh.uvs.empty();
  for (const glm::uvec3& t : mesh.triangles) {
    out << "f";
    for (int c = 0; c < 3; ++c) {
      uint32_t i = t[c] + 1;
      out << " " << i << (uv ? "/" + std::to_string(i) : "/") << "/" << i;
    }
    out << "\n";
  }
}

}  // namespace hairgen
