#include "libcore/io/ply_io.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <unordered_map>

#include "libcore/io/hair_io.h"
#include "libcore/util/checked.h"
#include "libcore/util/error.h"
#include "libcore/util/file_util.h"
#include "libcore/util/text.h"

namespace hairgen {
namespace {

// ---------------------------------------------------------------------------------------- types

enum class PlyType { kInt8, kUInt8, kInt16, kUInt16, kInt32, kUInt32, kFloat32, kFloat64 };

struct TypeName {
  const char* name;
  const char* alias;  // the sized spelling some writers use
  PlyType type;
  int bytes;
};
constexpr TypeName kTypes[] = {
    {"char", "int8", PlyType::kInt8, 1},        {"uchar", "uint8", PlyType::kUInt8, 1},
    {"short", "int16", PlyType::kInt16, 2},     {"ushort", "uint16", PlyType::kUInt16, 2},
    {"int", "int32", PlyType::kInt32, 4},       {"uint", "uint32", PlyType::kUInt32, 4},
    {"float", "float32", PlyType::kFloat32, 4}, {"double", "float64", PlyType::kFloat64, 8},
};

std::optional<PlyType> typeNamed(const std::string& name) {
  for (const TypeName& t : kTypes)
    if (name == t.name || name == t.alias) return t.type;
  return std::nullopt;
}
int bytesOf(PlyType type) {
  for (const TypeName& t : kTypes)
    if (t.type == type) return t.bytes;
  return 0;
}
const char* nameOf(PlyType type) {
  for (const TypeName& t : kTypes)
    if (t.type == type) return t.name;
  return "?";
}
bool isReal(PlyType type) {
  return type == PlyType::kFloat32 || type == PlyType::kFloat64;
}

struct Property {
  std::string name;
  PlyType type = PlyType::kFloat32;
  bool list = false;
  PlyType countType = PlyType::kUInt8;
};

struct Element {
  std::string name;
  uint64_t count = 0;
  std::vector<Property> properties;
  std::unordered_map<std::string, int> byName;  // property name -> index: a header of a million
                                                // properties is read in linear time
  int find(const std::string& property) const {
    const auto it = byName.find(property);
    return it == byName.end() ? -1 : it->second;
  }
  // Adds `p`; false when the element already has a property of that name.
  bool add(Property p) {
    if (!byName.try_emplace(p.name, static_cast<int>(properties.size())).second) return false;
    properties.push_back(std::move(p));
    return true;
  }
};

enum class Format { kAscii, kLittle, kBig };

// ------------------------------------------------------------------------------ what hairgen reads

// A per-strand count property: its name and what it counts.
struct CountProperty {
  const char* name;
  uint32_t pointsPerCount;  // 1: the count is of segments (points = count + 1); 0: of points
};
constexpr CountProperty kStrandCounts[] = {{"nsegs", 1}, {"vertex_count", 0}};

// The names of the per-point and per-strand arrays hairgen reads and writes, one declaration each.
constexpr const char* kNormal[3] = {"nx", "ny", "nz"};
constexpr const char* kTangent[3] = {"tangent_x", "tangent_y", "tangent_z"};
constexpr const char* kColor[3] = {"red", "green", "blue"};
constexpr const char* kThickness = "thickness";
constexpr const char* kTransparency = "transparency";
constexpr const char* kStrandId = "strand_id";
constexpr const char* kRootTriangle = "root_triangle";
constexpr const char* kRootBary[3] = {"root_bary0", "root_bary1", "root_bary2"};
constexpr const char* kRootUv[2] = {"root_u", "root_v"};
constexpr const char* kGuide[3] = {"guide0", "guide1", "guide2"};
constexpr const char* kWeight[3] = {"weight0", "weight1", "weight2"};
constexpr const char* kCommentTag = "hairgen ";  // `comment hairgen key=value`

// The address of component c of a vector array's first element, or null for an empty array (whose
// element has no records to store).
template <typename Vec, class A>
auto* component(std::vector<Vec, A>& values, int c) {
  return values.empty() ? nullptr : &values[0][c];
}

// Where a decoded value goes: a float or a uint32 slot `stride` apart, times `scale`.
struct Sink {
  float* f = nullptr;
  uint32_t* u = nullptr;
  size_t stride = 1;
  double scale = 1.0;
  std::string what;  // "vertex property red", for messages
};

// -------------------------------------------------------------------------------------- header

struct Header {
  Format format = Format::kAscii;
  std::vector<Element> elements;
  std::vector<std::string> comments;  // comment and obj_info lines, without the keyword
  size_t bodyOffset = 0;
};

Header parseHeader(const uint8_t* data, size_t size, const std::string& name) {
  auto fail = [&](int line, const std::string& message) { return InputError({name, line}, message); };
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  if (text.substr(0, 3) != "ply" || size < 4 || (text[3] != '\n' && text[3] != '\r'))
    throw fail(0, "not a PLY file: it does not start with \"ply\"");
  Header h;
  bool formatSeen = false, ended = false;
  size_t pos = 0;
  int number = 0;
  while (pos < size && !ended) {
    size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) throw fail(0, "the header has no end_header line");
    std::string_view line = text.substr(pos, end - pos);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos = end + 1;
    ++number;
    std::vector<std::string> words;
    for (size_t i = 0; i < line.size();) {
      while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
      size_t j = i;
      while (j < line.size() && line[j] != ' ' && line[j] != '\t') ++j;
      if (j > i) words.emplace_back(line.substr(i, j - i));
      i = j;
    }
    if (words.empty()) continue;
    const std::string& key = words[0];
    if (key == "ply" && number == 1) continue;
    if (key == "comment" || key == "obj_info") {
      std::string_view rest = line.substr(std::min(line.size(), line.find(key) + key.size()));
      while (!rest.empty() && (rest.front() == ' ' || rest.front() == '\t')) rest.remove_prefix(1);
      h.comments.emplace_back(rest);
    } else if (key == "format") {
      if (words.size() != 3 || words[2] != "1.0")
        throw fail(number, "expected 'format ascii|binary_little_endian|binary_big_endian 1.0'");
      if (words[1] == "ascii")
        h.format = Format::kAscii;
      else if (words[1] == "binary_little_endian")
        h.format = Format::kLittle;
      else if (words[1] == "binary_big_endian")
        h.format = Format::kBig;
      else
        throw fail(number, "unknown PLY format '" + oneLine(words[1]) + "'");
      formatSeen = true;
    } else if (key == "element") {
      std::optional<uint64_t> count = words.size() == 3 ? parseUInt(words[2]) : std::nullopt;
      if (!count) throw fail(number, "expected 'element NAME COUNT' with a non-negative count");
      h.elements.push_back({words[1], *count, {}, {}});
    } else if (key == "property") {
      if (h.elements.empty()) throw fail(number, "a property before any element");
      Property p;
      if (words.size() == 5 && words[1] == "list") {
        std::optional<PlyType> countType = typeNamed(words[2]), type = typeNamed(words[3]);
        if (!countType || !type || isReal(*countType))
          throw fail(number, "expected 'property list INTEGER-TYPE TYPE NAME'");
        p = {words[4], *type, true, *countType};
      } else if (words.size() == 3 && typeNamed(words[1])) {
        p = {words[2], *typeNamed(words[1]), false, PlyType::kUInt8};
      } else {
        throw fail(number, "expected 'property TYPE NAME' or 'property list COUNT-TYPE TYPE NAME'");
      }
      const std::string propertyName = p.name;
      if (!h.elements.back().add(std::move(p)))
        throw fail(number, "property '" + oneLine(propertyName) + "' appears twice in element '" +
                               oneLine(h.elements.back().name) + "'");
    } else if (key == "end_header") {
      ended = true;
    } else {
      throw fail(number, "unknown header line '" + oneLine(std::string(line.substr(0, 40))) + "'");
    }
  }
  if (!ended) throw fail(0, "the header has no end_header line");
  if (!formatSeen) throw fail(0, "the header has no format line");
  h.bodyOffset = pos;
  return h;
}

// ---------------------------------------------------------------------------------------- body

class Body {
 public:
  Body(const uint8_t* data, size_t size, size_t offset, Format format, const std::string& name)
      : data_(data), size_(size), pos_(offset), format_(format), name_(name) {}

