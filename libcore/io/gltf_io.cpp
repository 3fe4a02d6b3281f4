#include "libcore/io/gltf_io.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <optional>
#include <ostream>
#include <sstream>
#include <string_view>
#include <utility>

#include <tiny_gltf.h>
#include <nlohmann/json.hpp>

#include "libcore/util/checked.h"
#include "libcore/util/error.h"
#include "libcore/util/file_util.h"
#include "libcore/util/text.h"

namespace hairgen {
namespace {

using tinygltf::Value;

// Old files (before per-strand accessors) stored ids on every vertex as floats: exact below 2^24.
constexpr uint32_t kMaxExactId = 1u << 24;

// The id stored as a float at `value`, checked to be a whole number in range.
uint32_t idFrom(float value, const std::string& what, const std::string& name) {
  if (!(value >= 0.0f) || value >= float(kMaxExactId) || value != std::floor(value))
    throw InputError({name, 0},
                     what + " holds " + std::to_string(value) + ", not a whole number in [0, 2^24)");
  return static_cast<uint32_t>(value);
}

// A checked view of one accessor's elements.
class AccessorView {
 public:
  AccessorView(const tinygltf::Model& model, int index, const std::string& what, const std::string& name) {
    auto fail = [&](const std::string& message) { return InputError({name, 0}, what + ": " + message); };
    if (index < 0 || static_cast<size_t>(index) >= model.accessors.size())
      throw fail("accessor index out of range");
    const tinygltf::Accessor& a = model.accessors[index];
    if (a.sparse.isSparse) throw fail("sparse accessors are not supported");
    if (a.bufferView < 0 || static_cast<size_t>(a.bufferView) >= model.bufferViews.size())
      throw fail("the accessor has no valid bufferView");
    const tinygltf::BufferView& v = model.bufferViews[a.bufferView];
    if (v.buffer < 0 || static_cast<size_t>(v.buffer) >= model.buffers.size())
      throw fail("bufferView names no buffer");
    const std::vector<unsigned char>& data = model.buffers[v.buffer].data;
    int componentSize = tinygltf::GetComponentSizeInBytes(static_cast<uint32_t>(a.componentType));
    int components = tinygltf::GetNumComponentsInType(static_cast<uint32_t>(a.type));
    if (componentSize <= 0 || components <= 0) throw fail("invalid componentType or type");
    int stride = a.ByteStride(v);
    if (stride <= 0) throw fail("invalid byteStride");
    const uint64_t elementSize = uint64_t(componentSize) * uint64_t(components);
    if (v.byteOffset > data.size() || v.byteLength > data.size() - v.byteOffset)
      throw fail("bufferView reaches past the end of its buffer");
    // In exact arithmetic: a count near 2^64 must not wrap past the check and read outside the buffer.
    if (!extentFits(a.byteOffset, a.count, uint64_t(stride), elementSize, v.byteLength))
      throw fail("accessor of " + std::to_string(a.count) +
                 " elements reaches past the end of its bufferView");
    base_ = data.data() + v.byteOffset + a.byteOffset;
    count_ = a.count;
    stride_ = static_cast<size_t>(stride);
    componentType_ = a.componentType;
    components_ = components;
    what_ = what;
    name_ = name;
  }

  size_t count() const { return count_; }
  void expect(int componentType, int components) const {
    if (componentType_ != componentType || components_ != components)
      throw InputError({name_, 0}, what_ + ": expected " + std::to_string(components) +
                                       " component(s) of type " + std::to_string(componentType) + ", found " +
                                       std::to_string(components_) + " of type " +
                                       std::to_string(componentType_));
  }
  float f(size_t i, int c) const {
    float v;
    std::memcpy(&v, base_ + i * stride_ + 4 * c, 4);
    return v;
  }
  uint32_t u(size_t i, int c) const {
    const unsigned char* p = base_ + i * stride_;
    switch (componentType_) {
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
        return p[c];
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        uint16_t v;
        std::memcpy(&v, p + 2 * c, 2);
        return v;
      }
      default: {
        uint32_t v;
        std::memcpy(&v, p + 4 * c, 4);
        return v;
      }
    }
  }
  int componentType() const { return componentType_; }

