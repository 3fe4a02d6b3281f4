// The .hair cache: cyHair compatibility, byte-for-byte round trips, and hostile files.
#include <gtest/gtest.h>

#include <csignal>
#include <cstdio>
#include <cstring>
#include <fstream>

#include <zlib.h>

#include "libcore/io/hair_io.h"
#include "libcore/util/error.h"
#include "libcore/util/file_util.h"
#include "libcore/util/huge_pages.h"
#include "libcore/util/mapped_file.h"
#include "tests/test_util.h"

namespace hairgen {
namespace {

// A minimal cyHair reader written from the published layout alone: header, then the arrays the flags
// name. It knows nothing of hairgen's chunk block.
struct CyHair {
  uint32_t strands = 0, points = 0, flags = 0, defaultSegments = 0;
  std::vector<uint16_t> segments;
  std::vector<float> xyz, thickness;
  size_t bytesRead = 0;
};

CyHair readCyHair(const std::vector<uint8_t>& file) {
  CyHair h;
  EXPECT_EQ(std::memcmp(file.data(), "HAIR", 4), 0);
  std::memcpy(&h.strands, &file[4], 4);
  std::memcpy(&h.points, &file[8], 4);
  std::memcpy(&h.flags, &file[12], 4);
  std::memcpy(&h.defaultSegments, &file[16], 4);
  size_t pos = 128;
  if (h.flags & 1) {
    h.segments.resize(h.strands);
    std::memcpy(h.segments.data(), &file[pos], 2 * h.strands);
    pos += 2 * h.strands;
  }
  h.xyz.resize(3 * h.points);
  std::memcpy(h.xyz.data(), &file[pos], 12 * h.points);
  pos += 12 * h.points;
  if (h.flags & 4) {
    h.thickness.resize(h.points);
    std::memcpy(h.thickness.data(), &file[pos], 4 * h.points);
    pos += 4 * h.points;
  }
  if (h.flags & 8) pos += 4 * h.points;
  if (h.flags & 16) pos += 12 * h.points;
  h.bytesRead = pos;
  return h;
}

TEST(HairFile, WrittenFileRoundTripsByteForByte) {
  Strands s = test::sampleStrands();
  std::vector<uint8_t> bytes = encodeHair(s);
  Strands back = decodeHair(bytes.data(), bytes.size(), "mem.hair");
  test::expectSameStrands(back, s);
  EXPECT_EQ(encodeHair(back), bytes);
}

TEST(HairFile, FileOnDiskRoundTripsByteForByte) {
  test::TempDir dir("hair");
  Strands s = test::sampleStrands(30, 5);
  writeHair(dir / "a.hair", s);
  writeHair(dir / "b.hair", readHair(dir / "a.hair"));
  EXPECT_EQ(readFileBytes(dir / "a.hair"), readFileBytes(dir / "b.hair"));
}

TEST(HairFile, CyHairReaderReadsCoreAndStopsBeforeChunks) {
  Strands s = test::sampleStrands();
  std::vector<uint8_t> bytes = encodeHair(s);
  CyHair h = readCyHair(bytes);
  EXPECT_EQ(h.strands, s.strandCount());
  EXPECT_EQ(h.points, s.pointCount());
  ASSERT_EQ(h.segments.size(), s.strandCount());
  for (size_t i = 0; i < s.strandCount(); ++i) EXPECT_EQ(h.segments[i] + 1u, s.pointsOf(i));
  for (size_t p = 0; p < s.pointCount(); ++p) {
    EXPECT_EQ(h.xyz[3 * p], s.points[p].x);
    EXPECT_EQ(h.xyz[3 * p + 2], s.points[p].z);
    EXPECT_EQ(h.thickness[p], s.thickness[p]);
  }
  ASSERT_LT(h.bytesRead, bytes.size());
  EXPECT_EQ(std::memcmp(&bytes[h.bytesRead], "HGEN", 4), 0);  // the chunk block starts where cyHair ends
}

TEST(HairFile, UniformStrandsUseDefaultSegmentsAndReadBack) {
  Strands s;
  for (int i = 0; i < 5; ++i) s.addStrand({glm::vec3(i, 0, 0), glm::vec3(i, 1, 0), glm::vec3(i, 2, 0)});
  std::vector<uint8_t> bytes = encodeHair(s);
  CyHair h = readCyHair(bytes);
  EXPECT_EQ(h.flags & 1, 0u);
  EXPECT_EQ(h.defaultSegments, 2u);
  EXPECT_EQ(decodeHair(bytes.data(), bytes.size(), "u.hair"), s);
}

TEST(HairFile, EveryTruncationIsAnInputError) {
  std::vector<uint8_t> bytes = encodeHair(test::sampleStrands(4));
  size_t cyHairEnd = readCyHair(bytes).bytesRead;  // cut exactly there, it is a valid plain cyHair file
  for (size_t length = 0; length < bytes.size(); ++length)
    if (length != cyHairEnd) {
      EXPECT_THROW(decodeHair(bytes.data(), length, "t.hair"), InputError) << "length " << length;
    }
}

TEST(HairFile, BitFlipsInChunksFailTheirCrc) {
  std::vector<uint8_t> bytes = encodeHair(test::sampleStrands(4));
  size_t block = readCyHair(bytes).bytesRead + 12;
  for (size_t i = block; i < bytes.size(); i += 7) {
    std::vector<uint8_t> flipped = bytes;
    flipped[i] ^= 0x10;
    EXPECT_THROW(decodeHair(flipped.data(), flipped.size(), "f.hair"), InputError) << "byte " << i;
  }
}

TEST(HairFile, OversizedCountsAreRejectedBeforeAllocating) {
  std::vector<uint8_t> bytes = encodeHair(test::sampleStrands(4));
  for (uint32_t count : {0xffffffffu, 0x10000000u, 100000u}) {
    std::vector<uint8_t> bad = bytes;
    std::memcpy(&bad[8], &count, 4);  // points
    EXPECT_THROW(decodeHair(bad.data(), bad.size(), "o.hair"), InputError);
    bad = bytes;
    std::memcpy(&bad[4], &count, 4);  // strands
    EXPECT_THROW(decodeHair(bad.data(), bad.size(), "o.hair"), InputError);
  }
  // A chunk claiming 2^60 bytes.
  std::vector<uint8_t> bad = bytes;
  size_t chunkLength = readCyHair(bytes).bytesRead + 12 + 4;
  uint64_t huge = uint64_t(1) << 60;
  std::memcpy(&bad[chunkLength], &huge, 8);
  EXPECT_THROW(decodeHair(bad.data(), bad.size(), "o.hair"), InputError);
}

// Appends one chunk of a newer hairgen (tag, payload) to a file's block, with a correct CRC.
std::vector<uint8_t> withChunk(std::vector<uint8_t> bytes, const char tag[4],
                               const std::vector<uint8_t>& payload) {
  const size_t block = readCyHair(bytes).bytesRead;
  uint32_t count = 0;
  std::memcpy(&count, &bytes[block + 8], 4);
  ++count;
  std::memcpy(&bytes[block + 8], &count, 4);
  std::vector<uint8_t> chunk(tag, tag + 4);
  const uint64_t length = payload.size();
  for (int i = 0; i < 8; ++i) chunk.push_back(uint8_t(length >> (8 * i)));
  chunk.insert(chunk.end(), payload.begin(), payload.end());
  const uint32_t crc = uint32_t(crc32(0L, chunk.data(), uInt(chunk.size())));
  for (int i = 0; i < 4; ++i) chunk.push_back(uint8_t(crc >> (8 * i)));
  bytes.insert(bytes.end(), chunk.begin(), chunk.end());
  return bytes;
}

TEST(HairFile, ChunksOfANewerHairgenAreCheckedThenSkippedEmptyOnesToo) {
  const Strands s = test::sampleStrands(3);
  for (size_t length : {0, 1, 100}) {
    const std::vector<uint8_t> bytes = withChunk(encodeHair(s), "NEWC", std::vector<uint8_t>(length, 7));
    HairHeader header;
    EXPECT_EQ(decodeHair(bytes.data(), bytes.size(), "n.hair", &header), s) << length << " bytes";
    EXPECT_EQ(header.chunks.back(), "NEWC");
  }
}

TEST(HairFile, AFileOfManyChunksIsRefusedAtOnceAndTagsAreShownEscaped) {
  std::vector<uint8_t> bytes = withChunk(encodeHair(test::sampleStrands(2)), "\x01\x1b[X", {});
  HairHeader header;
  decodeHair(bytes.data(), bytes.size(), "e.hair", &header);
  EXPECT_EQ(header.chunks.back(), "\\x01\\x1b[X");
  // A block that declares four billion chunks is refused from its count, not after comparing each.
  const size_t block = readCyHair(bytes).bytesRead;
  const uint32_t many = 0xffffffffu;
  std::memcpy(&bytes[block + 8], &many, 4);
  try {
    decodeHair(bytes.data(), bytes.size(), "m.hair");
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("chunks"), std::string::npos) << e.what();
  }
}

TEST(HairFile, GarbageAfterArraysAndBadMagicAreErrors) {
  std::vector<uint8_t> bytes = encodeHair(test::sampleStrands(2));
  std::vector<uint8_t> trailing = bytes;
  trailing.push_back(0);
  EXPECT_THROW(decodeHair(trailing.data(), trailing.size(), "g.hair"), InputError);
  std::vector<uint8_t> magic = bytes;
  magic[0] = 'X';
  EXPECT_THROW(decodeHair(magic.data(), magic.size(), "g.hair"), InputError);
}

TEST(HairFile, ErrorsNameTheFile) {
  std::vector<uint8_t> bytes = encodeHair(test::sampleStrands(2));
  try {
    decodeHair(bytes.data(), 100, "named.hair");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("named.hair: truncated", 0), 0u) << e.what();
    EXPECT_EQ(e.code(), ExitCode::kBadInput);
  }
}

