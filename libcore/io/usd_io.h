// USD export (DESIGN §6): one BasisCurves prim in a text layer (.usda), what DCCs (Houdini, Maya,
// Blender 3.6+, Unreal's USD importer) exchange grooms as. hairgen has no USD library, so it writes the
// text itself and never reads USD.
//
// The layer: `defaultPrim = "hair"`, `metersPerUnit = 1` and `upAxis = "Y"` when the strands are in
// hairgen's frame (a file made elsewhere whose units or axis were not given leaves them out: USD's own
// fallbacks, centimetres and +y, then apply), and customLayerData `hairgen` with the provenance.
// The prim `/hair`: `type "linear"`, `wrap "nonperiodic"`, curveVertexCounts, points, extent (the
// points' box grown by half the widest strand), `widths` as diameters (USD's convention, and hairgen's)
// per vertex or one constant, `normals` per vertex when shaded (USD then reads the curves as ribbons
// facing them), primvars:displayColor and displayOpacity (1 − transparency) per vertex or constant, and
// per curve (uniform) the primvars Unreal's groom schema names: groom_id (the strand id), groom_root_uv,
// groom_closest_guides, groom_guide_weights; hairgen's own as primvars:hairgen:root_triangle,
// hairgen:root_bary and, per vertex, hairgen:tangent. Floats are written in their shortest exact form,
// so a reader gets the very floats hairgen had.
#pragma once

#include <filesystem>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "libcore/model/strands.h"

namespace hairgen {

// Throws InputError for strands USD cannot hold: a strand with fewer than 2 points (linear curves need
// two), an id at or above 2^31 (USD's int).
void encodeUsda(std::ostream& out, const Strands& strands);

void writeUsda(const std::filesystem::path& file, const Strands& strands);  // atomic

// What a .usda hairgen wrote says of itself, for `hairgen info`: the layer's metadata lines (the
// `hairgen` dictionary of customLayerData, metersPerUnit, upAxis) in file order, read as text up to the
// first prim. Not a USD reader: a layer hairgen did not write is an InputError saying so.
std::vector<std::pair<std::string, std::string>> readUsdaSummary(const std::filesystem::path& file);

}  // namespace hairgen
