#include "libcore/io/usd_io.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <sstream>

#include "libcore/model/mesh.h"
#include "libcore/util/error.h"
#include "libcore/util/file_util.h"
#include "libcore/util/text.h"

namespace hairgen {
namespace {

constexpr int kPerLine = 8;  // array items per line, so a person can scroll the file

std::string quoted(const std::string& text) {
  std::string out = "\"";
  for (char c : printableText(text)) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

// Items in their shortest exact form, no spaces: "(x,y,z)".
template <typename T>
void put(std::string& o, T v) {
  char buffer[32];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, v);
  o.append(buffer, ec == std::errc() ? end : buffer);
}
void put(std::string& o, const glm::vec2& v) {
  o += '(', put(o, v.x), o += ',', put(o, v.y), o += ')';
}
void put(std::string& o, const glm::vec3& v) {
  o += '(', put(o, v.x), o += ',', put(o, v.y), o += ',', put(o, v.z), o += ')';
}
void put(std::string& o, const glm::uvec3& v) {
  o += '(', put(o, v.x), o += ',', put(o, v.y), o += ',', put(o, v.z), o += ')';
}

template <class Values>
std::string arrayText(const Values& values) {
  std::string o = "[";
  o.reserve(values.size() * 12 + 2);
  size_t i = 0;
  for (const auto& v : values) {
    if (i) o += (i % kPerLine ? "," : ",\n");
    put(o, v);
    ++i;
  }
  return o + "]";
}

// An attribute's value at one time: its text and, for widths and primvars, its interpolation.
struct Value {
  std::string text;                     // "[...]"; empty: the attribute is not written
  const char* interpolation = nullptr;  // nullptr: not a primvar
};

struct Attribute {
  const char* type;
  const char* name;
  Value (*encode)(const Strands&);
};

// Per vertex, or one constant from the header's default.
template <class PerVertex, class Constant>
Value vertexOrConstant(const PerVertex& perVertex, const Constant& constant) {
  if (!perVertex.empty()) return {arrayText(perVertex), "vertex"};
  return {arrayText(std::vector<Constant>{constant}), "constant"};
}

Value extentOf(const Strands& s) {
  const Bounds box = bounds(s.points);
  float widest = s.defaultThickness;
  if (!s.thickness.empty()) widest = *std::max_element(s.thickness.begin(), s.thickness.end());
  const glm::vec3 pad(std::max(widest, 0.0f) * 0.5f);
  return {arrayText(std::vector<glm::vec3>{box.min - pad, box.max + pad})};
}

Value opacityOf(const Strands& s) {
  std::vector<float> opacity(s.transparency.size());
  for (size_t i = 0; i < opacity.size(); ++i) opacity[i] = 1.0f - s.transparency[i];
  return vertexOrConstant(opacity, 1.0f - s.defaultTransparency);
}

// What may change from frame to frame, in the order written.
constexpr size_t kPoints = 0, kExtent = 1;  // their places in kVertexAttributes
const Attribute kVertexAttributes[] = {
    {"point3f[]", "points", [](const Strands& s) { return Value{arrayText(s.points)}; }},
    {"float3[]", "extent", extentOf},
    {"float[]", "widths", [](const Strands& s) { return vertexOrConstant(s.thickness, s.defaultThickness); }},
    {"normal3f[]", "primvars:hairgen:volumeNormal",
     [](const Strands& s) {
       return s.normals.empty() ? Value{} : Value{arrayText(s.normals), "vertex"};
     }},
    {"color3f[]", "primvars:displayColor",
     [](const Strands& s) { return vertexOrConstant(s.colors, s.defaultColor); }},
    {"float[]", "primvars:displayOpacity", opacityOf},
};
const Attribute kTangents = {"vector3f[]", "primvars:hairgen:tangent", [](const Strands& s) {
                               return s.tangents.empty() ? Value{} : Value{arrayText(s.tangents), "vertex"};
                             }};

template <class Values>
Value uniform(const Values& values) {
  return values.empty() ? Value{} : Value{arrayText(values), "uniform"};
}

// What a frame sequence keeps from its first frame: per curve.
const Attribute kCurveAttributes[] = {
    {"int[]", "primvars:groom_id", [](const Strands& s) { return uniform(s.strandId); }},
    {"float2[]", "primvars:groom_root_uv", [](const Strands& s) { return uniform(s.rootUv); }},
    {"int3[]", "primvars:groom_closest_guides", [](const Strands& s) { return uniform(s.guideIds); }},
    {"float3[]", "primvars:groom_guide_weights", [](const Strands& s) { return uniform(s.guideWeights); }},
    {"int[]", "primvars:hairgen:root_triangle", [](const Strands& s) { return uniform(s.rootTriangle); }},
    {"float3[]", "primvars:hairgen:root_bary", [](const Strands& s) { return uniform(s.rootBary); }},
};

void writeMetadata(std::ostream& out, const char* interpolation) {
  if (interpolation) out << " (\n        interpolation = \"" << interpolation << "\"\n    )";
}

void writeStatic(std::ostream& out, const Attribute& a, const Value& v) {
  if (v.text.empty()) return;
  out << "    " << a.type << " " << a.name << " = " << v.text;
  writeMetadata(out, v.interpolation);
  out << "\n";
}

// USD ints are signed 32-bit: a larger id cannot be written.
void checkIds(const std::vector<uint32_t>& ids, const char* what) {
  for (uint32_t id : ids)
    if (id > uint32_t(std::numeric_limits<int32_t>::max()))
      throw InputError(std::string(what) + " " + std::to_string(id) +
                       " is too large for a USD int (at most 2^31 - 1); use .hair");
}

void checkForUsd(const Strands& s) {
  s.validate("strands to write");
  if (s.strandCount() == 0)
    throw InputError("no strands of two points or more to write; a BasisCurves prim needs one");
  checkIds(s.strandId, "strand id");
  checkIds(s.rootTriangle, "root triangle");
  for (const glm::uvec3& g : s.guideIds) checkIds({g.x, g.y, g.z}, "guide id");
}

// The strands without their one-point strands (linear curves need two points); `dropped` counts them.
Strands withoutBareFollicles(Strands s, size_t& dropped) {
  dropped = onePointStrandCount(s);
  if (dropped == 0) return s;
  s.validate("strands to write");  // keepStrands' precondition
  return withoutOnePointStrands(s);
}

std::vector<uint32_t> curveCounts(const Strands& s) {
  std::vector<uint32_t> counts(s.strandCount());
  for (size_t i = 0; i < counts.size(); ++i) counts[i] = s.pointsOf(i);
  return counts;
}

// The layer's metadata: units, up axis, the provenance (and a shot's time codes).
struct LayerFacts {
  const Provenance* provenance;
  size_t strands = 0, points = 0;
  const FrameRange* frames = nullptr;  // a shot
  double framesPerSecond = 0.0;
};

void writeLayer(std::ostream& out, const LayerFacts& facts) {
  const Provenance& p = *facts.provenance;
  out << "#usda 1.0\n(\n";
  out << "    defaultPrim = \"hair\"\n";
  out << "    doc = "
      << quoted("hairgen " HAIRGEN_VERSION ": " + std::to_string(facts.strands) + " strands, " +
                std::to_string(facts.points) + " points" +
                (facts.frames ? ", frames " + std::to_string(facts.frames->first) + "-" +
                                    std::to_string(facts.frames->last)
                              : std::string()))
      << "\n";
  if (p.metres) out << "    metersPerUnit = 1\n";
  if (p.yUp) out << "    upAxis = \"Y\"\n";
  if (facts.frames) {
    out << "    startTimeCode = " << facts.frames->first << "\n";
    out << "    endTimeCode = " << facts.frames->last << "\n";
    out << "    timeCodesPerSecond = " << formatReal(facts.framesPerSecond) << "\n";
    out << "    framesPerSecond = " << formatReal(facts.framesPerSecond) << "\n";
  }
  out << "    customLayerData = {\n        dictionary hairgen = {\n";
  auto entry = [&](const char* key, const std::string& value) {
    out << "            string " << key << " = " << quoted(value) << "\n";
  };
  entry("producer", p.producer.empty() ? std::string("hairgen " HAIRGEN_VERSION) : p.producer);
  entry("stage", p.stage);
  entry("seed", std::to_string(p.seed));
  entry("strands", std::to_string(facts.strands));
  entry("points", std::to_string(facts.points));
  if (facts.frames)
    entry("frames", std::to_string(facts.frames->first) + "-" + std::to_string(facts.frames->last));
  entry("configDigest", p.configDigest);
  if (!p.source.empty()) entry("source", p.source);
  if (!p.sourceInfo.empty()) entry("sourceInfo", p.sourceInfo);
  if (!p.conversion.empty()) entry("conversion", p.conversion);
  entry("units", std::string(p.metres ? "metres" : "unknown (the source file's own)") + ", " +
                     (p.yUp ? "+y up" : "up axis unknown"));
  out << "        }\n    }\n)\n\n";
}

// The attributes that do not change within a shot: the curves' layout and what each curve carries.
void writeCurvesHead(std::ostream& out, const Strands& s) {
  out << "    uniform token type = \"linear\"\n";
  out << "    uniform token wrap = \"nonperiodic\"\n";
  out << "    int[] curveVertexCounts = " << arrayText(curveCounts(s)) << "\n";
}

void writeCurvesTail(std::ostream& out, const Strands& s, bool guides) {
  out << "    int primvars:groom_guide = " << (guides ? 1 : 0);
  writeMetadata(out, "constant");
  out << "\n";
  for (const Attribute& a : kCurveAttributes) writeStatic(out, a, a.encode(s));
}

// A temporary file that collects one attribute's time samples, frame by frame, until they are
// copied into the layer (a shot of a full coupe does not fit in memory as text).
class Spool {
 public:
  Spool() : file_(std::tmpfile(), &std::fclose) {
    if (!file_) throw IoError("cannot make a temporary file for the USD time samples");
  }
  void append(const std::string& text) {
    if (std::fwrite(text.data(), 1, text.size(), file_.get()) != text.size())
      throw IoError("cannot write the USD time samples to a temporary file (disk full?)");
  }
  void copyTo(std::ostream& out) {
    std::rewind(file_.get());
    std::vector<char> buffer(1 << 20);
    size_t n;
    while ((n = std::fread(buffer.data(), 1, buffer.size(), file_.get())) > 0)
      out.write(buffer.data(), std::streamsize(n));
    if (std::ferror(file_.get())) throw IoError("cannot read back the USD time samples");
  }