TEST(HairFile, RealCyHairFilesRead) {
  if (!std::filesystem::exists(test::realData())) GTEST_SKIP() << "shared/testdata/real is absent";
  Strands straight = readHair(test::realData() / "luxcore" / "straight.hair");  // no segments array
  EXPECT_EQ(straight.strandCount(), 10000u);
  EXPECT_EQ(straight.pointCount(), 160000u);
  Strands bangs = readHair(test::realData() / "hairutil" / "Bangs_100.hair");  // a segments array
  EXPECT_EQ(bangs.strandCount(), 100u);
}

// Strands of `pointsEach` points each (plus one more on every other strand when `uneven`), with
// tangents.
Strands largeStrands(size_t strands, uint32_t pointsEach, bool uneven) {
  Strands s;
  for (size_t i = 0; i < strands; ++i) {
    const uint32_t n = pointsEach + (uneven && i % 2 ? 1 : 0);
    for (uint32_t k = 0; k < n; ++k)
      s.points.push_back(glm::vec3(0.001f * float(i), 0.002f * float(k), 0.5f));
    s.firstPoint.push_back(uint32_t(s.points.size()));
  }
  s.tangents = polylineTangents(s);
  return s;
}

// What /proc/self/smaps says of the mapping that holds `address`: its file (empty for memory of the
// process's own) and its resident KiB.
struct MappedAt {
  std::string file;
  long residentKiB = 0;
};
MappedAt mappingAt(const void* address) {
  std::ifstream smaps("/proc/self/smaps");
  const uintptr_t at = reinterpret_cast<uintptr_t>(address);
  std::string line;
  bool inside = false;
  MappedAt found;
  while (std::getline(smaps, line)) {
    unsigned long begin = 0, end = 0;  // a mapping's first line: "BEGIN-END perms offset dev inode path"
    if (std::sscanf(line.c_str(), "%lx-%lx", &begin, &end) == 2 && line.find('-') < line.find(' ')) {
      if (inside) break;
      inside = at >= begin && at < end;
      if (inside) {
        const size_t slash = line.find('/');
        found.file = slash == std::string::npos ? "" : line.substr(slash);
      }
      continue;
    }
    if (inside && line.rfind("Rss:", 0) == 0) found.residentKiB = std::atol(line.c_str() + 4);
  }
  return found;
}

