#include "libcore/io/gltf_io.h"

#include <cctype>
#include <cmath>
#include <cstring>
#include <optional>
#include <sstream>

#include <tiny_gltf.h>
#include <nlohmann/json.hpp>

#include "libcore/util/checked.h"
#include "libcore/util/error.h"
#include "libcore/util/file_util.h"
#include "libcore/util/text.h"

namespace hairgen {
namespace {

using tinygltf::Value;

struct Builder {
  tinygltf::Model model;
  std::vector<unsigned char> buffer;

  // Appends a tightly packed accessor; returns its index.
  template <typename T, class A>
  int add(const std::vector<T, A>& values, int componentType, int type, int target, bool minMax = false) {
    while (buffer.size() % 4) buffer.push_back(0);
    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = buffer.size();
    view.byteLength = values.size() * sizeof(T);
    view.target = target;
    const unsigned char* bytes = reinterpret_cast<const unsigned char*>(values.data());
    buffer.insert(buffer.end(), bytes, bytes + view.byteLength);
    model.bufferViews.push_back(view);

    tinygltf::Accessor accessor;
    accessor.bufferView = static_cast<int>(model.bufferViews.size() - 1);
    accessor.componentType = componentType;
    accessor.type = type;
    accessor.count = values.size() * sizeof(T) / tinygltf::GetComponentSizeInBytes(componentType) /
                     tinygltf::GetNumComponentsInType(type);
    if (minMax) {
      int n = tinygltf::GetNumComponentsInType(type);
      const float* f = reinterpret_cast<const float*>(values.data());
      accessor.minValues.assign(n, 1e300);
      accessor.maxValues.assign(n, -1e300);
      for (size_t i = 0; i < accessor.count; ++i)
        for (int c = 0; c < n; ++c) {
          accessor.minValues[c] = std::min<double>(accessor.minValues[c], f[i * n + c]);
          accessor.maxValues[c] = std::max<double>(accessor.maxValues[c], f[i * n + c]);
        }
    }
    model.accessors.push_back(accessor);
    return static_cast<int>(model.accessors.size() - 1);
  }
};

template <typename T>
std::vector<T> perVertex(const Strands& s, const std::vector<T>& perStrand) {
  std::vector<T> out(s.pointCount());
  for (size_t i = 0; i < s.strandCount(); ++i)
    for (uint32_t p = s.firstPoint[i]; p < s.firstPoint[i + 1]; ++p) out[p] = perStrand[i];
  return out;
}

// glTF forbids UNSIGNED_INT vertex attributes, so integer ids travel as floats: exact below 2^24.
constexpr uint32_t kMaxExactId = 1u << 24;

std::vector<float> asFloat(const std::vector<uint32_t>& ids, const char* what) {
  std::vector<float> out(ids.size());
  for (size_t i = 0; i < ids.size(); ++i) {
    if (ids[i] >= kMaxExactId)
      throw InputError(std::string(what) + " " + std::to_string(ids[i]) +
                       " is too large for a glTF float attribute (exact below 16777216); use .hair");
    out[i] = static_cast<float>(ids[i]);
  }
  return out;
}

std::vector<glm::vec3> asFloat(const std::vector<glm::uvec3>& ids, const char* what) {
  std::vector<glm::vec3> out(ids.size());
  for (size_t i = 0; i < ids.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      if (ids[i][c] >= kMaxExactId)
        throw InputError(std::string(what) + " " + std::to_string(ids[i][c]) +
                         " is too large for a glTF float attribute (exact below 16777216); use .hair");
      out[i][c] = static_cast<float>(ids[i][c]);
    }
  return out;
}

// The id stored as a float at `value`, checked to be a whole number in range.
uint32_t idFrom(float value, const std::string& what, const std::string& name) {
  if (!(value >= 0.0f) || value >= float(kMaxExactId) || value != std::floor(value))
    throw InputError({name, 0},
                     what + " holds " + std::to_string(value) + ", not a whole number in [0, 2^24)");
  return static_cast<uint32_t>(value);
}

Value vec3Value(const glm::vec3& v) {
  return Value(Value::Array{Value(double(v.x)), Value(double(v.y)), Value(double(v.z))});
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

std::vector<uint8_t> encodeGltf(const Strands& s, bool binary) {
  s.validate("strands to write");
  if (s.pointCount() == 0) throw InputError("no points to write; a glTF accessor cannot be empty");
  if (s.pointCount() > UINT32_MAX - 1) throw InputError("too many points for uint32 glTF indices");
  Builder b;
  std::vector<uint32_t> indices;
  for (size_t i = 0; i < s.strandCount(); ++i)
    for (uint32_t p = s.firstPoint[i]; p + 1 < s.firstPoint[i + 1]; ++p) {
      indices.push_back(p);
      indices.push_back(p + 1);
    }
  if (indices.empty())
    throw InputError("no strand has two points; a LINES primitive needs at least one segment");

  tinygltf::Primitive prim;
  prim.mode = TINYGLTF_MODE_LINE;
  prim.indices = b.add(indices, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR,
                       TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
  constexpr int kFloat = TINYGLTF_COMPONENT_TYPE_FLOAT;
  constexpr int kArray = TINYGLTF_TARGET_ARRAY_BUFFER;
  prim.attributes["POSITION"] = b.add(s.points, kFloat, TINYGLTF_TYPE_VEC3, kArray, true);
  if (!s.normals.empty()) {
    std::vector<glm::vec3> unit(s.normals);
    // glTF requires unit normals; ones already unit to float precision are kept bit for bit.
    for (glm::vec3& n : unit) {
      float length = glm::length(n);
      if (!(length > 0.0f))
        n = glm::vec3(0.0f, 1.0f, 0.0f);
      else if (std::abs(length - 1.0f) > 1e-5f)
        n /= length;
    }
    prim.attributes["NORMAL"] = b.add(unit, kFloat, TINYGLTF_TYPE_VEC3, kArray);
  }
  if (!s.colors.empty()) {
    // glTF colours lie in [0, 1]. A shaded coupe's per-strand ambient coefficient may pass 1: COLOR_0
    // holds the colours clamped, and _COLOR the values themselves, which a reader prefers.
    std::vector<glm::vec3> clamped(s.colors);
    bool outside = false;
    for (glm::vec3& c : clamped) {
      glm::vec3 in = glm::clamp(c, 0.0f, 1.0f);
      outside = outside || in != c;
      c = in;
    }
    prim.attributes["COLOR_0"] = b.add(clamped, kFloat, TINYGLTF_TYPE_VEC3, kArray);
    if (outside) prim.attributes["_COLOR"] = b.add(s.colors, kFloat, TINYGLTF_TYPE_VEC3, kArray);
  }
  if (!s.transparency.empty())
    prim.attributes["_TRANSPARENCY"] = b.add(s.transparency, kFloat, TINYGLTF_TYPE_SCALAR, kArray);
  if (!s.tangents.empty())
    prim.attributes["_TANGENT"] = b.add(s.tangents, kFloat, TINYGLTF_TYPE_VEC3, kArray);
  // Every vertex has a width, the default where the strands carry none, so an importer that reads
  // _THICKNESS never sees zero; asset.extras.thicknessFromDefault tells hairgen to drop it again.
  prim.attributes["_THICKNESS"] =
      b.add(s.thickness.empty() ? std::vector<float>(s.pointCount(), s.defaultThickness) : s.thickness,
            kFloat, TINYGLTF_TYPE_SCALAR, kArray);
  if (!s.strandId.empty())
    prim.attributes["_STRAND_ID"] =
        b.add(asFloat(perVertex(s, s.strandId), "strand id"), kFloat, TINYGLTF_TYPE_SCALAR, kArray);
  if (!s.rootUv.empty())
    prim.attributes["_ROOT_UV"] = b.add(perVertex(s, s.rootUv), kFloat, TINYGLTF_TYPE_VEC2, kArray);
  if (!s.guideIds.empty())
    prim.attributes["_GUIDE_IDS"] =
        b.add(asFloat(perVertex(s, s.guideIds), "guide id"), kFloat, TINYGLTF_TYPE_VEC3, kArray);
  if (!s.guideWeights.empty())
    prim.attributes["_GUIDE_WEIGHTS"] =
        b.add(perVertex(s, s.guideWeights), kFloat, TINYGLTF_TYPE_VEC3, kArray);
  if (!s.rootTriangle.empty())
    prim.attributes["_ROOT_TRIANGLE"] =
        b.add(asFloat(perVertex(s, s.rootTriangle), "root triangle"), kFloat, TINYGLTF_TYPE_SCALAR, kArray);
  if (!s.rootBary.empty())
    prim.attributes["_ROOT_BARY"] = b.add(perVertex(s, s.rootBary), kFloat, TINYGLTF_TYPE_VEC3, kArray);

  tinygltf::Model& m = b.model;
  // The hair's colour as the material's, so a DCC shows it: the header's default colour, or white
  // when COLOR_0 holds the colours (glTF multiplies the two).
  tinygltf::Material material;
  material.name = "hair";
  const glm::vec3 base = s.colors.empty() ? glm::clamp(s.defaultColor, 0.0f, 1.0f) : glm::vec3(1.0f);
  material.pbrMetallicRoughness.baseColorFactor = {double(base.x), double(base.y), double(base.z), 1.0};
  material.pbrMetallicRoughness.metallicFactor = 0.0;
  material.pbrMetallicRoughness.roughnessFactor = 0.6;
  material.doubleSided = true;
  m.materials.push_back(material);
  prim.material = 0;
  tinygltf::Buffer buffer;
  buffer.data = std::move(b.buffer);
  m.buffers.push_back(std::move(buffer));
  tinygltf::Mesh mesh;
  mesh.name = "hair";
  mesh.primitives.push_back(prim);
  m.meshes.push_back(mesh);
  tinygltf::Node node;
  node.name = "hair";
  node.mesh = 0;
  m.nodes.push_back(node);
  tinygltf::Scene scene;
  scene.nodes.push_back(0);
  m.scenes.push_back(scene);
  m.defaultScene = 0;
  m.asset.version = "2.0";
  m.asset.generator = "hairgen " HAIRGEN_VERSION;
  // Text from the strands' files goes through printableText: JSON must be UTF-8 (tinygltf's writer throws
  // on anything else) and a control character has no business in it.
  const auto text = [](const std::string& value) { return Value(printableText(value)); };
  Value::Object extras;
  extras["producer"] =
      text(s.provenance.producer.empty() ? std::string("hairgen " HAIRGEN_VERSION) : s.provenance.producer);
  extras["strands"] = Value(static_cast<double>(s.strandCount()));
  extras["points"] = Value(static_cast<double>(s.pointCount()));
  extras["stage"] = text(s.provenance.stage);
  extras["seed"] = Value(std::to_string(s.provenance.seed));
  extras["configDigest"] = text(s.provenance.configDigest);
  extras["defaultThickness"] = Value(static_cast<double>(s.defaultThickness));
  extras["defaultTransparency"] = Value(static_cast<double>(s.defaultTransparency));
  extras["defaultColor"] = vec3Value(s.defaultColor);
  // glTF's own units are metres with +y up; a file whose source did not say is not claimed to be.
  const Provenance& p = s.provenance;
  extras["units"] = Value(std::string(p.metres ? "metres" : "unknown: the source file's own, not metres"));
  extras["upAxis"] = Value(std::string(p.yUp ? "+y" : "unknown: the source file's own"));
  extras["thickness"] = Value(std::string("_THICKNESS is each vertex's diameter, in the units above"));
  extras["thicknessFromDefault"] = Value(s.thickness.empty());
  if (!p.source.empty()) extras["source"] = text(p.source);
  if (!p.sourceInfo.empty()) extras["sourceInfo"] = text(p.sourceInfo);
  if (!p.conversion.empty()) extras["conversion"] = text(p.conversion);
  m.asset.extras = Value(std::move(extras));

  tinygltf::TinyGLTF writer;
  std::ostringstream out;
  if (!writer.WriteGltfSceneToStream(&m, out, /*prettyPrint=*/!binary, binary))
    throw IoError("tinygltf could not serialise the model");
  std::string bytes = out.str();
  return std::vector<uint8_t>(bytes.begin(), bytes.end());
}

Strands decodeGltf(const uint8_t* data, size_t size, const std::string& name,
                   const std::filesystem::path& baseDir) {
  if (size > UINT32_MAX) throw InputError({name, 0}, "file larger than 4 GiB; glTF cannot address it");
  const bool binary = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
  checkExternalUris(jsonOf(data, size, binary), baseDir, name);
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
      // Per-strand values are stored on every vertex; the root's copy is the strand's value.
      const size_t strands = s.strandCount();
      auto root = [&](size_t strand) { return s.firstPoint[strand]; };
      if (auto v = attribute("_STRAND_ID")) {
        v->expect(TINYGLTF_COMPONENT_TYPE_FLOAT, 1);
        s.strandId.resize(strands);
        for (size_t i = 0; i < strands; ++i) s.strandId[i] = idFrom(v->f(root(i), 0), "_STRAND_ID", name);
      }
      if (auto v = attribute("_ROOT_TRIANGLE")) {
        v->expect(TINYGLTF_COMPONENT_TYPE_FLOAT, 1);
        s.rootTriangle.resize(strands);
        for (size_t i = 0; i < strands; ++i)
          s.rootTriangle[i] = idFrom(v->f(root(i), 0), "_ROOT_TRIANGLE", name);
      }
      if (auto v = attribute("_GUIDE_IDS")) {
        v->expect(TINYGLTF_COMPONENT_TYPE_FLOAT, 3);
        s.guideIds.resize(strands);
        for (size_t i = 0; i < strands; ++i)
          for (int c = 0; c < 3; ++c) s.guideIds[i][c] = idFrom(v->f(root(i), c), "_GUIDE_IDS", name);
      }
      if (auto v = attribute("_ROOT_UV")) {
        v->expect(TINYGLTF_COMPONENT_TYPE_FLOAT, 2);
        s.rootUv.resize(strands);
        for (size_t i = 0; i < strands; ++i) s.rootUv[i] = {v->f(root(i), 0), v->f(root(i), 1)};
      }
      auto strandVec3 = [&](const char* key, std::vector<glm::vec3>& out) {
        if (auto v = attribute(key)) {
          v->expect(TINYGLTF_COMPONENT_TYPE_FLOAT, 3);
          out.resize(strands);
          for (size_t i = 0; i < strands; ++i)
            out[i] = {v->f(root(i), 0), v->f(root(i), 1), v->f(root(i), 2)};
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

void writeGltf(const std::filesystem::path& file, const Strands& strands, bool binary) {
  std::vector<uint8_t> bytes = namingFile(file.string(), [&] { return encodeGltf(strands, binary); });
  writeFileAtomic(file, bytes.data(), bytes.size());
}

}  // namespace hairgen