 private:
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file_;
};

// A prim of a shot, its frames read one at a time: the first frame's values are kept, every frame's
// spooled, and an attribute is time-sampled only when some frame differs from the first.
class ShotPrim {
 public:
  ShotPrim(const UsdShotPrim& source, const FrameRange& frames) : source_(source), frames_(frames) {
    // An animated prim's points (and so its extent) are time-sampled even while they hold still, so a
    // DCC reads the prim as animated over the whole shot.
    sampled_[kPoints].varies = sampled_[kExtent].varies = source.animated;
    const int last = source.animated ? frames.last : frames.first;
    for (int f = frames.first; f <= last; ++f) add(f);
  }
  const Strands& first() const { return first_; }
  const Provenance& lastProvenance() const { return last_; }
  size_t dropped() const { return dropped_; }

  void write(std::ostream& out, const char* name, bool guides) {
    out << "    def BasisCurves \"" << name << "\"\n    {\n";
    std::ostringstream body;
    writeCurvesHead(body, first_);
    for (size_t i = 0; i < std::size(kVertexAttributes); ++i) {
      const Attribute& a = kVertexAttributes[i];
      Sampled& s = sampled_[i];
      if (!s.varies) {
        writeStatic(body, a, s.first);
        continue;
      }
      if (s.first.interpolation) {
        body << "    " << a.type << " " << a.name;
        writeMetadata(body, s.first.interpolation);
        body << "\n";
      }
      body << "    " << a.type << " " << a.name << ".timeSamples = {\n";
      out << indented(body.str());
      body.str("");
      s.spool.copyTo(out);
      body << "    }\n";
    }
    writeCurvesTail(body, first_, guides);
    out << indented(body.str()) << "    }\n";
  }

