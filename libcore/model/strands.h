// Hair strands as flat arrays: the guides `grow` makes, the coupe `interpolate` makes, and whatever a
// .hair or glTF cache holds.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "libcore/util/mapped_file.h"

namespace hairgen {

// A shard of a split stage (`--shard K/N`): the range of the stage's items it holds (grow: wick vertices,
// interpolate: wick triangles), of `total`. `hairgen merge` joins shards into the single run's file.
struct ShardRange {
  uint32_t index = 0, count = 0;  // shard `index` of `count`, 1-based
  uint64_t first = 0, end = 0;    // items [first, end)
  uint64_t total = 0;             // items in the whole stage
  bool operator==(const ShardRange&) const = default;
};

// Shard `index` (1-based) of `count` over `total` items: [⌊(index−1)·total/count⌋, ⌊index·total/count⌋).
ShardRange shardRange(uint32_t index, uint32_t count, uint64_t total);

// Where a cache came from, stored in it so a farm script can tell two caches apart.
struct Provenance {
  std::string producer;  // "hairgen 0.1.0"; empty for files made elsewhere
  std::string stage;     // "grow", "interpolate", "shade", "convert", ...
  uint64_t seed = 0;
  std::string configDigest;  // hex digest of the effective configuration, or ""
  std::string restDigest;    // a simulated frame: the digest of the rest guides it started from
                             // (restGuidesDigest, libcore/io/restart_state.h), or ""
  std::optional<int> frame;  // the frame of a sequence this cache is (DESIGN §8); none for a still
  double time = 0.0;         // seconds from the sequence's first frame, when `frame` is set
  // A file made elsewhere: what it was, what it said of itself and what hairgen did to it.
  std::string source;  // the name of the file this was read or converted from, when hairgen did not write it
  std::string sourceInfo;  // what that file said of itself, one line (cyHair info text, PLY comments, ...)
  std::string conversion;  // what hairgen applied ("units mm (x0.001); up axis z turned to +y"), or ""
  bool metres = true;      // positions and widths are metres; false: the file's own, unknown units
  bool yUp = true;         // +y is up; false: the file's own, unknown axis
  std::optional<ShardRange> shard;  // a shard of a split stage; none for a whole file

  bool empty() const {
    return producer.empty() && stage.empty() && configDigest.empty() && restDigest.empty() && seed == 0 &&
           source.empty() && sourceInfo.empty() && conversion.empty() && metres && yUp && !shard;
  }
  bool operator==(const Provenance&) const = default;
};

// The provenance of what this build of hairgen makes: producer "hairgen VERSION", no frame.
Provenance madeByHairgen(std::string stage, uint64_t seed, std::string configDigest);

// A coupe's points or tangents. Sizing one leaves its new elements unset (MappableAllocator): whoever
// resizes it writes every element it adds, so hundreds of MB are written once, not zeroed first. Read
// from a .hair file for the render, its storage may be the file's own pages (hair_io.h: ArrayStorage).
using PointArray = std::vector<glm::vec3, MappableAllocator<glm::vec3>>;

// A set of polyline strands. Strand s owns points [firstPoint[s], firstPoint[s+1]).
//
// Every optional array is either empty or has exactly its documented size; validate() checks it.
// Units: metres, unit vectors, widths as diameters in metres (DESIGN §2).
struct Strands {
  PointArray points;
  std::vector<uint32_t> firstPoint{0};  // strandCount() + 1 offsets, firstPoint[0] == 0

  // Per point (size points.size() or empty).
  PointArray tangents;              // unit
  std::vector<glm::vec3> normals;   // unit shading normals
  std::vector<glm::vec3> colors;    // linear RGB
  std::vector<float> thickness;     // diameter, metres
  std::vector<float> transparency;  // 0 = opaque

  // Per strand (size strandCount() or empty).
  std::vector<uint32_t> strandId;
  std::vector<uint32_t> rootTriangle;  // wick triangle the root lies on
  std::vector<glm::vec3> rootBary;     // barycentrics of the root on that triangle
  std::vector<glm::vec2> rootUv;
  std::vector<glm::uvec3> guideIds;     // the three guides a strand follows
  std::vector<glm::vec3> guideWeights;  // their weights at the root

  // cyHair header defaults, used where the per-point arrays are absent.
  float defaultThickness = 7.0e-5f;  // metres
  float defaultTransparency = 0.0f;
  glm::vec3 defaultColor{0.45f, 0.25f, 0.0f};

  Provenance provenance;

  // What `hairgen simulate` needs to resume from this frame, in its model's layout (Anjyo's angles of
  // the last step and the step before and what the steps carried with them, the springs' positions and
  // velocities); empty for anything else. Opaque to every other stage.
  std::vector<double> simulationState;

  size_t strandCount() const { return firstPoint.empty() ? 0 : firstPoint.size() - 1; }
  size_t pointCount() const { return points.size(); }
  uint32_t pointsOf(size_t strand) const { return firstPoint[strand + 1] - firstPoint[strand]; }

  // Becomes a copy of `rest` whose points, tangents and simulation state are to be filled: those arrays
  // keep their storage (sized to rest's points, their values unset: the caller writes every one), so a
  // frame posed into the same Strands each time allocates nothing.
  void assignRestKeepingBuffers(const Strands& rest);

  // Appends a strand's points; the optional arrays are left to the caller.
  void addStrand(const std::vector<glm::vec3>& strandPoints);

  // Throws InputError (naming `source`) if an array has the wrong size, an offset is out of order, or
  // a value is not finite.
  void validate(const std::string& source) const;

  bool operator==(const Strands&) const = default;
};

// The strands `keep(i)` holds for, in their order: every per-point array (points, tangents, normals,
// colors, thickness, transparency) and per-strand array (ids, root triangle, barycentrics and UV, guide
// ids and weights) that `strands` carries, cut to those strands; the header defaults and the provenance
// as they were. The simulation state is left out: its layout is a model's, over every strand.
// Precondition: strands.validate() passes.
Strands keepStrands(const Strands& strands, const std::function<bool(size_t strand)>& keep);

// How many strands have fewer than two points: bare follicles (USC-HairSalon's one-point strands), which
// have no segment, so USD's linear curves and glTF's LINES cannot hold them.
size_t onePointStrandCount(const Strands& strands);
// keepStrands of the strands of two points or more.
Strands withoutOnePointStrands(const Strands& strands);

// Unit tangents of every strand's polyline by forward differences (the last point looks back; a
// repeated point keeps the previous tangent, +y before any), for caches that carry none.
PointArray polylineTangents(const Strands& strands);

// The strands' own tangents when they carry them, else polylineTangents().
inline PointArray tangentsOf(const Strands& strands) {
  return strands.tangents.empty() ? polylineTangents(strands) : strands.tangents;
}

}  // namespace hairgen