  size_t remaining() const { return size_ - pos_; }

  // The fewest bytes one record of `e` can take: its scalars and list counts in binary, two bytes a
  // value ("0 ") in ASCII.
  uint64_t minimumRecordBytes(const Element& e) const {
    uint64_t bytes = 0;
    for (const Property& p : e.properties)
      bytes += format_ == Format::kAscii ? 2 : bytesOf(p.list ? p.countType : p.type);
    return bytes;
  }

  // Reads one value of `type`.
  double value(PlyType type, const std::string& what) {
    if (format_ == Format::kAscii) return asciiValue(type, what);
    const int n = bytesOf(type);
    if (remaining() < size_t(n)) throw truncated(what);
    uint8_t b[8];
    std::memcpy(b, data_ + pos_, n);
    pos_ += n;
    if (format_ == Format::kBig) std::reverse(b, b + n);
    switch (type) {
      case PlyType::kInt8:
        return double(int8_t(b[0]));
      case PlyType::kUInt8:
        return double(b[0]);
      case PlyType::kInt16: {
        int16_t v;
        std::memcpy(&v, b, 2);
        return v;
      }
      case PlyType::kUInt16: {
        uint16_t v;
        std::memcpy(&v, b, 2);
        return v;
      }
      case PlyType::kInt32: {
        int32_t v;
        std::memcpy(&v, b, 4);
        return v;
      }
      case PlyType::kUInt32: {
        uint32_t v;
        std::memcpy(&v, b, 4);
        return v;
      }
      case PlyType::kFloat32: {
        float v;
        std::memcpy(&v, b, 4);
        return v;
      }
      case PlyType::kFloat64:
        break;
    }
    double v;
    std::memcpy(&v, b, 8);
    return v;
  }