 private:
  struct Sampled {
    Value first;
    bool varies = false;
    Spool spool;
  };

  // A prim's attribute lines, one level deeper (inside the Xform `/hair`).
  static std::string indented(const std::string& lines) {
    std::string out;
    size_t at = 0;
    while (at < lines.size()) {
      const size_t end = lines.find('\n', at);
      const size_t stop = end == std::string::npos ? lines.size() : end + 1;
      if (lines.compare(at, 4, "    ") == 0) out += "    ";
      out.append(lines, at, stop - at);
      at = stop;
    }
    return out;
  }

  void add(int f) {
    const std::string file = source_.animated ? framePath(source_.pattern, f).string() : source_.pattern;
    size_t dropped = 0;
    Strands s = withoutBareFollicles(source_.frame(f), dropped);
    namingFile(file, [&] {
      checkForUsd(s);
      if (f == frames_.first) {
        dropped_ = dropped;
        return;
      }
      if (s.firstPoint != first_.firstPoint || s.strandId != first_.strandId)
        throw InputError("frame " + std::to_string(f) + " has other strands than frame " +
                         std::to_string(frames_.first) +
                         " (counts or ids): a shot's frames must be the same strands");
    });
    for (size_t i = 0; i < std::size(kVertexAttributes); ++i) {
      Value v = kVertexAttributes[i].encode(s);
      Sampled& sampled = sampled_[i];
      if (f != frames_.first) {
        if (v.text.empty() != sampled.first.text.empty() || v.interpolation != sampled.first.interpolation)
          throw InputError({file, 0}, std::string("frame ") + std::to_string(f) + "'s " +
                                          kVertexAttributes[i].name + " is stored otherwise than frame " +
                                          std::to_string(frames_.first) +
                                          "'s (present, per vertex or "
                                          "constant)");
        sampled.varies = sampled.varies || v.text != sampled.first.text;
      }
      if (source_.animated && !v.text.empty())
        sampled.spool.append("            " + std::to_string(f) + ": " + v.text + ",\n");
      if (f == frames_.first) sampled.first = std::move(v);
    }
    last_ = s.provenance;
    if (f == frames_.first) first_ = std::move(s);
  }

