#include "libcore/io/hair_io.h"

#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>

#include <tbb/parallel_for.h>
#include <zlib.h>

#include "libcore/util/error.h"
#include "libcore/util/file_util.h"
#include "libcore/util/huge_pages.h"
#include "libcore/util/text.h"

namespace hairgen {
namespace {

constexpr uint32_t kSegments = 1, kPoints = 2, kThickness = 4, kTransparency = 8, kColor = 16;
constexpr size_t kHeaderSize = 128, kInfoSize = 88;
constexpr uint32_t kBlockVersion = 1;
constexpr uint32_t kMaxChunks = 1024;
// A point array this large or larger is held where a mapped file has it (ArrayStorage::kMapped); a
// smaller one is copied, cheaper than its own faults. Low enough that the renders of the test suite's
// coupes map theirs.
constexpr size_t kMappedArray = size_t(64) << 10;
// The arrays are the bytes of these types: packed floats and uint32s, as the layout says.
static_assert(sizeof(glm::vec3) == 12 && sizeof(glm::vec2) == 8 && sizeof(glm::uvec3) == 12);

// Arrays of 4- and 8-byte words travel as their bytes on a little-endian machine; elsewhere every word
// is swapped on its way in and out.
constexpr bool kLittleEndian = std::endian::native == std::endian::little;

template <size_t Word>
void swapWords(void* data, size_t bytes) {
  uint8_t* b = static_cast<uint8_t*>(data);
  for (size_t i = 0; i + Word <= bytes; i += Word) std::reverse(b + i, b + i + Word);
}

// CRC-32 of a large buffer in 8 MB blocks on every core, combined in order: the same value as one pass.
uint32_t crcOf(uint32_t crc, const uint8_t* data, size_t size) {
  if (size == 0) return crc;  // zlib answers 0 for a null buffer, which an empty vector's data() may be
  constexpr size_t kBlock = size_t(8) << 20;
  if (size < 2 * kBlock) return uint32_t(crc32_z(crc, data, size));
  const size_t blocks = (size + kBlock - 1) / kBlock;
  std::vector<uLong> part(blocks);
  tbb::parallel_for(size_t(0), blocks, [&](size_t i) {
    const size_t begin = i * kBlock, length = std::min(kBlock, size - begin);
    part[i] = crc32_z(0L, data + begin, length);
  });
  uLong whole = crc;
  for (size_t i = 0; i < blocks; ++i)
    whole = crc32_combine(whole, part[i], z_off_t(std::min(kBlock, size - i * kBlock)));
  return uint32_t(whole);
}

// Where encoded bytes go: a growing buffer (encodeHair) or a file being written (writeHair).
class Writer {
 public:
  explicit Writer(std::function<void(const uint8_t*, size_t)> sink) : sink_(std::move(sink)) {}
  void bytes(const void* p, size_t n) {
    if (n) sink_(static_cast<const uint8_t*>(p), n);
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
  void f32(float v) { u32(std::bit_cast<uint32_t>(v)); }
  void vec(const glm::vec3& v) {
    f32(v.x);
    f32(v.y);
    f32(v.z);
  }
  // An array of Word-byte words (floats, uint32s, doubles, and vectors of them), as little-endian bytes.
  template <size_t Word, typename T, class A>
  void array(const std::vector<T, A>& v) {
    static_assert(sizeof(T) % Word == 0);
    const size_t n = v.size() * sizeof(T);
    if constexpr (kLittleEndian) {
      bytes(v.data(), n);
    } else {
      std::vector<uint8_t> copy(reinterpret_cast<const uint8_t*>(v.data()),
                                reinterpret_cast<const uint8_t*>(v.data()) + n);
      swapWords<Word>(copy.data(), n);
      bytes(copy.data(), n);
    }
  }

 private:
  std::function<void(const uint8_t*, size_t)> sink_;
};

// A chunk: tag, length, the payload as Word-byte words, and the CRC-32 of all three (of the bytes as
// written, so the payload is swapped first on a big-endian machine).
template <size_t Word, typename T, class A>
void chunk(Writer& w, const char tag[4], const std::vector<T, A>& values) {
  const uint64_t length = values.size() * sizeof(T);
  uint8_t head[12];
  std::memcpy(head, tag, 4);
  for (int i = 0; i < 8; ++i) head[4 + i] = uint8_t(length >> (8 * i));
  const uint8_t* payload = reinterpret_cast<const uint8_t*>(values.data());
  std::vector<uint8_t> swapped;
  if constexpr (!kLittleEndian) {
    swapped.assign(payload, payload + length);
    swapWords<Word>(swapped.data(), length);
    payload = swapped.data();
  }
  const uint32_t crc = crcOf(uint32_t(crc32(0L, head, 12)), payload, length);
  w.bytes(head, 12);
  w.bytes(payload, length);
  w.u32(crc);
}

// Where decoded bytes come from: memory (decodeHair) or a file read piece by piece (readHair), so a
// file's arrays are read straight into their vectors and never held twice.
class Source {
 public:
  virtual ~Source() = default;
  virtual uint64_t remaining() const = 0;
  virtual void read(void* out, size_t bytes) = 0;  // after need(): the bytes are there
  // The next `bytes` bytes where they lie in a mapped file, for an array to hold without a copy; null
  // where the source maps nothing. The caller then skip()s them.
  virtual std::shared_ptr<MappedRegion> region(size_t /*bytes*/, size_t /*elementBytes*/) { return nullptr; }
  virtual void skip(size_t bytes) = 0;  // after need(): moves past the bytes
};

class MemorySource final : public Source {
 public:
  MemorySource(const uint8_t* data, size_t size) : data_(data), size_(size) {}
  uint64_t remaining() const override { return size_ - pos_; }
  void read(void* out, size_t bytes) override {
    if (bytes) std::memcpy(out, data_ + pos_, bytes);
    pos_ += bytes;
  }
  void skip(size_t bytes) override { pos_ += bytes; }