  // Reads a float property's value as the float it is (ASCII text rounds once, to float).
  float floatValue(PlyType type, const std::string& what) {
    if (format_ != Format::kAscii || type != PlyType::kFloat32) return static_cast<float>(value(type, what));
    std::string_view token = nextToken(what);
    float v = 0.0f;
    const char* first = token.data() + (token.size() > 1 && token[0] == '+' ? 1 : 0);
    auto [end, ec] = std::from_chars(first, token.data() + token.size(), v);
    if (ec != std::errc() || end != token.data() + token.size())
      throw InputError({name_, 0},
                       what + ": '" + oneLine(std::string(token.substr(0, 32))) + "' is not a number");
    return v;
  }

  InputError truncated(const std::string& what) const {
    return InputError({name_, 0}, "truncated: the file ends in " + what);
  }

  bool atEnd() {
    if (format_ == Format::kAscii)
      while (pos_ < size_ && std::isspace(data_[pos_])) ++pos_;
    return pos_ == size_;
  }

 private:
  std::string_view nextToken(const std::string& what) {
    while (pos_ < size_ && std::isspace(data_[pos_])) ++pos_;
    size_t start = pos_;
    while (pos_ < size_ && !std::isspace(data_[pos_])) ++pos_;
    if (pos_ == start) throw truncated(what);
    return {reinterpret_cast<const char*>(data_ + start), pos_ - start};
  }

  double asciiValue(PlyType type, const std::string& what) {
    std::string_view token = nextToken(what);
    std::optional<double> v = parseReal(token);
    if (!v)
      throw InputError({name_, 0},
                       what + ": '" + oneLine(std::string(token.substr(0, 32))) + "' is not a number");
    if (!isReal(type) && *v != std::floor(*v))
      throw InputError({name_, 0}, what + ": '" + oneLine(std::string(token)) + "' is not a whole number");
    return *v;
  }

  const uint8_t* data_;
  size_t size_;
  size_t pos_;
  Format format_;
  const std::string& name_;
};

// The whole number a count or index property holds, checked to fit uint32.
uint32_t wholeNumber(double v, const std::string& what, const std::string& name) {
  if (!(v >= 0.0) || v > double(std::numeric_limits<uint32_t>::max()) || v != std::floor(v))
    throw InputError({name, 0}, what + " holds " + formatReal(v) + ", not a whole number in [0, 2^32)");
  return static_cast<uint32_t>(v);
}

// The scale that brings a colour property to [0, 1].
double colorScale(PlyType type, const std::string& name) {
  switch (type) {
    case PlyType::kUInt8:
      return 1.0 / 255.0;
    case PlyType::kUInt16:
      return 1.0 / 65535.0;
    case PlyType::kFloat32:
    case PlyType::kFloat64:
      return 1.0;
    default:
      throw InputError({name, 0}, std::string("vertex colours of type ") + nameOf(type) +
                                      " are not supported (uchar, ushort, float or double)");
  }
}

}  // namespace

