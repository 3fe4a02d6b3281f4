#include "libcore/io/hairsalon_io.h"

#include <cstring>
#include <limits>

#include "libcore/util/checked.h"
#include "libcore/util/error.h"
#include "libcore/util/file_util.h"

namespace hairgen {
namespace {

void putU32(std::vector<uint8_t>& out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(uint8_t(v >> (8 * i)));
}

uint32_t getU32(const uint8_t* p) {
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

}  // namespace

std::vector<uint8_t> encodeHairSalon(const Strands& s) {
  s.validate("strands to write");
  constexpr uint64_t kMaxCount = std::numeric_limits<int32_t>::max();
  if (s.strandCount() > kMaxCount) throw InputError("too many strands for a .data file (at most 2^31 - 1)");
  std::vector<uint8_t> out;
  out.reserve(4 + 4 * s.strandCount() + 12 * s.pointCount());
  putU32(out, static_cast<uint32_t>(s.strandCount()));
  for (size_t i = 0; i < s.strandCount(); ++i) {
    putU32(out, s.pointsOf(i));
    for (uint32_t p = s.firstPoint[i]; p < s.firstPoint[i + 1]; ++p)
      for (int c = 0; c < 3; ++c) {
        uint32_t bits;
        std::memcpy(&bits, &s.points[p][c], 4);
        putU32(out, bits);
      }
  }
  return out;
}

Strands decodeHairSalon(const uint8_t* data, size_t size, const std::string& name) {
  auto fail = [&](const std::string& message) { return InputError({name, 0}, message); };
  if (size < 4) throw fail("truncated: a .data file starts with a 4-byte strand count");
  const int32_t strands = static_cast<int32_t>(getU32(data));
  // Every strand needs at least its 4-byte point count.
  if (strands < 0) throw fail("the header's strand count is " + std::to_string(strands) + ", negative");
  std::optional<uint64_t> least = checkedMul(uint64_t(strands), 4);
  if (!least || *least > size - 4)
    throw fail("the header declares " + std::to_string(strands) + " strands, which the " +
               std::to_string(size) + "-byte file cannot hold");
  Strands s;
  s.firstPoint.reserve(size_t(strands) + 1);
  size_t pos = 4;
  uint64_t total = 0;
  for (int32_t i = 0; i < strands; ++i) {
    if (size - pos < 4) throw fail("truncated: strand " + std::to_string(i) + " has no point count");
    const int32_t points = static_cast<int32_t>(getU32(data + pos));
    pos += 4;
    if (points < 0)
      throw fail("strand " + std::to_string(i) + "'s point count is " + std::to_string(points) +
                 ", negative (at byte " + std::to_string(pos - 4) + ")");
    std::optional<uint64_t> bytes = checkedMul(uint64_t(points), 12);
    if (!bytes || *bytes > size - pos)
      throw fail("strand " + std::to_string(i) + " declares " + std::to_string(points) +
                 " points, more than the " + std::to_string(size - pos) + " bytes left hold");
    total += uint64_t(points);
    if (total > std::numeric_limits<uint32_t>::max() - 1) throw fail("more than 2^32 - 2 points");
    for (int32_t p = 0; p < points; ++p) {
      glm::vec3 v;
      for (int c = 0; c < 3; ++c) {
        const uint32_t bits = getU32(data + pos);
        std::memcpy(&v[c], &bits, 4);
        pos += 4;
      }
      s.points.push_back(v);
    }
    s.firstPoint.push_back(static_cast<uint32_t>(total));
  }
  if (pos != size) throw fail(std::to_string(size - pos) + " unexpected bytes after the last strand");
  // No header: the units and up axis are the file's own.
  s.provenance.metres = s.provenance.yUp = false;
  s.validate(name);
  return s;
}

Strands readHairSalon(const std::filesystem::path& file) {
  std::vector<uint8_t> bytes = readFileBytes(file);
  return decodeHairSalon(bytes.data(), bytes.size(), file.string());
}

void writeHairSalon(const std::filesystem::path& file, const Strands& strands) {
  std::vector<uint8_t> bytes = namingFile(file.string(), [&] { return encodeHairSalon(strands); });
  writeFileAtomic(file, bytes.data(), bytes.size());
}

}  // namespace hairgen
