#include "libcore/io/usd_io.h"

#include <algorithm>
#include <limits>

#include "libcore/model/mesh.h"
#include "libcore/util/error.h"
#include "libcore/util/file_util.h"
#include "libcore/util/text.h"

namespace hairgen {
namespace {

constexpr int kPerLine = 8;  // array items per line, for a file a person can scroll

std::string quoted(const std::string& text) {
  std::string out = "\"";
  for (char c : printableText(text)) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

std::string item(float v) {
  return formatFloat(v);
}
std::string item(uint32_t v) {
  return std::to_string(v);
}
std::string item(const glm::vec2& v) {
  return "(" + formatFloat(v.x) + ", " + formatFloat(v.y) + ")";
}
std::string item(const glm::vec3& v) {
  return "(" + formatFloat(v.x) + ", " + formatFloat(v.y) + ", " + formatFloat(v.z) + ")";
}
std::string item(const glm::uvec3& v) {
  return "(" + std::to_string(v.x) + ", " + std::to_string(v.y) + ", " + std::to_string(v.z) + ")";
}

template <typename T, class A>
void array(std::ostream& out, const std::vector<T, A>& values) {
  out << "[";
  for (size_t i = 0; i < values.size(); ++i) {
    if (i) out << (i % kPerLine ? ", " : ",\n        ");
    out << item(values[i]);
  }
  out << "]";
}

// `type name = [...]`, with an interpolation when it is a primvar or widths.
template <typename T, class A>
void attribute(std::ostream& out, const char* type, const std::string& name, const std::vector<T, A>& values,
               const char* interpolation = nullptr) {
  out << "    " << type << " " << name << " = ";
  array(out, values);
  if (interpolation) out << " (\n        interpolation = \"" << interpolation << "\"\n    )";
  out << "\n";
}

// USD ints are signed 32-bit: a larger id cannot be written.
void checkIds(const std::vector<uint32_t>& ids, const char* what) {
  for (uint32_t id : ids)
    if (id > uint32_t(std::numeric_limits<int32_t>::max()))
      throw InputError(std::string(what) + " " + std::to_string(id) +
                       " is too large for a USD int (at most 2^31 - 1); use .hair");
}

}  // namespace

void encodeUsda(std::ostream& out, const Strands& s) {
  s.validate("strands to write");
  if (s.strandCount() == 0) throw InputError("no strands to write; a BasisCurves prim needs one");
  std::vector<uint32_t> counts(s.strandCount());
  for (size_t i = 0; i < s.strandCount(); ++i) {
    counts[i] = s.pointsOf(i);
    if (counts[i] < 2)
      throw InputError("strand " + std::to_string(i) + " has " + std::to_string(counts[i]) +
                       " point(s); USD linear curves need at least 2 (USC-HairSalon marks bare follicles "
                       "with one)");
    if (counts[i] > uint32_t(std::numeric_limits<int32_t>::max()))
      throw InputError("strand " + std::to_string(i) + " has too many points for a USD int");
  }
  checkIds(s.strandId, "strand id");
  checkIds(s.rootTriangle, "root triangle");
  std::vector<uint32_t> guides;
  for (const glm::uvec3& g : s.guideIds) guides.insert(guides.end(), {g.x, g.y, g.z});
  checkIds(guides, "guide id");

  const Provenance& p = s.provenance;
  out << "#usda 1.0\n(\n";
  out << "    defaultPrim = \"hair\"\n";
  out << "    doc = "
      << quoted("hairgen " HAIRGEN_VERSION ": " + std::to_string(s.strandCount()) + " strands, " +
                std::to_string(s.pointCount()) + " points")
      << "\n";
  if (p.metres) out << "    metersPerUnit = 1\n";
  if (p.yUp) out << "    upAxis = \"Y\"\n";
  out << "    customLayerData = {\n        dictionary hairgen = {\n";
  auto entry = [&](const char* key, const std::string& value) {
    out << "            string " << key << " = " << quoted(value) << "\n";
  };
  entry("producer", p.producer.empty() ? std::string("hairgen " HAIRGEN_VERSION) : p.producer);
  entry("stage", p.stage);
  entry("seed", std::to_string(p.seed));
  entry("strands", std::to_string(s.strandCount()));
  entry("points", std::to_string(s.pointCount()));
  entry("configDigest", p.configDigest);
  if (!p.source.empty()) entry("source", p.source);
  if (!p.sourceInfo.empty()) entry("sourceInfo", p.sourceInfo);
  if (!p.conversion.empty()) entry("conversion", p.conversion);
  entry("units", std::string(p.metres ? "metres" : "unknown (the source file's own)") + ", " +
                     (p.yUp ? "+y up" : "up axis unknown"));
  out << "        }\n    }\n)\n\n";

  out << "def BasisCurves \"hair\"\n{\n";
  out << "    uniform token type = \"linear\"\n";
  out << "    uniform token wrap = \"nonperiodic\"\n";
  attribute(out, "int[]", "curveVertexCounts", counts);
  attribute(out, "point3f[]", "points", s.points);
  const Bounds box = bounds(s.points);
  float widest = s.defaultThickness;
  if (!s.thickness.empty()) widest = *std::max_element(s.thickness.begin(), s.thickness.end());
  const glm::vec3 pad(std::max(widest, 0.0f) * 0.5f);
  attribute(out, "float3[]", "extent", std::vector<glm::vec3>{box.min - pad, box.max + pad});
  if (!s.thickness.empty())
    attribute(out, "float[]", "widths", s.thickness, "vertex");
  else
    attribute(out, "float[]", "widths", std::vector<float>{s.defaultThickness}, "constant");
  if (!s.normals.empty()) attribute(out, "normal3f[]", "normals", s.normals, "vertex");
  if (!s.colors.empty())
    attribute(out, "color3f[]", "primvars:displayColor", s.colors, "vertex");
  else
    attribute(out, "color3f[]", "primvars:displayColor", std::vector<glm::vec3>{s.defaultColor}, "constant");
  if (!s.transparency.empty()) {
    std::vector<float> opacity(s.transparency.size());
    for (size_t i = 0; i < opacity.size(); ++i) opacity[i] = 1.0f - s.transparency[i];
    attribute(out, "float[]", "primvars:displayOpacity", opacity, "vertex");
  } else {
    attribute(out, "float[]", "primvars:displayOpacity", std::vector<float>{1.0f - s.defaultTransparency},
              "constant");
  }
  if (!s.strandId.empty()) attribute(out, "int[]", "primvars:groom_id", s.strandId, "uniform");
  if (!s.rootUv.empty()) attribute(out, "float2[]", "primvars:groom_root_uv", s.rootUv, "uniform");
  if (!s.guideIds.empty()) attribute(out, "int3[]", "primvars:groom_closest_guides", s.guideIds, "uniform");
  if (!s.guideWeights.empty())
    attribute(out, "float3[]", "primvars:groom_guide_weights", s.guideWeights, "uniform");
  if (!s.rootTriangle.empty())
    attribute(out, "int[]", "primvars:hairgen:root_triangle", s.rootTriangle, "uniform");
  if (!s.rootBary.empty()) attribute(out, "float3[]", "primvars:hairgen:root_bary", s.rootBary, "uniform");
  if (!s.tangents.empty()) attribute(out, "vector3f[]", "primvars:hairgen:tangent", s.tangents, "vertex");
  out << "}\n";
}

std::vector<std::pair<std::string, std::string>> readUsdaSummary(const std::filesystem::path& file) {
  const std::string text = readFileText(file);
  const std::string header = text.substr(0, text.find("\ndef "));
  std::vector<std::pair<std::string, std::string>> entries;
  bool ours = text.rfind("#usda 1.0\n", 0) == 0;
  forEachLine(header, [&](std::string_view line, int) {
    while (!line.empty() && line.front() == ' ') line.remove_prefix(1);
    const size_t equals = line.find(" = ");
    if (equals == std::string_view::npos) return;
    std::string key(line.substr(0, equals)), value(line.substr(equals + 3));
    if (key.rfind("string ", 0) == 0) key = key.substr(7);
    if (value.size() >= 2 && value.front() == '"' && value.back() == '"')
      value = value.substr(1, value.size() - 2);
    if (key == "producer") ours = ours && value.rfind("hairgen", 0) == 0;
    if (key == "defaultPrim" || key == "metersPerUnit" || key == "upAxis" || line.rfind("string ", 0) == 0)
      entries.emplace_back(oneLine(key), oneLine(value));
  });
  bool counted = false;
  for (const auto& [key, value] : entries) counted = counted || key == "strands";
  if (!ours || !counted)
    throw InputError({file.string(), 0},
                     "not a USD layer hairgen wrote; hairgen writes USD but does not read it (usdcat or "
                     "TinyUSDZ describe any layer)");
  return entries;
}

void writeUsda(const std::filesystem::path& file, const Strands& strands) {
  namingFile(file.string(), [&] {
    AtomicFile out(file);
    encodeUsda(out.stream(), strands);
    out.commit();
  });
}

}  // namespace hairgen
