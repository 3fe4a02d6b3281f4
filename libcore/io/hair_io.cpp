#include "libcore/io/hair_io.h"

#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>

#include <zlib.h>

#include "libcore/util/error.h"
#include "libcore/util/file_util.h"
#include "libcore/util/text.h"

namespace hairgen {
namespace {

constexpr uint32_t kSegments = 1, kPoints = 2, kThickness = 4, kTransparency = 8, kColor = 16;
constexpr size_t kHeaderSize = 128, kInfoSize = 88;
constexpr uint32_t kBlockVersion = 1;

class Writer {
 public:
  void bytes(const void* p, size_t n) {
    const uint8_t* b = static_cast<const uint8_t*>(p);
    out.insert(out.end(), b, b + n);
  }
  void u16(uint16_t v) {
    uint8_t b[2] = {uint8_t(v), uint8_t(v >> 8)};
    bytes(b, 2);
  }
  void u32(uint32_t v) {
    uint8_t b[4];
    for (int i = 0; i < 4; ++i) b[i] = uint8_t(v >> (8 * i));
    bytes(b, 4);
  }
  void u64(uint64_t v) {
    u32(uint32_t(v));
    u32(uint32_t(v >> 32));
  }
  void f32(float v) {
    uint32_t bits;
    std::memcpy(&bits, &v, 4);
    u32(bits);
  }
  void f64(double v) {
    uint64_t bits;
    std::memcpy(&bits, &v, 8);
    u64(bits);
  }
  void vec(const glm::vec3& v) {
    f32(v.x);
    f32(v.y);
    f32(v.z);
  }
  std::vector<uint8_t> out;
};

class Reader {
 public:
  Reader(const uint8_t* data, size_t size, const std::string& name) : data_(data), size_(size), name_(name) {}
  size_t remaining() const { return size_ - pos_; }
  size_t position() const { return pos_; }
  void need(uint64_t n, const std::string& what) const {
    if (n > remaining())
      throw InputError({name_, 0}, "truncated: " + what + " needs " + std::to_string(n) +
                                       " bytes at offset " + std::to_string(pos_) + " but only " +
                                       std::to_string(remaining()) + " remain");
  }
  const uint8_t* take(size_t n) {
    const uint8_t* p = data_ + pos_;
    pos_ += n;
    return p;
  }
  uint16_t u16() {
    const uint8_t* b = take(2);
    return uint16_t(b[0] | b[1] << 8);
  }
  uint32_t u32() {
    const uint8_t* b = take(4);
    return uint32_t(b[0]) | uint32_t(b[1]) << 8 | uint32_t(b[2]) << 16 | uint32_t(b[3]) << 24;
  }
  uint64_t u64() {
    uint64_t lo = u32();
    return lo | uint64_t(u32()) << 32;
  }
  float f32() {
    uint32_t bits = u32();
    float v;
    std::memcpy(&v, &bits, 4);
    return v;
  }
  glm::vec3 vec() {
    float x = f32(), y = f32();
    return {x, y, f32()};
  }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t pos_ = 0;
  const std::string& name_;
};

void chunk(Writer& w, const char tag[4], const std::vector<uint8_t>& payload) {
  Writer head;
  head.bytes(tag, 4);
  head.u64(payload.size());
  uLong crc = crc32(0L, head.out.data(), static_cast<uInt>(head.out.size()));
  crc = crc32_z(crc, payload.data(), payload.size());
  w.bytes(head.out.data(), head.out.size());
  w.bytes(payload.data(), payload.size());
  w.u32(static_cast<uint32_t>(crc));
}

template <typename Fn>
std::vector<uint8_t> payload(Fn fill) {
  Writer w;
  fill(w);
  return std::move(w.out);
}

// "shard=K/N" and "range=FIRST-END/TOTAL", checked for sense: 1 <= K <= N, FIRST <= END <= TOTAL.
void parseShard(const std::string& key, const std::string& value, Provenance& p, const std::string& name) {
  auto number = [&](std::string_view text) {
    uint64_t v = 0;
    auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (ec != std::errc() || end != text.data() + text.size() || text.empty())
      throw InputError({name, 0}, "PROV chunk: " + key + " '" + value + "' is malformed");
    return v;
  };
  if (!p.shard) p.shard = ShardRange{};
  ShardRange& r = *p.shard;
  const size_t slash = value.find('/');
  if (slash == std::string::npos)
    throw InputError({name, 0}, "PROV chunk: " + key + " '" + value + "' is malformed");
  const std::string_view v(value);
  if (key == "shard") {
    const uint64_t index = number(v.substr(0, slash)), count = number(v.substr(slash + 1));
    if (index < 1 || index > count || count > std::numeric_limits<uint32_t>::max())
      throw InputError({name, 0}, "PROV chunk: shard '" + value + "' is not K/N with 1 <= K <= N");
    r.index = uint32_t(index);
    r.count = uint32_t(count);
  } else {
    const size_t dash = value.find('-');
    if (dash == std::string::npos || dash > slash)
      throw InputError({name, 0}, "PROV chunk: range '" + value + "' is malformed");
    r.first = number(v.substr(0, dash));
    r.end = number(v.substr(dash + 1, slash - dash - 1));
    r.total = number(v.substr(slash + 1));
    if (r.first > r.end || r.end > r.total)
      throw InputError({name, 0}, "PROV chunk: range '" + value + "' is not FIRST-END/TOTAL in order");
  }
}

}  // namespace

std::string provenanceText(const Provenance& p) {
  std::string text = "producer=" + p.producer + "\nstage=" + p.stage + "\nseed=" + std::to_string(p.seed) +
                     "\nconfig=" + p.configDigest + "\n";
  if (p.frame) text += "frame=" + std::to_string(*p.frame) + "\ntime=" + formatReal(p.time) + "\n";
  // A file made elsewhere: written only when set, so hairgen's own files keep their bytes.
  auto line = [](const std::string& value) {
    std::string out = value;
    for (char& c : out)
      if (c == '\n' || c == '\r') c = ' ';
    return out;
  };
  if (!p.source.empty()) text += "source=" + line(p.source) + "\n";
  if (!p.sourceInfo.empty()) text += "sourceInfo=" + line(p.sourceInfo) + "\n";
  if (!p.conversion.empty()) text += "conversion=" + line(p.conversion) + "\n";
  if (!p.metres) text += "units=unknown\n";
  if (!p.yUp) text += "up=unknown\n";
  if (p.shard)
    text += "shard=" + std::to_string(p.shard->index) + "/" + std::to_string(p.shard->count) +
            "\nrange=" + std::to_string(p.shard->first) + "-" + std::to_string(p.shard->end) + "/" +
            std::to_string(p.shard->total) + "\n";
  return text;
}

Provenance parseProvenance(const std::string& text, const std::string& name) {
  Provenance p;
  size_t pos = 0;
  while (pos < text.size()) {
    size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(pos, end - pos);
    pos = end + 1;
    size_t eq = line.find('=');
    if (eq == std::string::npos) throw InputError({name, 0}, "PROV chunk: line without '='");
    std::string key = line.substr(0, eq), value = line.substr(eq + 1);
    if (key == "producer")
      p.producer = value;
    else if (key == "stage")
      p.stage = value;
    else if (key == "config")
      p.configDigest = value;
    else if (key == "frame" || key == "time") {
      std::optional<double> v = parseReal(value);
      if (!v || !std::isfinite(*v) || (key == "frame" && (*v != std::floor(*v) || std::abs(*v) > 1e9)))
        throw InputError({name, 0}, "PROV chunk: " + key + " '" + value + "' is not a " +
                                        (key == "frame" ? "frame number" : "time"));
      if (key == "frame")
        p.frame = int(*v);
      else
        p.time = *v;
    } else if (key == "seed") {
      char* end2 = nullptr;
      p.seed = std::strtoull(value.c_str(), &end2, 10);
      if (value.empty() || *end2 != '\0')
        throw InputError({name, 0}, "PROV chunk: seed '" + value + "' is not a number");
    } else if (key == "source")
      p.source = value;
    else if (key == "sourceInfo")
      p.sourceInfo = value;
    else if (key == "conversion")
      p.conversion = value;
    else if (key == "units")
      p.metres = value == "m";
    else if (key == "up")
      p.yUp = value == "y";
    else if (key == "shard" || key == "range")
      parseShard(key, value, p, name);
  }
  return p;
}

std::vector<uint8_t> encodeHair(const Strands& s) {
  s.validate("strands to write");
  const size_t strandCount = s.strandCount(), pointCount = s.pointCount();
  if (strandCount > std::numeric_limits<uint32_t>::max() || pointCount > std::numeric_limits<uint32_t>::max())
    throw InputError("too many strands or points for a .hair file (at most 2^32 - 1 each)");

  bool uniform = strandCount > 0;
  for (size_t i = 0; i < strandCount; ++i) {
    uint32_t n = s.pointsOf(i);
    if (n == 0)
      throw InputError("strand " + std::to_string(i) + " has no points; a .hair file cannot store it");
    if (n - 1 > 0xffff)
      throw InputError("strand " + std::to_string(i) + " has " + std::to_string(n) +
                       " points; .hair allows 65536");
    if (n != s.pointsOf(0)) uniform = false;
  }
  uint32_t flags = kPoints | (uniform ? 0 : kSegments) | (s.thickness.empty() ? 0 : kThickness) |
                   (s.transparency.empty() ? 0 : kTransparency) | (s.colors.empty() ? 0 : kColor);

  Writer w;
  w.bytes("HAIR", 4);
  w.u32(static_cast<uint32_t>(strandCount));
  w.u32(static_cast<uint32_t>(pointCount));
  w.u32(flags);
  w.u32(uniform ? s.pointsOf(0) - 1 : 0);
  w.f32(s.defaultThickness);
  w.f32(s.defaultTransparency);
  w.vec(s.defaultColor);
  char info[kInfoSize] = {};
  std::string text = "hairgen " HAIRGEN_VERSION " .hair (cyHair layout + hairgen chunks)";
  std::memcpy(info, text.data(), std::min(text.size(), kInfoSize - 1));
  w.bytes(info, kInfoSize);

  if (flags & kSegments)
    for (size_t i = 0; i < strandCount; ++i) w.u16(static_cast<uint16_t>(s.pointsOf(i) - 1));
  for (const glm::vec3& p : s.points) w.vec(p);
  for (float t : s.thickness) w.f32(t);
  for (float t : s.transparency) w.f32(t);
  for (const glm::vec3& c : s.colors) w.vec(c);

  std::vector<std::pair<const char*, std::vector<uint8_t>>> chunks;
  auto vec3s = [](const std::vector<glm::vec3>& v) {
    return payload([&](Writer& p) {
      for (auto& x : v) p.vec(x);
    });
  };
  auto u32s = [](const std::vector<uint32_t>& v) {
    return payload([&](Writer& p) {
      for (auto x : v) p.u32(x);
    });
  };
  if (!s.tangents.empty()) chunks.emplace_back("TANG", vec3s(s.tangents));
  if (!s.normals.empty()) chunks.emplace_back("NORM", vec3s(s.normals));
  if (!s.strandId.empty()) chunks.emplace_back("SIDS", u32s(s.strandId));
  if (!s.rootTriangle.empty()) chunks.emplace_back("RTRI", u32s(s.rootTriangle));
  if (!s.rootBary.empty()) chunks.emplace_back("RBAR", vec3s(s.rootBary));
  if (!s.rootUv.empty())
    chunks.emplace_back("RUVS", payload([&](Writer& p) {
                          for (auto& x : s.rootUv) {
                            p.f32(x.x);
                            p.f32(x.y);
                          }
                        }));
  if (!s.guideIds.empty())
    chunks.emplace_back("GIDS", payload([&](Writer& p) {
                          for (auto& x : s.guideIds) {
                            p.u32(x.x);
                            p.u32(x.y);
                            p.u32(x.z);
                          }
                        }));
  if (!s.guideWeights.empty()) chunks.emplace_back("GWTS", vec3s(s.guideWeights));
  if (!s.simulationState.empty())
    chunks.emplace_back("DYNS", payload([&](Writer& p) {
                          for (double v : s.simulationState) p.f64(v);
                        }));
  if (!s.provenance.empty()) {
    std::string prov = provenanceText(s.provenance);
    chunks.emplace_back("PROV", std::vector<uint8_t>(prov.begin(), prov.end()));
  }
  w.bytes("HGEN", 4);
  w.u32(kBlockVersion);
  w.u32(static_cast<uint32_t>(chunks.size()));
  for (const auto& [tag, bytes] : chunks) chunk(w, tag, bytes);
  return std::move(w.out);
}

Strands decodeHair(const uint8_t* data, size_t size, const std::string& name, HairHeader* headerOut) {
  Reader r(data, size, name);
  HairHeader header;
  r.need(kHeaderSize, "the 128-byte header");
  if (std::memcmp(r.take(4), "HAIR", 4) != 0)
    throw InputError({name, 0}, "not a .hair file: it does not start with \"HAIR\"");
  const uint64_t strandCount = r.u32(), pointCount = r.u32();
  header.flags = r.u32();
  header.defaultSegments = r.u32();
  Strands s;
  s.defaultThickness = r.f32();
  s.defaultTransparency = r.f32();
  s.defaultColor = r.vec();
  const char* info = reinterpret_cast<const char*>(r.take(kInfoSize));
  header.info.assign(info, strnlen(info, kInfoSize));
  if (!(header.flags & kPoints))
    throw InputError({name, 0}, "the file has no points array (flag 2 is not set)");

  // Everything the flags promise must fit in the file before any array is allocated.
  uint64_t arrays = (header.flags & kSegments ? 2 * strandCount : 0) + 12 * pointCount +
                    (header.flags & kThickness ? 4 * pointCount : 0) +
                    (header.flags & kTransparency ? 4 * pointCount : 0) +
                    (header.flags & kColor ? 12 * pointCount : 0);
  r.need(arrays, "the arrays for " + std::to_string(strandCount) + " strands and " +
                     std::to_string(pointCount) + " points");

  if (strandCount > pointCount)
    throw InputError({name, 0}, "the header declares " + std::to_string(strandCount) + " strands but only " +
                                    std::to_string(pointCount) + " points; every strand needs at least one");
  s.firstPoint.resize(strandCount + 1);
  s.firstPoint[0] = 0;
  uint64_t total = 0;
  for (uint64_t i = 0; i < strandCount; ++i) {
    uint64_t segments = header.flags & kSegments ? r.u16() : header.defaultSegments;
    total += segments + 1;
    if (total > pointCount)
      throw InputError({name, 0}, "the strands' segment counts need more than the " +
                                      std::to_string(pointCount) + " points the header declares (strand " +
                                      std::to_string(i) + ")");
    s.firstPoint[i + 1] = static_cast<uint32_t>(total);
  }
  if (total != pointCount)
    throw InputError({name, 0}, "the strands' segment counts cover " + std::to_string(total) +
                                    " points but the header declares " + std::to_string(pointCount));
  s.points.resize(pointCount);
  for (glm::vec3& p : s.points) p = r.vec();
  if (header.flags & kThickness) {
    s.thickness.resize(pointCount);
    for (float& t : s.thickness) t = r.f32();
  }
  if (header.flags & kTransparency) {
    s.transparency.resize(pointCount);
    for (float& t : s.transparency) t = r.f32();
  }
  if (header.flags & kColor) {
    s.colors.resize(pointCount);
    for (glm::vec3& c : s.colors) c = r.vec();
  }

  const bool blockFound = r.remaining() > 0;
  if (blockFound) {
    r.need(12, "the hairgen chunk block header");
    if (std::memcmp(r.take(4), "HGEN", 4) != 0)
      throw InputError({name, 0},
                       std::to_string(r.remaining() + 4) +
                           " unexpected bytes after the cyHair arrays (not a hairgen chunk block)");
    uint32_t version = r.u32();
    if (version != kBlockVersion)
      throw InputError({name, 0}, "chunk block version " + std::to_string(version) +
                                      " is not supported (this hairgen reads 1)");
    uint32_t chunkCount = r.u32();
    for (uint32_t c = 0; c < chunkCount; ++c) {
      r.need(12, "chunk " + std::to_string(c) + "'s header");
      const uint8_t* head = r.take(12);
      std::string tag(reinterpret_cast<const char*>(head), 4);
      uint64_t length = 0;
      for (int i = 0; i < 8; ++i) length |= uint64_t(head[4 + i]) << (8 * i);
      r.need(length, "chunk '" + tag + "'");
      r.need(length + 4, "chunk '" + tag + "' and its CRC");
      const uint8_t* bytes = r.take(length);
      uint32_t stored = r.u32();
      uLong crc = crc32_z(crc32(0L, head, 12), bytes, length);
      if (static_cast<uint32_t>(crc) != stored)
        throw InputError({name, 0}, "chunk '" + tag + "' fails its CRC-32 check: the file is corrupt");
      for (const std::string& seen : header.chunks)
        if (seen == tag) throw InputError({name, 0}, "chunk '" + tag + "' appears twice");
      header.chunks.push_back(tag);

      Reader p(bytes, length, name);
      auto expect = [&](uint64_t count, uint64_t bytesEach) {
        if (length != count * bytesEach)
          throw InputError({name, 0}, "chunk '" + tag + "' holds " + std::to_string(length) +
                                          " bytes, expected " + std::to_string(count * bytesEach));
      };
      auto readVec3 = [&](std::vector<glm::vec3>& v, uint64_t count) {
        expect(count, 12);
        v.resize(count);
        for (auto& x : v) x = p.vec();
      };
      auto readU32 = [&](std::vector<uint32_t>& v, uint64_t count) {
        expect(count, 4);
        v.resize(count);
        for (auto& x : v) x = p.u32();
      };
      if (tag == "TANG")
        readVec3(s.tangents, pointCount);
      else if (tag == "NORM")
        readVec3(s.normals, pointCount);
      else if (tag == "SIDS")
        readU32(s.strandId, strandCount);
      else if (tag == "RTRI")
        readU32(s.rootTriangle, strandCount);
      else if (tag == "RBAR")
        readVec3(s.rootBary, strandCount);
      else if (tag == "GWTS")
        readVec3(s.guideWeights, strandCount);
      else if (tag == "RUVS") {
        expect(strandCount, 8);
        s.rootUv.resize(strandCount);
        for (auto& x : s.rootUv) {
          x.x = p.f32();
          x.y = p.f32();
        }
      } else if (tag == "GIDS") {
        expect(strandCount, 12);
        s.guideIds.resize(strandCount);
        for (auto& x : s.guideIds) {
          x.x = p.u32();
          x.y = p.u32();
          x.z = p.u32();
        }
      } else if (tag == "DYNS") {
        if (length % 8) throw InputError({name, 0}, "chunk 'DYNS' is not a whole number of float64 values");
        s.simulationState.resize(length / 8);
        for (double& v : s.simulationState) {
          uint64_t bits = uint64_t(p.u32());
          bits |= uint64_t(p.u32()) << 32;
          std::memcpy(&v, &bits, 8);
        }
      } else if (tag == "PROV") {
        s.provenance = parseProvenance(std::string(reinterpret_cast<const char*>(bytes), length), name);
      }
    }
    if (r.remaining() > 0)
      throw InputError({name, 0}, std::to_string(r.remaining()) + " unexpected bytes after the last chunk");
  }
  if (!blockFound) {
    // A cyHair file made elsewhere: its units and up axis are its own, and its info text describes it.
    s.provenance.metres = s.provenance.yUp = false;
    s.provenance.sourceInfo = header.info;
  }
  s.validate(name);
  if (headerOut) *headerOut = std::move(header);
  return s;
}

Strands readHair(const std::filesystem::path& file, HairHeader* header) {
  std::vector<uint8_t> bytes = readFileBytes(file);
  return decodeHair(bytes.data(), bytes.size(), file.string(), header);
}

void writeHair(const std::filesystem::path& file, const Strands& strands) {
  std::vector<uint8_t> bytes = encodeHair(strands);
  writeFileAtomic(file, bytes.data(), bytes.size());
}

Provenance readHairProvenance(const std::filesystem::path& file) {
  requireRegularFile(file);
  const std::string name = file.string();
  std::ifstream in(file, std::ios::binary);
  if (!in) throw IoError("cannot open " + name);
  auto read = [&](void* to, size_t bytes, const char* what) {
    if (!in.read(static_cast<char*>(to), std::streamsize(bytes)))
      throw InputError({name, 0}, std::string("ends inside ") + what);
  };
  auto u32 = [&](const char* what) {
    uint8_t b[4];
    read(b, 4, what);
    return uint32_t(b[0]) | uint32_t(b[1]) << 8 | uint32_t(b[2]) << 16 | uint32_t(b[3]) << 24;
  };
  char magic[4];
  read(magic, 4, "the header");
  if (std::memcmp(magic, "HAIR", 4) != 0) throw InputError({name, 0}, "is not a .hair file");
  const uint64_t strands = u32("the header"), points = u32("the header"), flags = u32("the header");
  uint64_t arrays = (flags & kSegments ? 2 * strands : 0) + (flags & kPoints ? 12 * points : 0) +
                    (flags & kThickness ? 4 * points : 0) + (flags & kTransparency ? 4 * points : 0) +
                    (flags & kColor ? 12 * points : 0);
  in.seekg(std::streamoff(kHeaderSize + arrays));
  char block[4];
  if (!in.read(block, 4)) return {};  // no chunk block: made elsewhere
  if (std::memcmp(block, "HGEN", 4) != 0) return {};
  u32("the chunk block header");
  const uint32_t chunks = u32("the chunk block header");
  for (uint32_t c = 0; c < chunks; ++c) {
    char tag[4];
    read(tag, 4, "a chunk header");
    const uint64_t low = u32("a chunk header"), high = u32("a chunk header");
    const uint64_t length = low | high << 32;
    if (std::memcmp(tag, "PROV", 4) == 0) {
      if (length > (1u << 20))
        throw InputError({name, 0}, "PROV chunk of " + std::to_string(length) + " bytes");
      std::string text(length, '\0');
      read(text.data(), length, "the PROV chunk");
      return parseProvenance(text, name);
    }
    in.seekg(std::streamoff(length + 4), std::ios::cur);
  }
  return {};
}

}  // namespace hairgen