// The render reads a coupe where the file's pages lie: the same strands as a copy, its points and
// tangents the file's own pages, the tangents not the process's until they are read, and a write to
// them the process's alone.
TEST(HairFile, AMappedReadHoldsTheFilesPagesAndWritesNoneOfThem) {
  test::TempDir dir("mapped");
  const std::filesystem::path file = dir / "coupe.hair";
  writeHair(file, largeStrands(20000, 50, false));  // 12 MB of points, 12 MB of tangents
  const std::vector<uint8_t> bytes = readFileBytes(file);
  const Strands copied = readHair(file);
  Strands mapped = readHair(file, nullptr, ArrayStorage::kMapped);
  // Resident: the points (validate() read them), not the tangents, until they are read.
  const long arrayKiB = long(mapped.points.size() * sizeof(glm::vec3) / 1024);
  const long before = mappingAt(mapped.points.data()).residentKiB;
  EXPECT_LT(before, arrayKiB + arrayKiB / 4);
  test::expectSameStrands(mapped, copied);
  EXPECT_GT(mappingAt(mapped.points.data()).residentKiB, before + arrayKiB - arrayKiB / 4);
  const std::string mappedFile = std::filesystem::canonical(file).string();  // as smaps names it
  EXPECT_EQ(mappingAt(mapped.points.data()).file, mappedFile);
  EXPECT_EQ(mappingAt(mapped.tangents.data()).file, mappedFile);
  EXPECT_EQ(mappingAt(copied.points.data()).file, "");
  // A copy is memory of its own; a write changes the process's page, never the file.
  const Strands copy = mapped;
  EXPECT_EQ(mappingAt(copy.points.data()).file, "");
  mapped.points[0] = glm::vec3(9.0f);
  mapped.tangents.back() = glm::vec3(0.0f, 0.0f, 1.0f);
  EXPECT_EQ(readFileBytes(file), bytes);
  EXPECT_EQ(copy.points[0], copied.points[0]);
  const void* where = mapped.points.data();
  mapped = Strands{};  // the mapping goes with its last array
  EXPECT_EQ(mappingAt(where).file, "");
  EXPECT_EQ(readHair(file, nullptr, ArrayStorage::kMapped), copied);
}

