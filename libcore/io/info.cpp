#include "libcore/io/info.h"

#include <algorithm>
#include <cmath>
#include <span>
#include <sstream>

#include "libcore/io/exr_io.h"
#include "libcore/io/gltf_io.h"
#include "libcore/io/hair_cache.h"
#include "libcore/io/hair_io.h"
#include "libcore/io/obj_io.h"
#include "libcore/io/ply_io.h"
#include "libcore/io/usd_io.h"
#include "libcore/util/error.h"
#include "libcore/util/json.h"
#include "libcore/util/progress.h"
#include "libcore/util/resources.h"
#include "libcore/util/text.h"

namespace hairgen {
namespace {

nlohmann::ordered_json boundsJson(std::span<const glm::vec3> points) {
  Bounds b = bounds(points);
  return {{"min", {b.min.x, b.min.y, b.min.z}}, {"max", {b.max.x, b.max.y, b.max.z}}};
}

nlohmann::ordered_json describeUsda(const std::filesystem::path& file) {
  nlohmann::ordered_json j;
  j["layer"] = nlohmann::ordered_json::object();
  for (const auto& [key, value] : readUsdaSummary(file)) {
    if (key == "strands" || key == "points") {
      std::optional<uint64_t> count = parseUInt(value);
      if (!count) throw InputError({file.string(), 0}, "the layer's " + key + " is not a count: " + value);
      j[key] = *count;
    } else if (key == "producer")
      j[key] = value;
    else
      j["layer"][key] = value;
  }
  return j;
}

nlohmann::ordered_json describeStrands(const Strands& s) {
  nlohmann::ordered_json j;
  j["strands"] = s.strandCount();
  j["points"] = s.pointCount();
  uint32_t minPoints = UINT32_MAX, maxPoints = 0;
  double totalLength = 0.0;
  for (size_t i = 0; i < s.strandCount(); ++i) {
    minPoints = std::min(minPoints, s.pointsOf(i));
    maxPoints = std::max(maxPoints, s.pointsOf(i));
    for (uint32_t p = s.firstPoint[i] + 1; p < s.firstPoint[i + 1]; ++p)
      totalLength += glm::length(glm::dvec3(s.points[p]) - glm::dvec3(s.points[p - 1]));
  }
  j["pointsPerStrand"] = {{"min", s.strandCount() ? minPoints : 0}, {"max", maxPoints}};
  j["meanStrandLength"] = s.strandCount() ? totalLength / double(s.strandCount()) : 0.0;
  j["bounds"] = boundsJson(s.points);
  std::vector<std::string> arrays;
  auto note = [&](bool present, const char* label) {
    if (present) arrays.push_back(label);
  };
  note(!s.tangents.empty(), "tangents");
  note(!s.normals.empty(), "normals");
  note(!s.colors.empty(), "colors");
  note(!s.thickness.empty(), "thickness");
  note(!s.transparency.empty(), "transparency");
  note(!s.strandId.empty(), "strandId");
  note(!s.rootTriangle.empty(), "rootTriangle");
  note(!s.rootBary.empty(), "rootBary");
  note(!s.rootUv.empty(), "rootUv");
  note(!s.guideIds.empty(), "guideIds");
  note(!s.guideWeights.empty(), "guideWeights");
  j["attributes"] = arrays;
  j["defaults"] = {{"thickness", s.defaultThickness},
                   {"transparency", s.defaultTransparency},
                   {"color", {s.defaultColor.x, s.defaultColor.y, s.defaultColor.z}}};
  const Provenance& p = s.provenance;
  j["provenance"] = {
      {"producer", p.producer}, {"stage", p.stage}, {"seed", p.seed}, {"configDigest", p.configDigest}};
  if (!p.source.empty()) j["provenance"]["source"] = p.source;
  if (!p.sourceInfo.empty()) j["provenance"]["sourceInfo"] = p.sourceInfo;
  if (!p.conversion.empty()) j["provenance"]["conversion"] = p.conversion;
  j["units"] = p.metres ? "metres" : "unknown";
  j["upAxis"] = p.yUp ? "+y" : "unknown";
  if (p.frame) {
    j["provenance"]["frame"] = *p.frame;
    j["provenance"]["time"] = p.time;
  }
  if (p.shard)
    j["provenance"]["shard"] = {{"index", p.shard->index},
                                {"count", p.shard->count},
                                {"first", p.shard->first},
                                {"end", p.shard->end},
                                {"total", p.shard->total}};
  if (!s.simulationState.empty()) j["restartState"] = s.simulationState.size();
  return j;
}

}  // namespace

namespace {

nlohmann::ordered_json describeFileAsRead(const std::filesystem::path& file) {
  std::string ext = toLower(file.extension().string());
  nlohmann::ordered_json j;
  j["file"] = file.string();
  if (ext == ".obj") {
    MeshReadStats stats;
    // Roots alone (a wick of points, as grow takes one) are described too.
    MeshReadOptions options;
    options.allowPoints = true;
    Mesh mesh = readObj(file, options, &stats);
    j["format"] = "obj";
    j["vertices"] = mesh.vertexCount();
    j["triangles"] = mesh.triangleCount();
    j["areaM2"] = surfaceArea(mesh);
    j["areaCm2"] = surfaceArea(mesh) * 1e4;
    double edge = 0.0;
    for (const glm::uvec3& t : mesh.triangles)
      for (int c = 0; c < 3; ++c) edge += glm::length(mesh.positions[t[c]] - mesh.positions[t[(c + 1) % 3]]);
    j["meanEdgeLength"] = mesh.triangles.empty() ? 0.0 : edge / (3.0 * double(mesh.triangleCount()));
    j["bounds"] = boundsJson(mesh.positions);
    j["uvs"] = !mesh.uvs.empty();
    j["normals"] = stats.normalsFromFile
                       ? (stats.normalsReindexed ? "from file, averaged per position" : "from file")
                   : mesh.triangles.empty() ? "computed (away from the points' fitted sphere: no faces)"
                                            : "computed (area-weighted)";
    j["polygonsTriangulated"] = stats.polygonsTriangulated;
    j["degenerateFacesDropped"] = stats.degenerateDropped;
    j["unreferencedVerticesDropped"] = stats.unreferencedDropped;
    return j;
  }
  if (ext == ".exr") {
    const ImageHeader header = readImageHeader(file);
    j["format"] = "exr";
    j["width"] = header.width;
    j["height"] = header.height;
    j["channels"] = nlohmann::ordered_json::array();
    for (const auto& [name, type] : header.channels)
      j["channels"].push_back({{"name", name}, {"type", type}});
    j["metadata"] = nlohmann::ordered_json::object();
    for (const auto& [name, value] : header.attributes) j["metadata"][name] = value;
    return j;
  }
  HairFormat format;
  try {
    format = hairFormatOf(file);
  } catch (const InputError&) {  // info reads meshes and images too: name them with the hair formats
    throw InputError({file.string(), 0}, "unknown file extension '" + file.extension().string() +
                                             "'; info reads " + hairExtensionList() + ", .obj and .exr");
  }
  Strands s;
  nlohmann::ordered_json details = nlohmann::ordered_json::object();
  switch (format) {
    case HairFormat::kHair: {
      HairHeader header;
      s = readHair(file, &header);
      details["cyHair"] = {
          {"flags", header.flags}, {"defaultSegments", header.defaultSegments}, {"info", header.info}};
      details["chunks"] = header.chunks;
      break;
    }
    case HairFormat::kPly: {
      PlyHeader header;
      s = readPly(file, &header);
      details["ply"] = {
          {"format", header.format}, {"elements", header.elements}, {"strandsFrom", header.strandsFrom}};
      break;
    }
    case HairFormat::kUsda:
      j["format"] = "usda";
      j.update(describeUsda(file));
      return j;
    default:
      s = readStrands(file);
  }
  noteSource(s, file);
  static const char* kNames[] = {"hair", "gltf", "glb", "ply", "data", "usda"};
  j["format"] = kNames[static_cast<int>(format)];
  j.update(describeStrands(s));
  j.update(details);
  return j;
}

}  // namespace

nlohmann::ordered_json describeFile(const std::filesystem::path& file) {
  return printableJson(describeFileAsRead(file));
}

std::string formatDescription(const nlohmann::ordered_json& j) {
  std::ostringstream out;
  auto num = [](const nlohmann::ordered_json& v) {
    if (v.is_number_float()) {
      char buffer[32];
      std::snprintf(buffer, sizeof buffer, "%.6g", v.get<double>());
      return std::string(buffer);
    }
    return jsonText(v, -1);
  };
  auto box = [&](const nlohmann::ordered_json& b) {
    return "(" + num(b["min"][0]) + ", " + num(b["min"][1]) + ", " + num(b["min"][2]) + ") to (" +
           num(b["max"][0]) + ", " + num(b["max"][1]) + ", " + num(b["max"][2]) + ")";
  };
  out << j["file"].get<std::string>() << ": " << j["format"].get<std::string>() << "\n";
  if (j["format"] == "exr") {
    out << "  " << j["width"] << "x" << j["height"] << ", " << j["channels"].size() << " channels:";
    for (const auto& c : j["channels"])
      out << " " << c["name"].get<std::string>() << " (" << c["type"].get<std::string>() << ")";
    out << "\n";
    for (const auto& [key, value] : j["metadata"].items())
      out << "  " << key << ": " << value.get<std::string>() << "\n";
    return out.str();
  }
  if (j["format"] == "usda") {
    out << "  USD layer written by " << j["producer"].get<std::string>() << ": " << j["strands"]
        << " curves, " << j["points"] << " points\n";
    for (const auto& [key, value] : j["layer"].items())
      out << "  " << key << ": " << value.get<std::string>() << "\n";
    return out.str();
  }
  if (j["format"] == "obj") {
    out << "  " << j["vertices"] << " vertices, " << j["triangles"] << " triangles, area "
        << num(j["areaCm2"]) << " cm² (" << num(j["areaM2"]) << " m²), mean edge " << num(j["meanEdgeLength"])
        << " m\n"
        << "  bounds " << box(j["bounds"]) << "\n"
        << "  normals " << j["normals"].get<std::string>() << (j["uvs"].get<bool>() ? ", UVs" : ", no UVs")
        << "\n"
        << "  " << j["polygonsTriangulated"] << " polygons triangulated, " << j["degenerateFacesDropped"]
        << " degenerate faces dropped, " << j["unreferencedVerticesDropped"]
        << " unreferenced vertices dropped\n";
    return out.str();
  }
  out << "  " << j["strands"] << " strands, " << j["points"] << " points (" << j["pointsPerStrand"]["min"]
      << " to " << j["pointsPerStrand"]["max"] << " per strand), mean strand length "
      << num(j["meanStrandLength"]) << "\n"
      << "  bounds " << box(j["bounds"]) << "\n";
  std::string attributes;
  for (const auto& a : j["attributes"]) attributes += (attributes.empty() ? "" : ", ") + a.get<std::string>();
  out << "  attributes: " << (attributes.empty() ? "positions only" : attributes) << "\n";
  if (j.contains("cyHair"))
    out << "  cyHair flags " << j["cyHair"]["flags"] << ", default segments "
        << j["cyHair"]["defaultSegments"] << ", info \"" << j["cyHair"]["info"].get<std::string>() << "\"\n";
  if (j.contains("ply"))
    out << "  PLY " << j["ply"]["format"].get<std::string>() << ", strands from "
        << j["ply"]["strandsFrom"].get<std::string>() << "\n";
  const nlohmann::ordered_json& p = j["provenance"];
  auto text = [&](const char* key) { return p.contains(key) ? p[key].get<std::string>() : std::string(); };
  const std::string producer = text("producer"), source = text("source");
  if (!producer.empty() && p["stage"] == "convert" && !source.empty())
    out << "  converted from " << source << " by " << producer << "\n";
  else if (!producer.empty())
    out << "  made by " << producer << " (" << text("stage") << "), seed " << p["seed"] << ", config "
        << text("configDigest") << (source.empty() ? "" : ", from " + source) << "\n";
  else
    out << "  made elsewhere, not by hairgen\n";
  if (!text("sourceInfo").empty()) out << "  the source says: \"" << text("sourceInfo") << "\"\n";
  if (!text("conversion").empty()) out << "  converted with " << text("conversion") << "\n";
  const bool metres = j["units"] == "metres", yUp = j["upAxis"] == "+y";
  out << "  units: " << (metres ? "metres" : "unknown (the file's own)") << ", "
      << (yUp ? "+y up" : "up axis unknown")
      << (metres && yUp ? "" : "; convert with --units and --up-axis to bring it to metres, +y up") << "\n";
  if (p.contains("frame"))
    out << "  frame " << p["frame"] << " at " << p["time"].get<double>() << " s"
        << (j.contains("restartState") ? ", with the state a restart needs" : "") << "\n";
  if (p.contains("shard")) {
    const nlohmann::ordered_json& r = p["shard"];
    out << "  shard " << r["index"] << "/" << r["count"] << ": items " << r["first"] << "-" << r["end"]
        << " of " << r["total"] << " (join the shards with hairgen merge)\n";
  }
  return out.str();
}

nlohmann::ordered_json describeSetup(const std::string& setupName, const Config& config, const Mesh* wick,
                                     const Mesh* head) {
  nlohmann::ordered_json report;
  report["setup"] = setupName;
  report["digest"] = config.digest();
  report["load"] = config.setup.load;
  report["collisionShapes"] = config.collision.shapes.size();
  report["model"] = name(config.hairstyle.model);
  if (config.hairstyle.model == StylingModel::kCantilever)
    report["cantileverSegments"] = config.hairstyle.segments;
  else
    report["superHelixElements"] = config.hairstyle.hairLengths.size();
  report["hairLength"] = config.hairstyle.totalLength();
  for (auto [ref, key, given] : {std::tuple{&config.setup.wickModel, "wick", wick},
                                 std::tuple{&config.setup.headModel, "head", head}}) {
    if (!ref->given()) continue;
    MeshReadStats meshStats;
    Mesh mesh = given ? *given : readObj(ref->path, &meshStats);
    report[key] = {{"file", ref->path.string()},
                   {"vertices", mesh.vertexCount()},
                   {"triangles", mesh.triangleCount()},
                   {"areaCm2", surfaceArea(mesh) * 1e4},
                   {"degenerateFacesDropped", meshStats.degenerateDropped}};
  }
  return report;
}

std::string formatSetupReport(const nlohmann::ordered_json& report) {
  std::ostringstream out;
  out << report["setup"].get<std::string>() << ": ok, config digest " << report["digest"].get<std::string>()
      << "\n";
  if (report.contains("cantileverSegments"))
    out << "  Anjyo's cantilever (Model cantilever), " << report["cantileverSegments"] << " segments";
  else
    out << "  " << report["superHelixElements"] << " Super-Helix elements";
  out << ", hair length " << report["hairLength"].get<double>() << " m, " << report["collisionShapes"]
      << " collision shapes\n";
  for (const char* key : {"wick", "head"})
    if (report.contains(key))
      out << "  " << key << " " << report[key]["file"].get<std::string>() << ": " << report[key]["vertices"]
          << " vertices, " << report[key]["triangles"] << " triangles, "
          << std::lround(report[key]["areaCm2"].get<double>()) << " cm²\n";
  if (report.contains("meshConversion"))
    out << "  meshes: " << report["meshConversion"].get<std::string>() << "\n";
  if (report.contains("fittedShapes")) {
    out << "  fitted collision shapes (to freeze them, put these lines in the Collision Info):\n";
    for (const auto& line : report["fittedShapes"]) out << "    " << line.get<std::string>() << "\n";
  }
  if (report.contains("fittedRootFlow"))
    out << "  the head's whorl, where the follicles lean away from (to freeze it, in the Hairstyle Info):\n  "
           "  "
        << report["fittedRootFlow"].get<std::string>() << "\n";
  auto time = [](double seconds) {
    return seconds < 0.5 ? std::string("under a second") : formatDuration(seconds);
  };
  if (report.contains("work")) {
    for (const auto& w : report["work"]) {
      const double seconds = w["seconds"].get<double>();
      out << "  " << w["stage"].get<std::string>();
      if (w.contains("frames")) {
        const int frames = w["frames"].get<int>();
        out << ", " << frames << " frames: about " << formatBytes(w["bytes"].get<uint64_t>()) << ", "
            << time(seconds) << " (" << time(seconds / std::max(frames, 1)) << " a frame)";
      } else {
        out << ": about " << formatBytes(w["bytes"].get<uint64_t>()) << ", " << time(seconds);
      }
      out << ", " << w["detail"].get<std::string>() << "\n";
    }
    out << "  in all about " << time(report["workSeconds"].get<double>()) << " on "
        << report["workThreads"].get<size_t>() << " threads (a rough estimate; --stats measures a run)\n";
  }
  return out.str();
}

}  // namespace hairgen