// ------------------------------------------------------------------------------------- decoding

Strands decodePly(const uint8_t* data, size_t size, const std::string& name, PlyHeader* headerOut) {
  const Header h = parseHeader(data, size, name);
  Body body(data, size, h.bodyOffset, h.format, name);

  const Element* vertex = nullptr;
  const Element* strand = nullptr;
  const Element* edge = nullptr;
  bool faces = false;
  for (const Element& e : h.elements) {
    if (e.name == "vertex" && !vertex) vertex = &e;
    if (e.name == "strand" && !strand) strand = &e;
    if (e.name == "edge" && !edge) edge = &e;
    faces = faces || e.name == "face";
    // Every element's records must fit in the bytes that follow the header, before anything is
    // allocated for any of them (an element with no properties has empty records).
    std::optional<uint64_t> bytes = checkedMul(e.count, body.minimumRecordBytes(e));
    if (!bytes || *bytes > size - h.bodyOffset)
      throw InputError({name, 0}, "element '" + oneLine(e.name) + "' declares " + std::to_string(e.count) +
                                      " records, more than the " + std::to_string(size - h.bodyOffset) +
                                      " bytes after the header can hold");
  }
  if (!vertex) throw InputError({name, 0}, "no 'vertex' element: the file holds no points");
  for (const char* axis : {"x", "y", "z"})
    if (vertex->find(axis) < 0 || vertex->properties[vertex->find(axis)].list)
      throw InputError({name, 0}, std::string("the vertex element has no scalar property '") + axis + "'");
  if (vertex->count > std::numeric_limits<uint32_t>::max() - 1)
    throw InputError({name, 0}, "more than 2^32 - 2 vertices");

  const CountProperty* counts = nullptr;
  if (strand)
    for (const CountProperty& c : kStrandCounts)
      if (!counts && strand->find(c.name) >= 0 && !strand->properties[strand->find(c.name)].list) counts = &c;
  const bool byEdges = !counts && edge && edge->find("vertex1") >= 0 && edge->find("vertex2") >= 0;
  if (!counts && !byEdges)
    throw InputError({name, 0}, std::string(faces ? "a mesh (it has faces), not strands: " : "") +
                                    "a PLY of strands needs a 'strand' element with 'nsegs' or "
                                    "'vertex_count', or an 'edge' element with 'vertex1' and 'vertex2'");

  Strands s;
  const size_t n = vertex->count;
  s.points.resize(n);
  std::vector<Sink> vertexSinks(vertex->properties.size()), strandSinks, edgeSinks;
  auto sinkFloat = [&](std::vector<Sink>& sinks, const Element& e, const char* property, float* base,
                       size_t stride, double scale = 1.0) {
    int i = e.find(property);
    if (i < 0 || e.properties[i].list) return false;
    sinks[i] = {base, nullptr, stride, scale, e.name + " property " + property};
    return true;
  };
  // A vector attribute is read when the vertex has its three components, each a scalar (`out` is sized
  // only then, and every element is written: tangents are a PointArray, which sizing leaves unset).
  auto sinkVec3 = [&](const char* const names[3], auto& out) {
    for (int c = 0; c < 3; ++c)
      if (vertex->find(names[c]) < 0) return;
    for (int c = 0; c < 3; ++c)
      if (vertex->properties[vertex->find(names[c])].list)
        throw InputError({name, 0}, std::string("the vertex element's property '") + names[c] +
                                        "' is a list; hairgen reads it as one number per vertex");
    out.resize(n);
    for (int c = 0; c < 3; ++c) sinkFloat(vertexSinks, *vertex, names[c], component(out, c), 3);
  };
  constexpr const char* kAxes[3] = {"x", "y", "z"};
  for (int c = 0; c < 3; ++c) sinkFloat(vertexSinks, *vertex, kAxes[c], component(s.points, c), 3);
  sinkVec3(kNormal, s.normals);
  sinkVec3(kTangent, s.tangents);
  if (vertex->find(kColor[0]) >= 0 && vertex->find(kColor[1]) >= 0 && vertex->find(kColor[2]) >= 0) {
    s.colors.resize(n);
    for (int c = 0; c < 3; ++c)
      sinkFloat(vertexSinks, *vertex, kColor[c], component(s.colors, c), 3,
                colorScale(vertex->properties[vertex->find(kColor[c])].type, name));
  }
  if (vertex->find(kThickness) >= 0) {
    s.thickness.resize(n);
    sinkFloat(vertexSinks, *vertex, kThickness, s.thickness.empty() ? nullptr : s.thickness.data(), 1);
  }
  if (vertex->find(kTransparency) >= 0) {
    s.transparency.resize(n);
    sinkFloat(vertexSinks, *vertex, kTransparency, s.transparency.data(), 1);
  }

  std::vector<uint32_t> strandCounts, edgeFrom, edgeTo;
  if (counts) {
    const size_t strands = strand->count;
    strandSinks.resize(strand->properties.size());
    strandCounts.resize(strands);
    strandSinks[strand->find(counts->name)] = {nullptr, strandCounts.data(), 1, 1.0,
                                               "strand property " + std::string(counts->name)};
    auto sinkUInt = [&](const char* property, uint32_t* base, size_t stride) {
      int i = strand->find(property);
      if (i >= 0 && !strand->properties[i].list)
        strandSinks[i] = {nullptr, base, stride, 1.0, "strand property " + std::string(property)};
    };
    auto has = [&](const char* const* names, int count) {
      for (int c = 0; c < count; ++c)
        if (strand->find(names[c]) < 0) return false;
      return true;
    };
    if (strand->find(kStrandId) >= 0) {
      s.strandId.resize(strands);
      sinkUInt(kStrandId, s.strandId.data(), 1);
    }
    if (strand->find(kRootTriangle) >= 0) {
      s.rootTriangle.resize(strands);
      sinkUInt(kRootTriangle, s.rootTriangle.data(), 1);
    }
    if (has(kRootBary, 3)) {
      s.rootBary.resize(strands);
      for (int c = 0; c < 3; ++c) sinkFloat(strandSinks, *strand, kRootBary[c], component(s.rootBary, c), 3);
    }
    if (has(kRootUv, 2)) {
      s.rootUv.resize(strands);
      for (int c = 0; c < 2; ++c) sinkFloat(strandSinks, *strand, kRootUv[c], component(s.rootUv, c), 2);
    }
    if (has(kGuide, 3)) {
      s.guideIds.resize(strands);
      for (int c = 0; c < 3; ++c) sinkUInt(kGuide[c], component(s.guideIds, c), 3);
    }
    if (has(kWeight, 3)) {
      s.guideWeights.resize(strands);
      for (int c = 0; c < 3; ++c)
        sinkFloat(strandSinks, *strand, kWeight[c], component(s.guideWeights, c), 3);
    }
  } else {
    edgeSinks.resize(edge->properties.size());
    edgeFrom.resize(edge->count);
    edgeTo.resize(edge->count);
    edgeSinks[edge->find("vertex1")] = {nullptr, edgeFrom.data(), 1, 1.0, "edge property vertex1"};
    edgeSinks[edge->find("vertex2")] = {nullptr, edgeTo.data(), 1, 1.0, "edge property vertex2"};
  }

  // Every element in file order; the ones hairgen does not read are parsed and dropped.
  for (const Element& e : h.elements) {
    std::vector<Sink>* sinks = &e == vertex             ? &vertexSinks
                               : &e == strand && counts ? &strandSinks
                               : &e == edge && byEdges  ? &edgeSinks
                                                        : nullptr;
    if (e.properties.empty()) continue;
    const std::string element = "element '" + oneLine(e.name) + "' record ";
    for (uint64_t r = 0; r < e.count; ++r) {
      const std::string what = element + std::to_string(r);  // once a record, not once a value
      for (size_t p = 0; p < e.properties.size(); ++p) {
        const Property& prop = e.properties[p];
        if (prop.list) {
          const uint32_t count = wholeNumber(body.value(prop.countType, what), what + " list count", name);
          // A list's items must fit in what is left before they are read one by one.
          std::optional<uint64_t> bytes =
              checkedMul(count, h.format == Format::kAscii ? 2 : bytesOf(prop.type));
          if (!bytes || *bytes > body.remaining()) throw body.truncated(what);
          for (uint32_t i = 0; i < count; ++i) body.value(prop.type, what);
          continue;
        }
        const Sink* sink = sinks && ((*sinks)[p].f || (*sinks)[p].u) ? &(*sinks)[p] : nullptr;
        if (!sink) {
          body.value(prop.type, what);
        } else if (sink->f) {
          const float v = sink->scale == 1.0
                              ? body.floatValue(prop.type, sink->what)
                              : static_cast<float>(body.value(prop.type, sink->what) * sink->scale);
          sink->f[r * sink->stride] = v;
        } else {
          sink->u[r * sink->stride] = wholeNumber(body.value(prop.type, sink->what),
                                                  sink->what + " of record " + std::to_string(r), name);
        }
      }
    }
  }
  if (!body.atEnd()) throw InputError({name, 0}, "unexpected bytes after the last element");

  // The strands: counts per strand, or runs of vertices joined by edges.
  if (counts) {
    s.firstPoint.assign(1, 0);
    uint64_t total = 0;
    for (size_t i = 0; i < strandCounts.size(); ++i) {
      total += uint64_t(strandCounts[i]) + counts->pointsPerCount;
      if (total > n)
        throw InputError({name, 0}, "the strands' " + std::string(counts->name) + " need more than the " +
                                        std::to_string(n) + " vertices (strand " + std::to_string(i) + ")");
      s.firstPoint.push_back(static_cast<uint32_t>(total));
    }
    if (total != n)
      throw InputError({name, 0}, "the strands' " + std::string(counts->name) + " cover " +
                                      std::to_string(total) + " vertices but the file has " +
                                      std::to_string(n));
  } else {
    std::vector<bool> joinsNext(n, false);
    for (size_t i = 0; i < edgeFrom.size(); ++i) {
      const uint32_t a = std::min(edgeFrom[i], edgeTo[i]), b = std::max(edgeFrom[i], edgeTo[i]);
      if (b >= n)
        throw InputError({name, 0}, "edge " + std::to_string(i) + " names vertex " + std::to_string(b) +
                                        ", past the " + std::to_string(n) + " vertices");
      if (b != a + 1)
        throw InputError({name, 0}, "edge " + std::to_string(i) + " (" + std::to_string(edgeFrom[i]) + ", " +
                                        std::to_string(edgeTo[i]) +
                                        ") does not join consecutive vertices; hairgen reads strands stored "
                                        "as runs of vertices");
      joinsNext[a] = true;
    }
    s.firstPoint.assign(1, 0);
    for (size_t i = 1; i < n; ++i)
      if (!joinsNext[i - 1]) s.firstPoint.push_back(static_cast<uint32_t>(i));
    if (n > 0) s.firstPoint.push_back(static_cast<uint32_t>(n));
  }

  // hairgen's comments hold its provenance and the cyHair defaults; any other comment is the source's.
  std::string provenance, sourceInfo;
  for (const std::string& comment : h.comments) {
    if (comment.rfind(kCommentTag, 0) != 0) {
      sourceInfo += (sourceInfo.empty() ? "" : "; ") + oneLine(comment);
      continue;
    }
    const std::string line = comment.substr(std::strlen(kCommentTag));
    auto real = [&](const char* key) -> std::optional<float> {
      const std::string prefix = std::string(key) + "=";
      if (line.rfind(prefix, 0) != 0) return std::nullopt;
      std::optional<double> v = parseReal(line.substr(prefix.size()));
      if (!v) throw InputError({name, 0}, "comment '" + oneLine(comment) + "': not a number");
      return static_cast<float>(*v);
    };
    if (auto v = real("defaultThickness")) {
      s.defaultThickness = *v;
    } else if (auto t = real("defaultTransparency")) {
      s.defaultTransparency = *t;
    } else if (line.rfind("defaultColor=", 0) == 0) {
      std::string rest = line.substr(13);
      for (int c = 0; c < 3; ++c) {
        size_t space = rest.find(' ');
        std::optional<double> component = parseReal(rest.substr(0, space));
        if (!component) throw InputError({name, 0}, "comment '" + oneLine(comment) + "': not three numbers");
        s.defaultColor[c] = static_cast<float>(*component);
        rest = space == std::string::npos ? "" : rest.substr(space + 1);
      }
    } else {
      provenance += line + "\n";
    }
  }
  if (!provenance.empty()) {
    s.provenance = parseProvenance(provenance, name);
  } else {
    s.provenance.metres = s.provenance.yUp = false;  // the data sets' own units and axes
    s.provenance.sourceInfo = sourceInfo;
  }
  s.validate(name);

  if (headerOut) {
    static const char* kFormats[] = {"ascii", "binary_little_endian", "binary_big_endian"};
    headerOut->format = kFormats[static_cast<int>(h.format)];
    headerOut->elements.clear();
    for (const Element& e : h.elements) {
      std::string line = e.name + " " + std::to_string(e.count) + ":";
      for (const Property& p : e.properties) line += " " + p.name;
      headerOut->elements.push_back(oneLine(line));
    }
    headerOut->strandsFrom = counts ? "strand " + std::string(counts->name) : "edge";
  }
  return s;
}