 private:
  const unsigned char* base_ = nullptr;
  size_t count_ = 0, stride_ = 0;
  int componentType_ = 0, components_ = 0;
  std::string what_, name_;
};

double numberOr(const Value& object, const char* key, double fallback) {
  if (!object.IsObject() || !object.Has(key)) return fallback;
  const Value& v = object.Get(key);
  return v.IsNumber() ? v.GetNumberAsDouble() : fallback;
}

std::string stringOr(const Value& object, const char* key) {
  if (!object.IsObject() || !object.Has(key) || !object.Get(key).IsString()) return {};
  return object.Get(key).Get<std::string>();
}

// ---------------------------------------------------------------------------------- external files
//
// A glTF may name buffers and images by URI. hairgen reads only what sits beside the file: a data: URI,
// or a relative path to a regular file inside the glTF's own folder. An absolute path, "..", a
// directory, a device or a FIFO is refused by name; the file-system callbacks given to tinygltf enforce
// the same rule again on the paths it builds (it also tries the working directory, and an absolute
// path with no base folder), so nothing outside the folder is ever opened.

// The JSON text of a .gltf, or the JSON chunk of a .glb ("" when the chunk is malformed: tinygltf then
// reports the file as unreadable).
std::string jsonOf(const uint8_t* data, size_t size, bool binary) {
  if (!binary) return std::string(reinterpret_cast<const char*>(data), size);
  if (size < 20) return {};
  uint32_t length, type;
  std::memcpy(&length, data + 12, 4);
  std::memcpy(&type, data + 16, 4);
  if (type != 0x4E4F534Au || length > size - 20) return {};  // "JSON"
  return std::string(reinterpret_cast<const char*>(data) + 20, length);
}

// %XX decoded, as tinygltf decodes URIs before it opens them.
std::string decodeUri(const std::string& uri) {
  std::string out;
  for (size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '%' && i + 2 < uri.size() && std::isxdigit(static_cast<unsigned char>(uri[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(uri[i + 2]))) {
      out += char(std::stoi(uri.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      out += uri[i];
    }
  }
  return out;
}

// Why the file `path` (reached from `uri`) may not be read, or "" when it may: it must be a regular
// file whose real path lies inside the real `baseDir`.
std::string refusal(const std::filesystem::path& path, const std::filesystem::path& baseDir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (baseDir.empty()) return "a glTF read from memory has no folder to read external files from";
  const fs::path base = fs::weakly_canonical(fs::absolute(baseDir, ec), ec);
  const fs::path real = fs::weakly_canonical(fs::absolute(path, ec), ec);
  const fs::path relative = real.lexically_relative(base);
  if (ec || relative.empty() || *relative.begin() == "..") return "it lies outside the glTF's folder";
  const fs::file_status status = fs::status(real, ec);
  if (!fs::exists(status)) return "there is no such file beside the glTF";
  if (fs::is_directory(status)) return "it is a directory";
  if (!fs::is_regular_file(status)) return "it is not a regular file (a device, FIFO or socket)";
  return {};
}

// The deepest nesting of arrays and objects in JSON text (strings skipped), without parsing it: a glTF
// is a few levels deep, and its `extras` are any JSON, which tinygltf converts by recursion (20,000
// levels of [[[...]]] overflowed the stack: a crash, from a 42 KB file).
size_t jsonDepth(const std::string& json) {
  size_t depth = 0, deepest = 0;
  bool inString = false, escaped = false;
  for (const char c : json) {
    if (inString) {
      if (escaped)
        escaped = false;
      else if (c == '\\')
        escaped = true;
      else if (c == '"')
        inString = false;
    } else if (c == '"') {
      inString = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return deepest;
}

// The deepest a glTF's JSON may nest: far past any glTF's own structure and any DCC's extras.
constexpr size_t kMaxJsonDepth = 256;

// Throws InputError naming `name` for JSON nested deeper than kMaxJsonDepth, before any parser recurses.
void requireShallowJson(const std::string& json, const std::string& name) {
  if (const size_t depth = jsonDepth(json); depth > kMaxJsonDepth)
    throw InputError({name, 0}, "its JSON nests arrays and objects " + std::to_string(depth) +
                                    " deep; hairgen reads a glTF nested at most " +
                                    std::to_string(kMaxJsonDepth) + " deep");
}

void checkExternalUris(const std::string& json, const std::filesystem::path& baseDir,
                       const std::string& name) {
  const nlohmann::json doc = nlohmann::json::parse(json, nullptr, /*allow_exceptions=*/false);
  if (!doc.is_object()) return;  // tinygltf says what is wrong with it
  for (const char* list : {"buffers", "images"}) {
    if (!doc.contains(list) || !doc[list].is_array()) continue;
    for (const nlohmann::json& entry : doc[list]) {
      if (!entry.is_object() || !entry.contains("uri") || !entry["uri"].is_string()) continue;
      const std::string uri = entry["uri"].get<std::string>();
      if (uri.rfind("data:", 0) == 0) continue;
      const std::string path = decodeUri(uri);
      auto refuse = [&](const std::string& why) {
        return InputError({name, 0},
                          std::string(list) + " URI '" + oneLine(uri) + "' is refused: " + why +
                              "; hairgen reads only data: URIs and files in the glTF's own folder");
      };
      const size_t colon = path.find(':');
      if (colon != std::string::npos && colon > 0 && path.find('/') > colon)  // "file:", "http:"
        throw refuse("it names a scheme other than data:");
      const std::filesystem::path relative(path);
      if (relative.is_absolute()) throw refuse("it is an absolute path");
      for (const auto& part : relative)
        if (part == "..") throw refuse("it climbs out of the folder with '..'");
      if (std::string why = refusal(baseDir / relative, baseDir); !why.empty()) throw refuse(why);
    }
  }
}

struct ExternalFiles {
  std::filesystem::path baseDir;
  std::string name;

  tinygltf::FsCallbacks callbacks() {
    tinygltf::FsCallbacks fs{};
    fs.FileExists = [](const std::string& path, void* self) {
      return refusal(path, static_cast<ExternalFiles*>(self)->baseDir).empty();
    };
    fs.ExpandFilePath = [](const std::string& path, void*) { return path; };  // no ~ or $VAR expansion
    fs.ReadWholeFile = [](std::vector<unsigned char>* out, std::string* err, const std::string& path,
                          void* self) {
      const std::string why = refusal(path, static_cast<ExternalFiles*>(self)->baseDir);
      if (!why.empty()) {
        if (err) *err = path + ": " + why;
        return false;
      }
      try {
        *out = readFileBytes(path);
      } catch (const Error& e) {
        if (err) *err = e.what();
        return false;
      }
      return true;
    };
    fs.WriteWholeFile = [](std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
      if (err) *err = "hairgen does not write through tinygltf's file system";
      return false;
    };
    fs.user_data = this;
    return fs;
  }
};

bool skipImage(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int,
               void*) {
  return true;
}

}  // namespace

namespace {

// ------------------------------------------------------------------------------------------------ writing
//
// The file is written in one pass straight from the strands: the JSON first (every accessor's size
// follows from the counts), then each array into the binary chunk (or a .gltf's base64 data: URI),
// contiguous arrays as they lie and converted ones (unit normals, clamped colours, indices) through a
// small buffer, so no array is copied whole.

constexpr int kFloatComponent = TINYGLTF_COMPONENT_TYPE_FLOAT;
constexpr int kUintComponent = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
// Elements converted at a time on their way out: small next to any coupe, large enough that the
// stream's calls cost nothing.
constexpr size_t kChunkElements = size_t(1) << 16;
// _STRAND is a float vertex attribute (glTF allows no UNSIGNED_INT one): exact below 2^24 strands.
constexpr size_t kMaxStrands = size_t(1) << 24;

// Where the buffer's bytes go: the stream as they are (.glb), or as base64 (a .gltf's data: URI).
class Sink {
 public:
  Sink(std::ostream& out, bool base64) : out_(out), base64_(base64) {}

  void write(const void* data, size_t size) {
    const auto* bytes = static_cast<const uint8_t*>(data);
    if (!base64_) {
      out_.write(reinterpret_cast<const char*>(bytes), static_cast<std::streamsize>(size));
      return;
    }
    size_t i = 0;
    while (carried_ > 0 && carried_ < 3 && i < size) carry_[carried_++] = bytes[i++];
    if (carried_ == 3) {
      encode(carry_, 3);
      carried_ = 0;
    }
    for (; i + 3 <= size; i += 3) encode(bytes + i, 3);
    while (i < size) carry_[carried_++] = bytes[i++];
  }

  // base64's last group, padded with '='.
  void finish() {
    if (carried_ > 0) encode(carry_, carried_);
    carried_ = 0;
    out_.write(text_.data(), static_cast<std::streamsize>(text_.size()));
    text_.clear();
  }

 private:
  void encode(const uint8_t* in, int n) {
    static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    const uint32_t v = uint32_t(in[0]) << 16 | (n > 1 ? uint32_t(in[1]) << 8 : 0u) | (n > 2 ? in[2] : 0u);
    const char group[4] = {kAlphabet[v >> 18 & 63], kAlphabet[v >> 12 & 63],
                           n > 1 ? kAlphabet[v >> 6 & 63] : '=', n > 2 ? kAlphabet[v & 63] : '='};
    text_.append(group, 4);
    if (text_.size() >= 4 * kChunkElements) {
      out_.write(text_.data(), static_cast<std::streamsize>(text_.size()));
      text_.clear();
    }
  }

  std::ostream& out_;
  bool base64_;
  uint8_t carry_[3] = {};
  int carried_ = 0;
  std::string text_;
};

// Values pushed one at a time, written to the sink kChunkElements at a time.
template <typename T>
class Chunked {
 public:
  explicit Chunked(Sink& sink) : sink_(sink) { buffer_.reserve(kChunkElements); }
  void push(const T& value) {
    buffer_.push_back(value);
    if (buffer_.size() == kChunkElements) flush();
  }
  void flush() {
    sink_.write(buffer_.data(), buffer_.size() * sizeof(T));
    buffer_.clear();
  }

 private:
  Sink& sink_;
  std::vector<T> buffer_;
};

// One accessor and its tightly packed bufferView. Every component hairgen writes is 4 bytes.
struct Array {
  Array(int componentType_, int components_, size_t count_, int target_, std::function<void(Sink&)> write_)
      : componentType(componentType_),
        components(components_),
        count(count_),
        target(target_),
        write(std::move(write_)) {}
  int componentType;
  int components;
  size_t count;
  int target;  // 0 for per-strand data, which no vertex stage reads
  std::function<void(Sink&)> write;
  nlohmann::ordered_json min, max;  // POSITION's bounds; null elsewhere
  size_t bytes() const { return count * size_t(components) * 4; }
};

// An array as it lies in memory.
template <typename T, class A>
std::function<void(Sink&)> arrayBytes(const std::vector<T, A>& values) {
  return [&values](Sink& sink) { sink.write(values.data(), values.size() * sizeof(T)); };
}

// A per-vertex array converted on its way out: value(p) for each of `points` points.
template <typename T, class Value>
std::function<void(Sink&)> vertexValues(size_t points, Value value) {
  return [points, value](Sink& sink) {
    Chunked<T> out(sink);
    for (size_t p = 0; p < points; ++p) out.push(value(p));
    out.flush();
  };
}

const char* typeName(int components) {
  return components == 1 ? "SCALAR" : components == 2 ? "VEC2" : "VEC3";
}

// Writes strands of two points or more each (checked by encodeGltf); `dropped` one-point strands were
// left out of them.
void encodeLines(std::ostream& out, const Strands& s, bool binary, size_t dropped) {
  const size_t strands = s.strandCount(), points = s.pointCount();

  std::vector<Array> arrays;
  nlohmann::ordered_json attributes = nlohmann::ordered_json::object();
  nlohmann::ordered_json perStrand = nlohmann::ordered_json::object();
  auto add = [&](Array array) {
    arrays.push_back(std::move(array));
    return arrays.size() - 1;
  };
  auto vertex = [&](const char* name, int components, std::function<void(Sink&)> write) {
    attributes[name] =
        add(Array(kFloatComponent, components, points, TINYGLTF_TARGET_ARRAY_BUFFER, std::move(write)));
  };
  auto strand = [&](const char* name, int componentType, int components, std::function<void(Sink&)> write) {
    perStrand[name] = add(Array(componentType, components, strands, 0, std::move(write)));
  };

  // Indices: each strand's consecutive vertices joined, (v, v + 1).
  const size_t indices = add(
      Array(kUintComponent, 1, 2 * (points - strands), TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER, [&](Sink& sink) {
        Chunked<uint32_t> index(sink);
        for (size_t i = 0; i < strands; ++i)
          for (uint32_t v = s.firstPoint[i]; v + 1 < s.firstPoint[i + 1]; ++v) {
            index.push(v);
            index.push(v + 1);
          }
        index.flush();
      }));
  Array position(kFloatComponent, 3, points, TINYGLTF_TARGET_ARRAY_BUFFER, arrayBytes(s.points));
  glm::vec3 lo(std::numeric_limits<float>::max()), hi(std::numeric_limits<float>::lowest());
  for (const glm::vec3& p : s.points) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  position.min = {double(lo.x), double(lo.y), double(lo.z)};
  position.max = {double(hi.x), double(hi.y), double(hi.z)};
  attributes["POSITION"] = add(std::move(position));
  if (!s.normals.empty())
    // glTF requires unit normals; ones already unit to float precision are kept bit for bit.
    vertex("NORMAL", 3, vertexValues<glm::vec3>(points, [&](size_t p) {
             const glm::vec3 n = s.normals[p];
             const float length = glm::length(n);
             if (!(length > 0.0f)) return glm::vec3(0.0f, 1.0f, 0.0f);
             return std::abs(length - 1.0f) > 1e-5f ? n / length : n;
           }));
  if (!s.colors.empty()) {
    // glTF colours lie in [0, 1]. A shaded coupe's per-strand ambient coefficient may pass 1: COLOR_0
    // holds the colours clamped, and _COLOR the values themselves, which a reader prefers.
    vertex("COLOR_0", 3,
           vertexValues<glm::vec3>(points, [&](size_t p) { return glm::clamp(s.colors[p], 0.0f, 1.0f); }));
    bool outside = false;
    for (size_t p = 0; p < points && !outside; ++p)
      outside = glm::clamp(s.colors[p], 0.0f, 1.0f) != s.colors[p];
    if (outside) vertex("_COLOR", 3, arrayBytes(s.colors));
  }
  if (!s.transparency.empty()) vertex("_TRANSPARENCY", 1, arrayBytes(s.transparency));
  if (!s.tangents.empty()) vertex("_TANGENT", 3, arrayBytes(s.tangents));
  // Every vertex has a width, the default where the strands carry none, so an importer that reads
  // _THICKNESS never sees zero; asset.extras.thicknessFromDefault tells hairgen to drop it again.
  if (s.thickness.empty())
    vertex("_THICKNESS", 1, vertexValues<float>(points, [&](size_t) { return s.defaultThickness; }));
  else
    vertex("_THICKNESS", 1, arrayBytes(s.thickness));
  // Each vertex's strand: the index of its strand's entry in the per-strand accessors.
  vertex("_STRAND", 1, [&](Sink& sink) {
    Chunked<float> strandOf(sink);
    for (size_t i = 0; i < strands; ++i)
      for (uint32_t p = s.firstPoint[i]; p < s.firstPoint[i + 1]; ++p) strandOf.push(static_cast<float>(i));
    strandOf.flush();
  });
  // Per-strand data once per strand: accessors no vertex stage reads, named in the primitive's extras.
  // Not vertex attributes, so ids are UNSIGNED_INT and exact whatever their size.
  if (!s.strandId.empty()) strand("_STRAND_ID", kUintComponent, 1, arrayBytes(s.strandId));
  if (!s.rootUv.empty()) strand("_ROOT_UV", kFloatComponent, 2, arrayBytes(s.rootUv));
  if (!s.guideIds.empty()) strand("_GUIDE_IDS", kUintComponent, 3, arrayBytes(s.guideIds));
  if (!s.guideWeights.empty()) strand("_GUIDE_WEIGHTS", kFloatComponent, 3, arrayBytes(s.guideWeights));
  if (!s.rootTriangle.empty()) strand("_ROOT_TRIANGLE", kUintComponent, 1, arrayBytes(s.rootTriangle));
  if (!s.rootBary.empty()) strand("_ROOT_BARY", kFloatComponent, 3, arrayBytes(s.rootBary));

  nlohmann::ordered_json accessors = nlohmann::ordered_json::array(), views = nlohmann::ordered_json::array();
  size_t offset = 0;
  for (size_t i = 0; i < arrays.size(); ++i) {
    const Array& a = arrays[i];
    nlohmann::ordered_json view = {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", a.bytes()}};
    if (a.target) view["target"] = a.target;
    views.push_back(std::move(view));
    nlohmann::ordered_json accessor = {{"bufferView", i},
                                       {"componentType", a.componentType},
                                       {"count", a.count},
                                       {"type", typeName(a.components)}};
    if (!a.min.is_null()) {
      accessor["min"] = a.min;
      accessor["max"] = a.max;
    }
    accessors.push_back(std::move(accessor));
    offset += a.bytes();
  }
  const size_t bufferBytes = offset;

  // The hair's colour as the material's, so a DCC shows it: the header's default colour, or white
  // when COLOR_0 holds the colours (glTF multiplies the two).
  const glm::vec3 base = s.colors.empty() ? glm::clamp(s.defaultColor, 0.0f, 1.0f) : glm::vec3(1.0f);
  // Text from the strands' files goes through printableText: JSON must be UTF-8 and a control
  // character has no business in it.
  const auto text = [](const std::string& value) { return printableText(value); };
  const Provenance& p = s.provenance;
  nlohmann::ordered_json extras;
  extras["producer"] = text(p.producer.empty() ? std::string("hairgen " HAIRGEN_VERSION) : p.producer);
  extras["strands"] = strands;
  extras["points"] = points;
  extras["stage"] = text(p.stage);
  extras["seed"] = std::to_string(p.seed);
  extras["configDigest"] = text(p.configDigest);
  extras["defaultThickness"] = double(s.defaultThickness);
  extras["defaultTransparency"] = double(s.defaultTransparency);
  extras["defaultColor"] = {double(s.defaultColor.x), double(s.defaultColor.y), double(s.defaultColor.z)};
  // glTF's own units are metres with +y up; a file whose source did not say is not claimed to be.
  extras["units"] = p.metres ? "metres" : "unknown: the source file's own, not metres";
  extras["upAxis"] = p.yUp ? "+y" : "unknown: the source file's own";
  extras["thickness"] = "_THICKNESS is each vertex's diameter, in the units above";
  extras["thicknessFromDefault"] = s.thickness.empty();
  if (!p.source.empty()) extras["source"] = text(p.source);
  if (!p.sourceInfo.empty()) extras["sourceInfo"] = text(p.sourceInfo);
  if (!p.conversion.empty()) extras["conversion"] = text(p.conversion);
  if (dropped > 0) extras["onePointStrandsDropped"] = dropped;

  nlohmann::ordered_json primitive = {
      {"attributes", attributes}, {"indices", indices}, {"material", 0}, {"mode", TINYGLTF_MODE_LINE}};
  primitive["extras"] = {
      {"strandAttribute", "_STRAND"},
      {"perStrand", perStrand},
      {"note", "_STRAND is each vertex's strand: the index of its entry in the perStrand accessors"}};
  nlohmann::ordered_json doc;
  doc["asset"] = {{"version", "2.0"}, {"generator", "hairgen " HAIRGEN_VERSION}, {"extras", extras}};
  doc["scene"] = 0;
  doc["scenes"] = {{{"nodes", {0}}}};
  doc["nodes"] = {{{"name", "hair"}, {"mesh", 0}}};
  doc["meshes"] = {{{"name", "hair"}, {"primitives", {primitive}}}};
  doc["materials"] = {{{"name", "hair"},
                       {"pbrMetallicRoughness",
                        {{"baseColorFactor", {double(base.x), double(base.y), double(base.z), 1.0}},
                         {"metallicFactor", 0.0},
                         {"roughnessFactor", 0.6}}},
                       {"doubleSided", true}}};
  doc["accessors"] = std::move(accessors);
  doc["bufferViews"] = std::move(views);
  // The data: URI's base64 is streamed in place of this mark; "buffers" comes last, so the mark's last
  // occurrence is the buffer's whatever text the extras hold.
  constexpr std::string_view kMark = "@hairgen-buffer@";
  doc["buffers"] = {{{"byteLength", bufferBytes}}};
  if (!binary) doc["buffers"][0]["uri"] = "data:application/octet-stream;base64," + std::string(kMark);
  // Bytes that are not UTF-8 were made printable above; replace keeps dump() from throwing on any left.
  std::string json = doc.dump(binary ? -1 : 2, ' ', false, nlohmann::ordered_json::error_handler_t::replace);

  if (binary) {
    while (json.size() % 4) json += ' ';
    const uint64_t total = 12 + 8 + json.size() + 8 + bufferBytes;
    if (total > UINT32_MAX)
      throw InputError("the coupe needs " + std::to_string(total) +
                       " bytes of .glb, past its 4 GiB limit; use .hair");
    auto word = [&](uint32_t v) { out.write(reinterpret_cast<const char*>(&v), 4); };
    out.write("glTF", 4);
    word(2);
    word(static_cast<uint32_t>(total));
    word(static_cast<uint32_t>(json.size()));
    word(0x4E4F534Au);  // "JSON"
    out.write(json.data(), static_cast<std::streamsize>(json.size()));
    word(static_cast<uint32_t>(bufferBytes));
    word(0x004E4942u);  // "BIN\0"
    Sink sink(out, false);
    for (const Array& a : arrays) a.write(sink);
  } else {
    const size_t mark = json.rfind(kMark);
    out.write(json.data(), static_cast<std::streamsize>(mark));
    Sink sink(out, true);
    for (const Array& a : arrays) a.write(sink);
    sink.finish();
    out.write(json.data() + mark + kMark.size(),
              static_cast<std::streamsize>(json.size() - mark - kMark.size()));
    out.put('\n');
  }
}

}  // namespace

void encodeGltf(std::ostream& out, const Strands& s, bool binary, size_t* droppedStrands) {
  s.validate("strands to write");
  if (s.pointCount() == 0) throw InputError("no points to write; a glTF accessor cannot be empty");
  if (s.pointCount() > UINT32_MAX - 1) throw InputError("too many points for uint32 glTF indices");
  const size_t dropped = onePointStrandCount(s), strands = s.strandCount() - dropped;
  if (strands == 0)
    throw InputError("no strand has two points; a LINES primitive needs at least one segment");
  if (strands >= kMaxStrands)
    throw InputError(
        std::to_string(strands) +
        " strands are too many for glTF's float _STRAND attribute (exact below 16777216); use .hair");
  if (droppedStrands) *droppedStrands = dropped;
  if (dropped > 0)
    encodeLines(out, withoutOnePointStrands(s), binary, dropped);
  else
    encodeLines(out, s, binary, 0);
}

std::vector<uint8_t> encodeGltf(const Strands& strands, bool binary, size_t* droppedStrands) {
  std::ostringstream out;
  encodeGltf(out, strands, binary, droppedStrands);
  const std::string bytes = std::move(out).str();
  return std::vector<uint8_t>(bytes.begin(), bytes.end());
}

Strands decodeGltf(const uint8_t* data, size_t size, const std::string& name,
                   const std::filesystem::path& baseDir) {
  if (size > UINT32_MAX) throw InputError({name, 0}, "file larger than 4 GiB; glTF cannot address it");
  const bool binary = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
  const std::string json = jsonOf(data, size, binary);
  requireShallowJson(json, name);
  checkExternalUris(json, baseDir, name);
  ExternalFiles external{baseDir, name};
  tinygltf::TinyGLTF loader;
  loader.SetFsCallbacks(external.callbacks());
  loader.SetImageLoader(skipImage, nullptr);  // hair has no textures; no image decoder sees the bytes
  tinygltf::Model m;
  std::string err, warn;
  const bool ok = binary ? loader.LoadBinaryFromMemory(&m, &err, &warn, data, static_cast<unsigned>(size),
                                                       baseDir.string())
                         : loader.LoadASCIIFromString(&m, &err, &warn, reinterpret_cast<const char*>(data),
                                                      static_cast<unsigned>(size), baseDir.string());
  if (!ok) throw InputError({name, 0}, "not a readable glTF file: " + oneLine(err.empty() ? warn : err));

  Strands s;
  s.provenance.producer = stringOr(m.asset.extras, "producer");
  s.provenance.stage = stringOr(m.asset.extras, "stage");
  s.provenance.configDigest = stringOr(m.asset.extras, "configDigest");
  s.provenance.source = stringOr(m.asset.extras, "source");
  s.provenance.sourceInfo = stringOr(m.asset.extras, "sourceInfo");
  s.provenance.conversion = stringOr(m.asset.extras, "conversion");
  s.provenance.metres = stringOr(m.asset.extras, "units").rfind("unknown", 0) != 0;  // glTF's own: metres
  s.provenance.yUp = stringOr(m.asset.extras, "upAxis").rfind("unknown", 0) != 0;    // and +y up
  if (s.provenance.producer.empty())  // made elsewhere: what it says of itself
    s.provenance.sourceInfo =
        oneLine(m.asset.generator + (m.asset.copyright.empty() ? "" : "; " + m.asset.copyright));
  std::string seed = stringOr(m.asset.extras, "seed");
  if (!seed.empty()) s.provenance.seed = std::strtoull(seed.c_str(), nullptr, 10);
  s.defaultThickness = static_cast<float>(numberOr(m.asset.extras, "defaultThickness", s.defaultThickness));
  s.defaultTransparency =
      static_cast<float>(numberOr(m.asset.extras, "defaultTransparency", s.defaultTransparency));
  if (m.asset.extras.IsObject() && m.asset.extras.Has("defaultColor")) {
    const Value& c = m.asset.extras.Get("defaultColor");
    if (c.IsArray() && c.ArrayLen() == 3)
      for (int i = 0; i < 3; ++i)
        s.defaultColor[i] = static_cast<float>(c.Get(i).IsNumber() ? c.Get(i).GetNumberAsDouble() : 0.0);
  }

  bool found = false;
  for (const tinygltf::Mesh& mesh : m.meshes) {
    for (const tinygltf::Primitive& prim : mesh.primitives) {
      if (prim.mode != TINYGLTF_MODE_LINE) continue;
      if (found)
        throw InputError({name, 0},
                         "more than one LINES primitive; hairgen reads one hair primitive per file");
      found = true;
      auto position = prim.attributes.find("POSITION");
      if (position == prim.attributes.end())
        throw InputError({name, 0}, "the LINES primitive has no POSITION");
      AccessorView pos(m, position->second, "POSITION", name);
      pos.expect(TINYGLTF_COMPONENT_TYPE_FLOAT, 3);
      const size_t n = pos.count();
      if (prim.indices < 0)
        throw InputError({name, 0}, "the LINES primitive has no indices; hairgen needs indexed strands");
      AccessorView idx(m, prim.indices, "indices", name);
      if (idx.componentType() != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT &&
          idx.componentType() != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
          idx.componentType() != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE)
        throw InputError({name, 0}, "indices must be unsigned integers");
      if (idx.count() % 2) throw InputError({name, 0}, "LINES indices come in pairs; found an odd count");
      std::vector<bool> joinsNext(n, false);
      for (size_t i = 0; i < idx.count(); i += 2) {
        uint32_t a = idx.u(i, 0), b = idx.u(i + 1, 0);
        if (a >= n || b >= n)
          throw InputError({name, 0}, "index " + std::to_string(std::max(a, b)) + " is past the " +
                                          std::to_string(n) + " vertices");
        if (b != a + 1)
          throw InputError(
              {name, 0},
              "segment (" + std::to_string(a) + ", " + std::to_string(b) +
                  ") does not join consecutive vertices; hairgen reads strands stored as runs of vertices");
        joinsNext[a] = true;
      }
      s.points.resize(n);
      for (size_t i = 0; i < n; ++i) s.points[i] = {pos.f(i, 0), pos.f(i, 1), pos.f(i, 2)};
      s.firstPoint.assign(1, 0);
      for (size_t i = 1; i < n; ++i)
        if (!joinsNext[i - 1]) s.firstPoint.push_back(static_cast<uint32_t>(i));
      s.firstPoint.push_back(static_cast<uint32_t>(n));

      auto attribute = [&](const char* key) -> std::optional<AccessorView> {
        auto it = prim.attributes.find(key);
        if (it == prim.attributes.end()) return std::nullopt;
        AccessorView view(m, it->second, key, name);
        if (view.count() != n)
          throw InputError({name, 0}, std::string(key) + " has " + std::to_string(view.count()) +
                                          " entries for " + std::to_string(n) + " vertices");
        return view;
      };
      auto vec3s = [&](const char* key, auto& out) {
        if (auto v = attribute(key)) {
          v->expect(TINYGLTF_COMPONENT_TYPE_FLOAT, 3);
          out.resize(n);
          for (size_t i = 0; i < n; ++i) out[i] = {v->f(i, 0), v->f(i, 1), v->f(i, 2)};
        }
      };
      vec3s("NORMAL", s.normals);
      vec3s("_TANGENT", s.tangents);
      if (auto v = attribute(prim.attributes.count("_COLOR") ? "_COLOR" : "COLOR_0")) {
        v->expect(TINYGLTF_COMPONENT_TYPE_FLOAT, 3);
        s.colors.resize(n);
        for (size_t i = 0; i < n; ++i) s.colors[i] = {v->f(i, 0), v->f(i, 1), v->f(i, 2)};
      }
      if (auto v = attribute("_TRANSPARENCY")) {
        v->expect(TINYGLTF_COMPONENT_TYPE_FLOAT, 1);
        s.transparency.resize(n);
        for (size_t i = 0; i < n; ++i) s.transparency[i] = v->f(i, 0);
      }
      if (auto v = attribute("_THICKNESS")) {
        v->expect(TINYGLTF_COMPONENT_TYPE_FLOAT, 1);
        s.thickness.resize(n);
        for (size_t i = 0; i < n; ++i) s.thickness[i] = v->f(i, 0);
      }
      // Per-strand values: an accessor of one entry per strand named in the primitive's extras
      // (perStrand, ids UNSIGNED_INT), or in files written before it a FLOAT attribute repeated on
      // every vertex, whose root's copy is the strand's value.
      const size_t strands = s.strandCount();
      const Value* named =
          prim.extras.IsObject() && prim.extras.Has("perStrand") && prim.extras.Get("perStrand").IsObject()
              ? &prim.extras.Get("perStrand")
              : nullptr;
      struct PerStrand {
        AccessorView view;
        bool onVertices;
      };
      auto perStrand = [&](const char* key, int components) -> std::optional<PerStrand> {
        if (named && named->Has(key)) {
          const Value& index = named->Get(key);
          if (!index.IsInt())
            throw InputError({name, 0}, std::string("perStrand.") + key + " is not an accessor index");
          AccessorView view(m, index.Get<int>(), key, name);
          if (view.count() != strands)
            throw InputError({name, 0}, std::string(key) + " has " + std::to_string(view.count()) +
                                            " entries for " + std::to_string(strands) + " strands");
          if (view.componentType() != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
            view.expect(TINYGLTF_COMPONENT_TYPE_FLOAT, components);
          view.expect(view.componentType(), components);
          return PerStrand{view, false};
        }
        if (auto view = attribute(key)) {
          view->expect(TINYGLTF_COMPONENT_TYPE_FLOAT, components);
          return PerStrand{*view, true};
        }
        return std::nullopt;
      };
      // Strand i's entry: the accessor's i-th, or its root vertex's.
      auto entry = [&](const PerStrand& v, size_t i) -> size_t { return v.onVertices ? s.firstPoint[i] : i; };
      auto id = [&](const PerStrand& v, size_t i, int c, const char* key) {
        return v.view.componentType() == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT
                   ? v.view.u(entry(v, i), c)
                   : idFrom(v.view.f(entry(v, i), c), key, name);
      };
      auto floats = [&](const PerStrand& v, size_t i, int c) {
        if (v.view.componentType() != TINYGLTF_COMPONENT_TYPE_FLOAT)
          throw InputError({name, 0}, "a per-strand value of integers where floats belong");
        return v.view.f(entry(v, i), c);
      };
      if (auto v = perStrand("_STRAND_ID", 1)) {
        s.strandId.resize(strands);
        for (size_t i = 0; i < strands; ++i) s.strandId[i] = id(*v, i, 0, "_STRAND_ID");
      }
      if (auto v = perStrand("_ROOT_TRIANGLE", 1)) {
        s.rootTriangle.resize(strands);
        for (size_t i = 0; i < strands; ++i) s.rootTriangle[i] = id(*v, i, 0, "_ROOT_TRIANGLE");
      }
      if (auto v = perStrand("_GUIDE_IDS", 3)) {
        s.guideIds.resize(strands);
        for (size_t i = 0; i < strands; ++i)
          for (int c = 0; c < 3; ++c) s.guideIds[i][c] = id(*v, i, c, "_GUIDE_IDS");
      }
      if (auto v = perStrand("_ROOT_UV", 2)) {
        s.rootUv.resize(strands);
        for (size_t i = 0; i < strands; ++i) s.rootUv[i] = {floats(*v, i, 0), floats(*v, i, 1)};
      }
      auto strandVec3 = [&](const char* key, std::vector<glm::vec3>& out) {
        if (auto v = perStrand(key, 3)) {
          out.resize(strands);
          for (size_t i = 0; i < strands; ++i)
            out[i] = {floats(*v, i, 0), floats(*v, i, 1), floats(*v, i, 2)};
        }
      };
      strandVec3("_GUIDE_WEIGHTS", s.guideWeights);
      strandVec3("_ROOT_BARY", s.rootBary);
    }
  }
  if (!found) throw InputError({name, 0}, "no mesh primitive in mode LINES: the file holds no hair strands");
  if (m.asset.extras.IsObject() && m.asset.extras.Has("thicknessFromDefault") &&
      m.asset.extras.Get("thicknessFromDefault").IsBool() &&
      m.asset.extras.Get("thicknessFromDefault").Get<bool>())
    s.thickness.clear();
  s.validate(name);
  return s;
}

Strands readGltf(const std::filesystem::path& file) {
  std::vector<uint8_t> bytes = readFileBytes(file);
  // "x.gltf" lies in the working directory: its folder is ".", where an empty one would mean none.
  const std::filesystem::path folder = file.has_parent_path() ? file.parent_path() : ".";
  return decodeGltf(bytes.data(), bytes.size(), file.string(), folder);
}

void writeGltf(const std::filesystem::path& file, const Strands& strands, bool binary,
               size_t* droppedStrands) {
  AtomicFile out(file);
  namingFile(file.string(), [&] { encodeGltf(out.stream(), strands, binary, droppedStrands); });
  out.commit();
}

}  // namespace hairgen