  const UsdShotPrim& source_;
  FrameRange frames_;
  Strands first_;
  Provenance last_;  // the last frame's
  size_t dropped_ = 0;
  Sampled sampled_[std::size(kVertexAttributes)];
};

}  // namespace

bool areGuides(const Strands& s) {
  return s.provenance.stage == "grow" || s.provenance.stage == "simulate";
}

UsdWritten encodeUsda(std::ostream& out, const Strands& strands) {
  UsdWritten written;
  const Strands s = withoutBareFollicles(strands, written.droppedStrands);
  checkForUsd(s);
  writeLayer(out, {&s.provenance, s.strandCount(), s.pointCount()});
  out << "def BasisCurves \"hair\"\n{\n";
  writeCurvesHead(out, s);
  for (const Attribute& a : kVertexAttributes) writeStatic(out, a, a.encode(s));
  writeStatic(out, kTangents, kTangents.encode(s));
  writeCurvesTail(out, s, areGuides(s));
  out << "}\n";
  return written;
}

UsdWritten writeUsda(const std::filesystem::path& file, const Strands& strands) {
  return namingFile(file.string(), [&] {
    AtomicFile out(file);
    const UsdWritten written = encodeUsda(out.stream(), strands);
    out.commit();
    return written;
  });
}

namespace {

// The frames' rate, from the frame numbers and times the first and last frame's provenance hold
// (rounded to a millionth, what the times' text keeps); a single frame has no rate and gets 24.
double frameRateOf(const ShotPrim& prim, const UsdShotPrim& source, const FrameRange& frames) {
  constexpr double kSingleFrameRate = 24.0;  // film's; nothing moves, so any rate shows the same
  if (frames.count() == 1 || !source.animated) return kSingleFrameRate;
  const Provenance &a = prim.first().provenance, &b = prim.lastProvenance();
  if (!a.frame || !b.frame || *a.frame != frames.first || *b.frame != frames.last || !(b.time > a.time))
    throw InputError({source.pattern, 0},
                     "its frames do not say their frame and time (a cache hairgen did not simulate): give "
                     "--fps");
  return std::round(double(*b.frame - *a.frame) / (b.time - a.time) * 1e6) / 1e6;
}

}  // namespace

UsdWritten writeUsdShot(const std::filesystem::path& file, const UsdShot& shot) {
  if (!shot.strands && !shot.guides) throw InputError("a shot's USD needs strands or guides");
  if (shot.framesPerSecond && (!(*shot.framesPerSecond > 0.0) || !std::isfinite(*shot.framesPerSecond)))
    throw InputError("frames per second " + formatReal(*shot.framesPerSecond) + " is not a positive number");
  if (shot.frames.last < shot.frames.first) throw InputError("a shot's USD needs at least one frame");
  std::optional<ShotPrim> strands, guides;
  if (shot.strands) strands.emplace(*shot.strands, shot.frames);
  if (shot.guides) guides.emplace(*shot.guides, shot.frames);
  double framesPerSecond = 0.0;
  if (shot.framesPerSecond)
    framesPerSecond = *shot.framesPerSecond;
  else if (guides && shot.guides->animated)
    framesPerSecond = frameRateOf(*guides, *shot.guides, shot.frames);
  else
    framesPerSecond =
        frameRateOf(strands ? *strands : *guides, strands ? *shot.strands : *shot.guides, shot.frames);
  const Provenance& p = (strands ? *strands : *guides).first().provenance;
  if (strands && guides) {
    const Provenance& g = guides->first().provenance;
    if (g.metres != p.metres || g.yUp != p.yUp)
      throw InputError({shot.guides->pattern, 0}, "the guides' units or up axis differ from the strands' (" +
                                                      shot.strands->pattern +
                                                      "): convert both with the same --units and --up-axis");
  }
  UsdWritten written;
  LayerFacts facts{&p, 0, 0, &shot.frames, framesPerSecond};
  for (const std::optional<ShotPrim>* prim : {&strands, &guides})
    if (*prim) {
      facts.strands += (*prim)->first().strandCount();
      facts.points += (*prim)->first().pointCount();
      written.droppedStrands += (*prim)->dropped();
    }
  namingFile(file.string(), [&] {
    AtomicFile out(file);
    writeLayer(out.stream(), facts);
    out.stream() << "def Xform \"hair\"\n{\n";
    if (strands) strands->write(out.stream(), "strands", false);
    if (strands && guides) out.stream() << "\n";
    if (guides) guides->write(out.stream(), "guides", true);
    out.stream() << "}\n";
    out.commit();
  });
  return written;
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
    if (key == "defaultPrim" || key == "metersPerUnit" || key == "upAxis" || key == "startTimeCode" ||
        key == "endTimeCode" || key == "timeCodesPerSecond" || line.rfind("string ", 0) == 0)
      entries.emplace_back(oneLine(key), oneLine(value));
  });
  // hairgen writes a few dozen entries at most; thousands are no layer of its (and `info` files them by
  // name: 150,000 took a minute).
  constexpr size_t kMostEntries = 256;
  if (entries.size() > kMostEntries)
    throw InputError({file.string(), 0}, "its layer holds " + std::to_string(entries.size()) +
                                             " entries; hairgen writes at most " +
                                             std::to_string(kMostEntries) +
                                             ", so it is not a USD layer hairgen wrote (usdcat or TinyUSDZ "
                                             "describe any layer)");
  bool counted = false;
  for (const auto& [key, value] : entries) counted = counted || key == "strands";
  if (!ours || !counted)
    throw InputError({file.string(), 0},
                     "not a USD layer hairgen wrote; hairgen writes USD but does not read it (usdcat or "
                     "TinyUSDZ describe any layer)");
  return entries;
}

}  // namespace hairgen