 private:
  const uint8_t* data_;
  size_t size_, pos_ = 0;
};

class FileSource final : public Source {
 public:
  FileSource(const std::filesystem::path& path, ArrayStorage storage,
             InputFile::Reading reading = InputFile::Reading::kWhole)
      : file_(path, reading), mapped_(storage == ArrayStorage::kMapped) {}
  uint64_t remaining() const override { return file_.remaining(); }
  void read(void* out, size_t bytes) override { file_.read(out, bytes); }
  std::shared_ptr<MappedRegion> region(size_t bytes, size_t elementBytes) override {
    const std::shared_ptr<FileMapping> mapping = mapped_ ? file_.mapping() : nullptr;
    if (!mapping) return nullptr;
    return std::make_shared<MappedRegion>(
        MappedRegion{mapping, mapping->data() + file_.position(), bytes, elementBytes});
  }
  void skip(size_t bytes) override { file_.skip(bytes); }

 private:
  InputFile file_;
  bool mapped_;
};

class Reader {
 public:
  Reader(Source& source, const std::string& name) : source_(source), name_(name) {}
  uint64_t remaining() const { return source_.remaining(); }
  void need(uint64_t n, const std::string& what) const {
    if (n > remaining())
      throw InputError({name_, 0}, "truncated: " + what + " needs " + std::to_string(n) + " bytes but only " +
                                       std::to_string(remaining()) + " remain");
  }
  void bytes(void* out, size_t n) { source_.read(out, n); }
  uint16_t u16() {
    uint8_t b[2];
    bytes(b, 2);
    return uint16_t(b[0] | b[1] << 8);
  }
  uint32_t u32() {
    uint8_t b[4];
    bytes(b, 4);
    return uint32_t(b[0]) | uint32_t(b[1]) << 8 | uint32_t(b[2]) << 16 | uint32_t(b[3]) << 24;
  }
  float f32() { return std::bit_cast<float>(u32()); }
  glm::vec3 vec() {
    float x = f32(), y = f32();
    return {x, y, f32()};
  }
  // `count` values of Word-byte words into `v`, after need() has checked they are there; returns the
  // bytes as they were in the file (for a CRC) through `crc` when it is given.
  template <size_t Word, typename T, class A>
  void array(std::vector<T, A>& v, uint64_t count, uint32_t* crc = nullptr) {
    static_assert(sizeof(T) % Word == 0);
    const size_t n = size_t(count) * sizeof(T);
    if constexpr (kLittleEndian && std::is_same_v<A, MappableAllocator<T>>) {
      if (n >= kMappedArray && mapped(v, count, crc)) return;
    }
    resizeLarge(v, count);
    bytes(v.data(), n);
    if (crc) *crc = crcOf(*crc, reinterpret_cast<const uint8_t*>(v.data()), n);
    if constexpr (!kLittleEndian) swapWords<Word>(v.data(), n);
  }
  // The mapped chunks leave the process, once the file's checks have read them (a chunk's CRC, the
  // strands' validate()): nothing has written them.
  void releaseChecked() {
    for (const std::shared_ptr<MappedRegion>& r : checked_)
      r->file->release(uint64_t(static_cast<uint8_t*>(r->data) - r->file->data()), r->bytes);
    checked_.clear();
  }