// Where the points do not lie on a float's boundary (an odd number of strands of unequal lengths: a
// 2-byte segment count each before them), a mapped read copies them, and reads the same strands.
TEST(HairFile, AMappedReadCopiesArraysTheFileDoesNotAlign) {
  test::TempDir dir("unaligned");
  const std::filesystem::path file = dir / "uneven.hair";
  writeHair(file, largeStrands(20001, 50, true));
  const Strands mapped = readHair(file, nullptr, ArrayStorage::kMapped);
  EXPECT_EQ(mapped, readHair(file));
  EXPECT_EQ(mappingAt(mapped.points.data()).file, "");
  EXPECT_EQ(mappingAt(mapped.tangents.data()).file, "");
}

// A coupe of 20,000 strands written in `dir` and read back where its file's pages lie, with the
// mapping guard a command installs: its file, and its strands.
struct MappedCoupe {
  std::filesystem::path file;
  Strands strands;
};
MappedCoupe mapCoupe(const test::TempDir& dir) {
  installMappingGuard();
  MappedCoupe c{dir / "coupe.hair", {}};
  writeHair(c.file, largeStrands(20000, 50, false));
  c.strands = readHair(c.file, nullptr, ArrayStorage::kMapped);
  return c;
}

// A mapped coupe another process shrinks under the render: its pages past the new end read as zeros (no
// SIGBUS ends the process), and the command's check fails it with the file's error, exit 2, once.
TEST(HairFile, AMappedFileThatShrinksIsTheFilesErrorNotACrash) {
  test::TempDir dir("shrinks");
  const auto [file, mapped] = mapCoupe(dir);
  EXPECT_NO_THROW(requireMappingsWhole());
  std::filesystem::resize_file(file, 4096);
  EXPECT_EQ(mapped.tangents.back(), glm::vec3(0.0f)) << "past the end: a fault, then zeros";
  EXPECT_EQ(mapped.points.front(), glm::vec3(0.0f)) << "the whole mapping is zeros, no value of the file";
  try {
    requireMappingsWhole();
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.code(), ExitCode::kBadInput);
    EXPECT_EQ(e.where().file, file.string());
    EXPECT_NE(std::string(e.what()).find(kFileShrank), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(requireMappingsWhole()) << "said once";
}

// A sequence keeps each frame it finishes (keepCommittedOutputs), but not one made after a mapped input's
// page could not be read: that frame was made from zeros, and the failed command removes it.
TEST(HairFile, AFrameMadeFromAMappedFileThatShrankIsNotKept) {
  test::TempDir dir("shrinks-kept");
  const auto [file, mapped] = mapCoupe(dir);
  forgetCommittedOutputs();
  writeFileAtomic(dir / "beauty.0001.exr", std::string("made from the file"));
  keepCommittedOutputs();
  std::filesystem::resize_file(file, 4096);
  ASSERT_EQ(mapped.tangents.back(), glm::vec3(0.0f));
  writeFileAtomic(dir / "beauty.0002.exr", std::string("made from zeros"));
  EXPECT_THROW(keepCommittedOutputs(), InputError);
  discardCommittedOutputs();  // as a failed command does
  EXPECT_TRUE(std::filesystem::exists(dir / "beauty.0001.exr"));
  EXPECT_FALSE(std::filesystem::exists(dir / "beauty.0002.exr"));
}

// A page that cannot be read where the file is no shorter by the check (here truncated and written back
// to its length, as cp over it does; or an I/O error) is an IoError, exit 1, which a retry may mend.
TEST(HairFile, AMappedPageThatCannotBeReadOtherwiseIsAnIoError) {
  test::TempDir dir("unreadable");
  const auto [file, mapped] = mapCoupe(dir);
  const uintmax_t size = std::filesystem::file_size(file);
  std::filesystem::resize_file(file, 4096);
  EXPECT_EQ(mapped.tangents.back(), glm::vec3(0.0f));
  std::filesystem::resize_file(file, size);
  try {
    requireMappingsWhole();
    ADD_FAILURE() << "no error";
  } catch (const IoError& e) {
    EXPECT_EQ(e.code(), ExitCode::kWorkFailed);
    EXPECT_NE(std::string(e.what()).find(kPageUnreadable), std::string::npos) << e.what();
  }
}

// A SIGBUS that is no fault of a mapping (sent with kill) gets the default action: the process ends.
TEST(HairFileDeathTest, ASigbusSentIsNotTakenForAMappingsFault) {
  const std::string style = GTEST_FLAG_GET(death_test_style);
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(
      {
        installMappingGuard();
        std::raise(SIGBUS);
        std::exit(0);
      },
      ::testing::KilledBySignal(SIGBUS), "");
  GTEST_FLAG_SET(death_test_style, style);
}

// The large arrays a cache is read into grow as resize grows them: the old values kept, the new ones
// zero, past the 8 MiB at which their pages are asked for in 2 MiB and faulted in on every core.
TEST(HugePages, ResizeLargeKeepsValuesAndZeroesTheRest) {
  std::vector<glm::vec3> v = {{1.0f, 2.0f, 3.0f}, {4.0f, 5.0f, 6.0f}};
  const size_t n = (size_t(20) << 20) / sizeof(glm::vec3) + 7;  // 20 MiB, not a whole number of pages
  resizeLarge(v, n);
  ASSERT_EQ(v.size(), n);
  EXPECT_EQ(v[0], glm::vec3(1.0f, 2.0f, 3.0f));
  EXPECT_EQ(v[1], glm::vec3(4.0f, 5.0f, 6.0f));
  size_t nonZero = 0;
  for (size_t i = 2; i < n; ++i) nonZero += v[i] != glm::vec3(0.0f);
  EXPECT_EQ(nonZero, 0u);
  v[n - 1] = glm::vec3(7.0f);
  resizeLarge(v, 3);  // shrinking keeps the first ones
  EXPECT_EQ(v.size(), 3u);
  EXPECT_EQ(v[1], glm::vec3(4.0f, 5.0f, 6.0f));
  resizeLarge(v, n);  // and growing within the capacity zeroes what comes back
  EXPECT_EQ(v[n - 1], glm::vec3(0.0f));
}

// Storage grown with room to spare holds that many more, so a reuse that needs a little more keeps it:
// the values kept, the new ones zero.
TEST(HugePages, ResizeLargeWithRoomToSpareKeepsItsStorageForALittleMore) {
  std::vector<uint32_t> v = {5, 6};
  const size_t n = (size_t(12) << 20) / sizeof(uint32_t) + 3;
  resizeLarge(v, n, n / 8);
  ASSERT_EQ(v.size(), n);
  EXPECT_GE(v.capacity(), n + n / 8);
  EXPECT_EQ(v[1], 6u);
  const uint32_t* storage = v.data();
  v[n - 1] = 9;
  v.clear();
  resizeLarge(v, n + n / 10);
  EXPECT_EQ(v.data(), storage);
  EXPECT_EQ(v[n - 1], 0u);
  EXPECT_EQ(v.back(), 0u);
}

}  // namespace
}  // namespace hairgen