// ------------------------------------------------------------------------------------- encoding

namespace {

class PlyWriter {
 public:
  explicit PlyWriter(bool ascii) : ascii_(ascii) {}
  void f32(float v) {
    if (ascii_) {
      text(formatFloat(v));
    } else {
      uint32_t bits;
      std::memcpy(&bits, &v, 4);
      le(bits, 4);
    }
  }
  void u8(uint8_t v) { ascii_ ? text(std::to_string(v)) : le(v, 1); }
  void u16(uint16_t v) { ascii_ ? text(std::to_string(v)) : le(v, 2); }
  void u32(uint32_t v) { ascii_ ? text(std::to_string(v)) : le(v, 4); }
  void endRecord() {
    if (ascii_) {
      if (!out.empty() && out.back() == ' ') out.pop_back();
      out.push_back('\n');
    }
  }
  std::vector<uint8_t> out;

 private:
  void text(const std::string& t) {
    out.insert(out.end(), t.begin(), t.end());
    out.push_back(' ');
  }
  void le(uint32_t v, int bytes) {
    for (int i = 0; i < bytes; ++i) out.push_back(uint8_t(v >> (8 * i)));
  }
  bool ascii_;
};

uint8_t colorByte(float v) {
  return static_cast<uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f));
}

}  // namespace

