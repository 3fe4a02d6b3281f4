// Wavefront OBJ meshes: the wick and the head.
#pragma once

#include <filesystem>
#include <ostream>
#include <string>
#include <string_view>

#include "libcore/model/mesh.h"
#include "libcore/model/units.h"

namespace hairgen {

// What reading a mesh changed, for `info` and --stats.
struct MeshReadStats {
  size_t facesRead = 0;             // faces as written (polygons count once)
  size_t polygonsTriangulated = 0;  // faces with more than three corners
  size_t degenerateDropped = 0;     // triangles with a repeated corner or no area
  size_t unreferencedDropped = 0;   // vertices no face uses (a wick vertex is a follicle only on a face)
  bool normalsFromFile = false;     // false: area-weighted normals were computed
  bool normalsReindexed = false;    // normals were indexed apart from positions and averaged per vertex
};

// How to read a mesh: which faces, and in which units and frame.
struct MeshReadOptions {
  std::string group;  // keep only faces of this group (g), object (o) or material (usemtl); "" = all
  bool allowPoints =
      false;  // a file of vertices and no faces is a point cloud (a wick of roots), not an error
  UnitConversion conversion;  // applied to positions and normals on reading
  std::string role;           // the key that names the mesh ("HeadModel", "WickModel"), for messages
};

// Reads an OBJ: a file that is another format (by its first bytes, or an extension such as .ply, .glb,
// .exr) is an InputError naming the file and `options.role` before anything is parsed. Then triangles and
// polygons (triangulated), normals and UVs indexed apart from positions (averaged, resp. first seen, per
// position, so each position stays one follicle), missing normals computed area-weighted. Malformed numbers,
// out-of-range indices and meshes with no vertices or no faces are InputErrors naming file:line. With
// `options.group`, vertices no kept face uses are dropped, and a name that no g, o or usemtl line gives is an
// InputError listing the names that exist. With `options.allowPoints`, a file with no faces gives a mesh with
// no triangles, its normals from the file's `vn` lines (one per vertex, in order) or, without them, pointing
// away from the points' least-squares sphere.
Mesh readObj(const std::filesystem::path& file, MeshReadStats* stats = nullptr);
Mesh readObj(const std::filesystem::path& file, const MeshReadOptions& options,
             MeshReadStats* stats = nullptr);
Mesh parseObj(std::string_view text, const std::string& name, MeshReadStats* stats = nullptr);
Mesh parseObj(std::string_view text, const std::string& name, const MeshReadOptions& options,
              MeshReadStats* stats = nullptr);

// Writes positions, normals, UVs (when present) and triangles; floats in shortest round-trip form so
// the same mesh always gives the same bytes.
void writeObj(const Mesh& mesh, std::ostream& out, const std::string& headerComment);

}  // namespace hairgen
