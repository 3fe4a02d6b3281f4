// USD export (DESIGN §6): BasisCurves in a text layer (.usda), what DCCs (Houdini, Maya, Blender 3.6+,
// Unreal's USD importer) exchange grooms as. hairgen has no USD library, so it writes the text itself
// and never reads USD.
//
// A still: one prim `/hair`. A shot (writeUsdShot): an Xform `/hair` holding `/hair/strands` (the
// coupe) and `/hair/guides`, whichever exist, their per-vertex values time-sampled at time code =
// frame number where they change from frame to frame, with startTimeCode, endTimeCode and
// timeCodesPerSecond (= framesPerSecond) in the layer.
//
// The layer: `defaultPrim = "hair"`, `metersPerUnit = 1` and `upAxis = "Y"` when the strands are in
// hairgen's frame (a file made elsewhere whose units or axis were not given leaves them out: USD's own
// fallbacks, centimetres and +y, then apply), and customLayerData `hairgen` with the provenance.
// A curves prim: `type "linear"`, `wrap "nonperiodic"`, curveVertexCounts, points, extent (the points'
// box grown by half the widest width, as UsdGeomCurves computes it), `widths` as diameters (USD's
// convention, and hairgen's) per vertex or one constant, primvars:displayColor and displayOpacity
// (1 − transparency) per vertex or constant; the primvars Unreal's groom schema names: groom_guide
// (constant: 1 on guides, 0 on strands), and per curve groom_id (the strand id), groom_root_uv,
// groom_closest_guides (the groom_id of guides), groom_guide_weights; hairgen's own under
// primvars:hairgen: the volume normals as hairgen:volumeNormal per vertex (never `normals`, which
// makes USD draw curves as ribbons facing them), root_triangle and root_bary per curve, and in a still
// tangent per vertex (a shot leaves tangents out: they follow from the points, and would double it).
// Floats are written in their shortest exact form without spaces, so a reader gets the very floats
// hairgen had in as few bytes as text allows.
//
// One-point strands (USC-HairSalon's bare follicles) are not curves USD can hold (linear curves need
// two points): they are left out, and the count is returned for the caller to say.
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <optional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "libcore/model/strands.h"
#include "libcore/util/frames.h"

namespace hairgen {

// What a USD layer left out of the strands it was given.
struct UsdWritten {
  size_t droppedStrands = 0;  // one-point strands, per prim of a shot summed
};

// Throws InputError for strands USD cannot hold: none of two points or more, an id at or above 2^31
// (USD's int).
UsdWritten encodeUsda(std::ostream& out, const Strands& strands);

UsdWritten writeUsda(const std::filesystem::path& file, const Strands& strands);  // atomic

// One prim of a shot: its strands at a frame.
struct UsdShotPrim {
  std::function<Strands(int frame)> frame;  // what reading it throws passes on
  std::string pattern;                      // the frames' file pattern, to name a frame in a message
  bool animated = true;  // false: the shot's first frame once, no time samples (a rest coupe)
};

// A shot's frames as one stage. Every frame of a prim must have the first frame's strands (counts and
// ids) and attributes: otherwise an InputError names the frame's file. timeCodesPerSecond is
// `framesPerSecond` (positive, finite) or, when not given, the frames' own rate: frames over seconds
// between the first and last frame's provenance (frame, time), rounded to a millionth; an InputError
// asks for it when the caches do not hold their frame and time. A single frame gets 24.
struct UsdShot {
  FrameRange frames;
  std::optional<double> framesPerSecond;
  std::optional<UsdShotPrim> strands, guides;  // at least one
};

// Whether strands are guides (what grow and simulate make), which USD marks groom_guide = 1.
bool areGuides(const Strands& strands);

UsdWritten writeUsdShot(const std::filesystem::path& file, const UsdShot& shot);  // atomic

// What a .usda hairgen wrote says of itself, for `hairgen info`: the layer's metadata lines (the
// `hairgen` dictionary of customLayerData, metersPerUnit, upAxis, the time codes) in file order, read
// as text up to the first prim. Not a USD reader: a layer hairgen did not write is an InputError
// saying so.
std::vector<std::pair<std::string, std::string>> readUsdaSummary(const std::filesystem::path& file);

}  // namespace hairgen