std::vector<uint8_t> encodePly(const Strands& s, bool ascii) {
  s.validate("strands to write");
  const size_t strands = s.strandCount(), n = s.pointCount();
  if (n > std::numeric_limits<uint32_t>::max() - 1) throw InputError("too many points for a PLY file");
  bool shortCounts = true;
  uint64_t segments = 0;
  for (size_t i = 0; i < strands; ++i) {
    if (s.pointsOf(i) == 0)
      throw InputError("strand " + std::to_string(i) + " has no points; a PLY strand cannot store it");
    shortCounts = shortCounts && s.pointsOf(i) - 1 <= 0xffff;
    segments += s.pointsOf(i) - 1;
  }
  const bool intEdges = n <= uint64_t(std::numeric_limits<int32_t>::max());

  std::string head = "ply\nformat " + std::string(ascii ? "ascii" : "binary_little_endian") + " 1.0\n";
  std::string provenance = provenanceText(s.provenance);
  for (size_t pos = 0; pos < provenance.size();) {
    size_t end = provenance.find('\n', pos);
    head += "comment " + std::string(kCommentTag) + provenance.substr(pos, end - pos) + "\n";
    pos = end + 1;
  }
  head +=
      "comment " + std::string(kCommentTag) + "defaultThickness=" + formatFloat(s.defaultThickness) + "\n";
  head += "comment " + std::string(kCommentTag) +
          "defaultTransparency=" + formatFloat(s.defaultTransparency) + "\n";
  head += "comment " + std::string(kCommentTag) + "defaultColor=" + formatFloat(s.defaultColor.x) + " " +
          formatFloat(s.defaultColor.y) + " " + formatFloat(s.defaultColor.z) + "\n";
  auto property = [&](const char* type, const char* name) {
    head += "property " + std::string(type) + " " + name + "\n";
  };
  head += "element vertex " + std::to_string(n) + "\n";
  for (const char* axis : {"x", "y", "z"}) property("float", axis);
  if (!s.normals.empty())
    for (const char* c : kNormal) property("float", c);
  if (!s.tangents.empty())
    for (const char* c : kTangent) property("float", c);
  if (!s.colors.empty())
    for (const char* c : kColor) property("uchar", c);
  if (!s.thickness.empty()) property("float", kThickness);
  if (!s.transparency.empty()) property("float", kTransparency);
  head += "element strand " + std::to_string(strands) + "\n";
  property(shortCounts ? "ushort" : "uint", "nsegs");
  if (!s.strandId.empty()) property("uint", kStrandId);
  if (!s.rootTriangle.empty()) property("uint", kRootTriangle);
  if (!s.rootBary.empty())
    for (const char* c : kRootBary) property("float", c);
  if (!s.rootUv.empty())
    for (const char* c : kRootUv) property("float", c);
  if (!s.guideIds.empty())
    for (const char* c : kGuide) property("uint", c);
  if (!s.guideWeights.empty())
    for (const char* c : kWeight) property("float", c);
  head += "element edge " + std::to_string(segments) + "\n";
  property(intEdges ? "int" : "uint", "vertex1");
  property(intEdges ? "int" : "uint", "vertex2");
  head += "end_header\n";

  PlyWriter w(ascii);
  w.out.assign(head.begin(), head.end());
  for (size_t p = 0; p < n; ++p) {
    for (int c = 0; c < 3; ++c) w.f32(s.points[p][c]);
    if (!s.normals.empty())
      for (int c = 0; c < 3; ++c) w.f32(s.normals[p][c]);
    if (!s.tangents.empty())
      for (int c = 0; c < 3; ++c) w.f32(s.tangents[p][c]);
    if (!s.colors.empty())
      for (int c = 0; c < 3; ++c) w.u8(colorByte(s.colors[p][c]));
    if (!s.thickness.empty()) w.f32(s.thickness[p]);
    if (!s.transparency.empty()) w.f32(s.transparency[p]);
    w.endRecord();
  }
  for (size_t i = 0; i < strands; ++i) {
    shortCounts ? w.u16(static_cast<uint16_t>(s.pointsOf(i) - 1)) : w.u32(s.pointsOf(i) - 1);
    if (!s.strandId.empty()) w.u32(s.strandId[i]);
    if (!s.rootTriangle.empty()) w.u32(s.rootTriangle[i]);
    if (!s.rootBary.empty())
      for (int c = 0; c < 3; ++c) w.f32(s.rootBary[i][c]);
    if (!s.rootUv.empty())
      for (int c = 0; c < 2; ++c) w.f32(s.rootUv[i][c]);
    if (!s.guideIds.empty())
      for (int c = 0; c < 3; ++c) w.u32(s.guideIds[i][c]);
    if (!s.guideWeights.empty())
      for (int c = 0; c < 3; ++c) w.f32(s.guideWeights[i][c]);
    w.endRecord();
  }
  for (size_t i = 0; i < strands; ++i)
    for (uint32_t p = s.firstPoint[i]; p + 1 < s.firstPoint[i + 1]; ++p) {
      w.u32(p);
      w.u32(p + 1);
      w.endRecord();
    }
  return std::move(w.out);
}

Strands readPly(const std::filesystem::path& file, PlyHeader* header) {
  std::vector<uint8_t> bytes = readFileBytes(file);
  return decodePly(bytes.data(), bytes.size(), file.string(), header);
}

void writePly(const std::filesystem::path& file, const Strands& strands, bool ascii) {
  std::vector<uint8_t> bytes = namingFile(file.string(), [&] { return encodePly(strands, ascii); });
  writeFileAtomic(file, bytes.data(), bytes.size());
}

}  // namespace hairgen