 private:
  // A point array held where the source's mapping has it (the next count · 12 bytes), when it lies on
  // a float's boundary there (the points of a file whose strands differ in length start 2 bytes past
  // one when their number is odd: read as a copy). A chunk's, once the file is checked, leaves the
  // process until what reads the array reads it (releaseChecked): the render's tangents are not the
  // process's through the passes that do not shade.
  template <typename T>
  bool mapped(std::vector<T, MappableAllocator<T>>& v, uint64_t count, uint32_t* crc) {
    const std::shared_ptr<MappedRegion> region = source_.region(size_t(count) * sizeof(T), sizeof(T));
    if (!region || reinterpret_cast<uintptr_t>(region->data) % alignof(T) != 0) return false;
    std::vector<T, MappableAllocator<T>> held{MappableAllocator<T>(region)};
    held.reserve(size_t(count));
    if (held.data() != region->data) return false;
    held.resize(size_t(count));
    source_.skip(region->bytes);
    if (crc) {
      *crc = crcOf(*crc, static_cast<const uint8_t*>(region->data), region->bytes);
      checked_.push_back(region);
    }
    v = std::move(held);
    return true;
  }

  Source& source_;
  const std::string& name_;
  std::vector<std::shared_ptr<MappedRegion>> checked_;  // mapped chunks whose CRC was taken
};

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
  // Each value one line of printable text (a PLY header carries these lines as comments).
  const auto line = [](const std::string& value) { return printableText(value); };
  std::string text = "producer=" + line(p.producer) + "\nstage=" + line(p.stage) +
                     "\nseed=" + std::to_string(p.seed) + "\nconfig=" + line(p.configDigest) + "\n";
  if (p.frame) text += "frame=" + std::to_string(*p.frame) + "\ntime=" + formatReal(p.time) + "\n";
  if (!p.restDigest.empty()) text += "rest=" + p.restDigest + "\n";
  // A file made elsewhere: written only when set, so hairgen's own files keep their bytes.
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
    else if (key == "rest")
      p.restDigest = value;
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

namespace {

void encodeHairTo(const Strands& s, Writer& w) {
  s.validate("strands to write");
  const size_t strandCount = s.strandCount(), pointCount = s.pointCount();
  if (strandCount > std::numeric_limits<uint32_t>::max() || pointCount > std::numeric_limits<uint32_t>::max())
    throw InputError("too many strands or points for a .hair file (at most 2^32 - 1 each)");

  bool uniform = strandCount > 0;
  std::vector<uint16_t> segments(strandCount);
  for (size_t i = 0; i < strandCount; ++i) {
    uint32_t n = s.pointsOf(i);
    if (n == 0)
      throw InputError("strand " + std::to_string(i) + " has no points; a .hair file cannot store it");
    if (n - 1 > 0xffff)
      throw InputError("strand " + std::to_string(i) + " has " + std::to_string(n) +
                       " points; .hair allows 65536");
    if (n != s.pointsOf(0)) uniform = false;
    segments[i] = static_cast<uint16_t>(n - 1);
  }
  uint32_t flags = kPoints | (uniform ? 0 : kSegments) | (s.thickness.empty() ? 0 : kThickness) |
                   (s.transparency.empty() ? 0 : kTransparency) | (s.colors.empty() ? 0 : kColor);

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

  if (flags & kSegments) w.array<2>(segments);
  w.array<4>(s.points);
  w.array<4>(s.thickness);
  w.array<4>(s.transparency);
  w.array<4>(s.colors);

  const std::string prov = s.provenance.empty() ? std::string() : provenanceText(s.provenance);
  const std::vector<char> provBytes(prov.begin(), prov.end());
  const uint32_t chunks = !s.tangents.empty() + !s.normals.empty() + !s.strandId.empty() +
                          !s.rootTriangle.empty() + !s.rootBary.empty() + !s.rootUv.empty() +
                          !s.guideIds.empty() + !s.guideWeights.empty() + !s.simulationState.empty() +
                          !prov.empty();
  w.bytes("HGEN", 4);
  w.u32(kBlockVersion);
  w.u32(chunks);
  if (!s.tangents.empty()) chunk<4>(w, "TANG", s.tangents);
  if (!s.normals.empty()) chunk<4>(w, "NORM", s.normals);
  if (!s.strandId.empty()) chunk<4>(w, "SIDS", s.strandId);
  if (!s.rootTriangle.empty()) chunk<4>(w, "RTRI", s.rootTriangle);
  if (!s.rootBary.empty()) chunk<4>(w, "RBAR", s.rootBary);
  if (!s.rootUv.empty()) chunk<4>(w, "RUVS", s.rootUv);
  if (!s.guideIds.empty()) chunk<4>(w, "GIDS", s.guideIds);
  if (!s.guideWeights.empty()) chunk<4>(w, "GWTS", s.guideWeights);
  if (!s.simulationState.empty()) chunk<8>(w, "DYNS", s.simulationState);
  if (!prov.empty()) chunk<1>(w, "PROV", provBytes);
}

Strands decodeHairFrom(Source& source, const std::string& name, HairHeader* headerOut) {
  Reader r(source, name);
  HairHeader header;
  r.need(kHeaderSize, "the 128-byte header");
  char magic[4];
  r.bytes(magic, 4);
  if (std::memcmp(magic, "HAIR", 4) != 0)
    throw InputError({name, 0}, "not a .hair file: it does not start with \"HAIR\"");
  const uint64_t strandCount = r.u32(), pointCount = r.u32();
  header.flags = r.u32();
  header.defaultSegments = r.u32();
  Strands s;
  s.defaultThickness = r.f32();
  s.defaultTransparency = r.f32();
  s.defaultColor = r.vec();
  char info[kInfoSize];
  r.bytes(info, kInfoSize);
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
  std::vector<uint16_t> segments;
  if (header.flags & kSegments) r.array<2>(segments, strandCount);
  uint64_t total = 0;
  for (uint64_t i = 0; i < strandCount; ++i) {
    total += uint64_t(header.flags & kSegments ? segments[i] : header.defaultSegments) + 1;
    if (total > pointCount)
      throw InputError({name, 0}, "the strands' segment counts need more than the " +
                                      std::to_string(pointCount) + " points the header declares (strand " +
                                      std::to_string(i) + ")");
    s.firstPoint[i + 1] = static_cast<uint32_t>(total);
  }
  if (total != pointCount)
    throw InputError({name, 0}, "the strands' segment counts cover " + std::to_string(total) +
                                    " points but the header declares " + std::to_string(pointCount));
  r.array<4>(s.points, pointCount);
  if (header.flags & kThickness) r.array<4>(s.thickness, pointCount);
  if (header.flags & kTransparency) r.array<4>(s.transparency, pointCount);
  if (header.flags & kColor) r.array<4>(s.colors, pointCount);

  const bool blockFound = r.remaining() > 0;
  if (blockFound) {
    r.need(12, "the hairgen chunk block header");
    r.bytes(magic, 4);
    if (std::memcmp(magic, "HGEN", 4) != 0)
      throw InputError({name, 0},
                       std::to_string(r.remaining() + 4) +
                           " unexpected bytes after the cyHair arrays (not a hairgen chunk block)");
    uint32_t version = r.u32();
    if (version != kBlockVersion)
      throw InputError({name, 0}, "chunk block version " + std::to_string(version) +
                                      " is not supported (this hairgen reads 1)");
    uint32_t chunkCount = r.u32();
    // hairgen writes a dozen; a file that claims more is refused before each is checked against the
    // others (which would cost the square of the count).
    if (chunkCount > kMaxChunks)
      throw InputError({name, 0}, "declares " + std::to_string(chunkCount) +
                                      " chunks; hairgen reads at most " + std::to_string(kMaxChunks));
    for (uint32_t c = 0; c < chunkCount; ++c) {
      r.need(12, "chunk " + std::to_string(c) + "'s header");
      uint8_t head[12];
      r.bytes(head, 12);
      std::string tag(reinterpret_cast<const char*>(head), 4), shown;
      for (char ch : tag) {  // the tag as messages and `info` show it: control bytes escaped
        char hex[5];
        std::snprintf(hex, sizeof hex, "\\x%02x", unsigned(static_cast<unsigned char>(ch)));
        shown += std::isprint(static_cast<unsigned char>(ch)) ? std::string(1, ch) : std::string(hex);
      }
      uint64_t length = 0;
      for (int i = 0; i < 8; ++i) length |= uint64_t(head[4 + i]) << (8 * i);
      r.need(length, "chunk '" + shown + "'");
      r.need(length + 4, "chunk '" + shown + "' and its CRC");
      for (const std::string& seen : header.chunks)
        if (seen == shown) throw InputError({name, 0}, "chunk '" + shown + "' appears twice");
      header.chunks.push_back(shown);

      // The payload, read straight into the array it fills when its size is the one expected.
      auto sized = [&](uint64_t count, uint64_t bytesEach) {
        if (length != count * bytesEach)
          throw InputError({name, 0}, "chunk '" + shown + "' holds " + std::to_string(length) +
                                          " bytes, expected " + std::to_string(count * bytesEach));
        return count;
      };
      uint32_t crc = uint32_t(crc32(0L, head, 12));
      std::vector<char> other;
      if (tag == "TANG")
        r.array<4>(s.tangents, sized(pointCount, 12), &crc);
      else if (tag == "NORM")
        r.array<4>(s.normals, sized(pointCount, 12), &crc);
      else if (tag == "SIDS")
        r.array<4>(s.strandId, sized(strandCount, 4), &crc);
      else if (tag == "RTRI")
        r.array<4>(s.rootTriangle, sized(strandCount, 4), &crc);
      else if (tag == "RBAR")
        r.array<4>(s.rootBary, sized(strandCount, 12), &crc);
      else if (tag == "GWTS")
        r.array<4>(s.guideWeights, sized(strandCount, 12), &crc);
      else if (tag == "RUVS")
        r.array<4>(s.rootUv, sized(strandCount, 8), &crc);
      else if (tag == "GIDS")
        r.array<4>(s.guideIds, sized(strandCount, 12), &crc);
      else if (tag == "DYNS") {
        if (length % 8) throw InputError({name, 0}, "chunk 'DYNS' is not a whole number of float64 values");
        r.array<8>(s.simulationState, length / 8, &crc);
      } else {
        r.array<1>(other, length, &crc);  // PROV, or a chunk of a newer hairgen: checked, then skipped
      }
      if (crc != r.u32())
        throw InputError({name, 0}, "chunk '" + shown + "' fails its CRC-32 check: the file is corrupt");
      if (tag == "PROV") s.provenance = parseProvenance(std::string(other.begin(), other.end()), name);
    }
    if (r.remaining() > 0)
      throw InputError({name, 0}, std::to_string(r.remaining()) + " unexpected bytes after the last chunk");
  }
  if (!blockFound) {
    // A cyHair file made elsewhere: its units and up axis are its own, and its info text describes it.
    s.provenance.metres = s.provenance.yUp = false;
    s.provenance.sourceInfo = header.info;
  }
  requireMappingsWhole();  // a mapped array's page that could not be read is zeros, no value of the file
  s.validate(name);
  r.releaseChecked();
  if (headerOut) *headerOut = std::move(header);
  return s;
}

}  // namespace

std::vector<uint8_t> encodeHair(const Strands& s) {
  std::vector<uint8_t> out;
  Writer w([&](const uint8_t* p, size_t n) { out.insert(out.end(), p, p + n); });
  encodeHairTo(s, w);
  return out;
}

Strands decodeHair(const uint8_t* data, size_t size, const std::string& name, HairHeader* header) {
  MemorySource source(data, size);
  return decodeHairFrom(source, name, header);
}

Strands readHair(const std::filesystem::path& file, HairHeader* header, ArrayStorage storage) {
  FileSource source(file, storage);
  return decodeHairFrom(source, file.string(), header);
}

void writeHair(const std::filesystem::path& file, const Strands& strands) {
  namingFile(file.string(), [&] {
    AtomicFile out(file);
    Writer w([&](const uint8_t* p, size_t n) {
      out.stream().write(reinterpret_cast<const char*>(p), std::streamsize(n));
    });
    encodeHairTo(strands, w);
    out.commit();
  });
}

Provenance readHairProvenance(const std::filesystem::path& file) {
  // The file read from its start with seeks over the arrays and the other chunks, whatever its size;
  // every read and every seek is first checked against what remains of the file (Reader::need), as
  // decodeHair's are, so no length a header declares moves past its end.
  const std::string name = file.string();
  FileSource source(file, ArrayStorage::kCopied, InputFile::Reading::kParts);
  Reader r(source, name);
  r.need(kHeaderSize, "the 128-byte header");
  char magic[4];
  r.bytes(magic, 4);
  if (std::memcmp(magic, "HAIR", 4) != 0) throw InputError({name, 0}, "is not a .hair file");
  const uint64_t strands = r.u32(), points = r.u32(), flags = r.u32();
  const uint64_t arrays = (flags & kSegments ? 2 * strands : 0) + (flags & kPoints ? 12 * points : 0) +
                          (flags & kThickness ? 4 * points : 0) + (flags & kTransparency ? 4 * points : 0) +
                          (flags & kColor ? 12 * points : 0);
  r.need(kHeaderSize - 16 + arrays,
         "the arrays for " + std::to_string(strands) + " strands and " + std::to_string(points) + " points");
  source.skip(kHeaderSize - 16 + arrays);
  if (r.remaining() < 12) return {};  // no chunk block: made elsewhere
  r.bytes(magic, 4);
  if (std::memcmp(magic, "HGEN", 4) != 0) return {};
  r.u32();  // the block's version
  const uint32_t chunks = r.u32();
  if (chunks > kMaxChunks)
    throw InputError({name, 0}, "declares " + std::to_string(chunks) + " chunks; hairgen reads at most " +
                                    std::to_string(kMaxChunks));
  for (uint32_t c = 0; c < chunks; ++c) {
    r.need(12, "chunk " + std::to_string(c) + "'s header");
    char tag[4];
    r.bytes(tag, 4);
    const uint64_t low = r.u32(), high = r.u32();
    const uint64_t length = low | high << 32;
    r.need(length, "chunk " + std::to_string(c));
    r.need(length + 4, "chunk " + std::to_string(c) + " and its CRC");
    if (std::memcmp(tag, "PROV", 4) == 0) {
      if (length > (1u << 20))
        throw InputError({name, 0}, "PROV chunk of " + std::to_string(length) + " bytes");
      std::string text(length, '\0');
      r.bytes(text.data(), length);
      return parseProvenance(text, name);
    }
    source.skip(length + 4);
  }
  return {};
}

}  // namespace hairgen
