// The attacks of the hardening review, each kept as a test of the class of bug it found: wrapped
// extents, files read from outside a glTF's folder, images sized by their header, outputs that replaced
// devices and links, stale temporaries, runaway estimates, text as editors write it, non-UTF-8 JSON.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fstream>
#include <random>
#include <set>
#include <thread>

#include <nlohmann/json.hpp>

#include "libcore/config/keys.h"
#include "libcore/io/exr_io.h"
#include "libcore/io/gltf_io.h"
#include "libcore/io/hair_cache.h"
#include "libcore/io/info.h"
#include "libcore/io/obj_io.h"
#include "libcore/util/checked.h"
#include "libcore/util/file_util.h"
#include "libcore/util/json.h"
#include "stages/interpolate.h"
#include "stages/preflight/estimate.h"
#include "tests/test_util.h"

namespace hairgen {
namespace {

namespace fs = std::filesystem;

std::string inputError(const std::function<void()>& fn) {
  try {
    fn();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected an InputError";
  return {};
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

void spit(const fs::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
}

// --------------------------------------------------------------------------------------------- extents

TEST(Hardening, ExtentsAreCheckedInExactArithmetic) {
  EXPECT_TRUE(extentFits(0, 10, 12, 12, 120));
  EXPECT_FALSE(extentFits(0, 11, 12, 12, 120));
  EXPECT_TRUE(extentFits(7, 0, 12, 12, 0));
  // 2^62 elements 4 bytes apart wrap a 64-bit product to a small number.
  EXPECT_FALSE(extentFits(0, 1ull << 62, 4, 4, 1024));
  EXPECT_FALSE(extentFits(UINT64_MAX - 2, 1, 4, 4, UINT64_MAX));
}

// A glTF whose accessor claims 2^62 elements: the bounds check used to wrap and read past the buffer.
TEST(Hardening, AGltfAccessorCountNear2To62IsRefused) {
  std::vector<uint8_t> json = encodeGltf(test::sampleStrands(3), false);
  nlohmann::json doc = nlohmann::json::parse(json.begin(), json.end());
  for (auto& accessor : doc["accessors"]) accessor["count"] = uint64_t(1) << 62;
  const std::string text = doc.dump();
  std::string m =
      inputError([&] { decodeGltf(reinterpret_cast<const uint8_t*>(text.data()), text.size(), "x.gltf"); });
  EXPECT_NE(m.find("reaches past the end"), std::string::npos) << m;
}

// extras nested 20,000 deep (42 KB): tinygltf converts extras by recursion, and overflowed the stack. A
// glTF is refused past 256 levels; a DCC's extras nested a few deep still read (and quotes and
// escapes inside strings are not nesting).
TEST(Hardening, AGltfNestedPastAnyGltfIsRefusedNotACrash) {
  std::vector<uint8_t> json = encodeGltf(test::sampleStrands(3), false);
  nlohmann::json doc = nlohmann::json::parse(json.begin(), json.end());
  doc["extras"] = nlohmann::json::parse(R"({"a": [[{"b": "x[[{\"\\"}]]})");
  std::string text = doc.dump();
  EXPECT_EQ(decodeGltf(reinterpret_cast<const uint8_t*>(text.data()), text.size(), "x.gltf").strandCount(),
            3u);
  doc.erase("extras");
  text = doc.dump();
  text.insert(1, "\"extras\": " + std::string(20000, '[') + std::string(20000, ']') + ", ");
  std::string m =
      inputError([&] { decodeGltf(reinterpret_cast<const uint8_t*>(text.data()), text.size(), "x.gltf"); });
  EXPECT_NE(m.find("nests arrays and objects 20001 deep"), std::string::npos) << m;
}

// info files a .usda layer's entries by name: 150,000 of them in its hairgen dictionary took a minute.
// A layer holding more than hairgen ever writes is not hairgen's.
TEST(Hardening, AUsdaLayerWithThousandsOfEntriesIsRefusedAtOnce) {
  test::TempDir dir("hardening");
  const fs::path file = dir.path() / "hair.usda";
  writeStrands(file, test::sampleStrands(3));
  EXPECT_TRUE(describeFile(file).contains("strands"));
  std::string text = slurp(file);
  const size_t at = text.find("string producer");
  ASSERT_NE(at, std::string::npos);
  std::string many;
  for (int i = 0; i < 100000; ++i) many += "string k" + std::to_string(i) + " = \"v\"\n";
  text.insert(at, many);
  spit(file, text);
  const std::string m = inputError([&] { describeFile(file); });
  EXPECT_NE(m.find("holds 100"), std::string::npos) << m;
}

// --------------------------------------------------------------------------------------- glTF's folder

TEST(Hardening, AGltfReadsOnlyFilesInItsOwnFolder) {
  test::TempDir dir("hardening");
  const fs::path sub = dir.path() / "sub";
  fs::create_directories(sub / "folder");
  std::vector<uint8_t> json = encodeGltf(test::sampleStrands(3), false);
  nlohmann::json doc = nlohmann::json::parse(json.begin(), json.end());
  spit(dir.path() / "secret.txt", "not hair");
  ::symlink((dir.path() / "secret.txt").c_str(), (sub / "link.bin").c_str());
  ::mkfifo((sub / "pipe.bin").c_str(), 0600);
  for (const char* uri : {"/etc/passwd", "../secret.txt", "%2e%2e/secret.txt", "folder", "link.bin",
                          "pipe.bin", "file:///etc/passwd", "missing.bin"}) {
    doc["buffers"][0]["uri"] = uri;
    const std::string text = doc.dump();
    const fs::path file = sub / "hair.gltf";
    spit(file, text);
    std::string m = inputError([&] { readGltf(file); });
    EXPECT_NE(m.find(std::string("URI '") + uri + "' is refused"), std::string::npos) << m;
  }
  // Read from memory there is no folder: an external buffer is refused, whatever it names.
  doc["buffers"][0]["uri"] = "buffer.bin";
  const std::string text = doc.dump();
  EXPECT_THROW(decodeGltf(reinterpret_cast<const uint8_t*>(text.data()), text.size(), "x.gltf"), InputError);
}

// --------------------------------------------------------------------------------------------- images

TEST(Hardening, AnImageIsSizedBeforeItIsAllocated) {
  test::TempDir dir("hardening");
  // Noise, so that compression leaves the file long enough to hold the offset table of the size it
  // will claim: OpenEXR then gets as far as the header's data window.
  Image small;
  small.width = small.height = 128;
  small.channels = {"R", "G", "B", "A"};
  std::mt19937 rng(1);
  for (int c = 0; c < 4; ++c) {
    small.planes.emplace_back(128 * 128);
    for (float& v : small.planes.back()) v = float(rng() % 1000) / 1000.0f;
  }
  const fs::path file = dir.path() / "small.exr";
  writeExr(file, small, {});
  // The same file, its header claiming 30000 x 30000 pixels: kilobytes asking for gigabytes.
  std::string bytes = slurp(file);
  for (const std::string key : {"dataWindow", "displayWindow"}) {
    const size_t at = bytes.find(key + std::string("\0box2i\0", 7));
    ASSERT_NE(at, std::string::npos);
    const int32_t window[4] = {0, 0, 29999, 29999};
    std::memcpy(&bytes[at + key.size() + 7 + 4], window, sizeof window);
  }
  spit(dir.path() / "huge.exr", bytes);
  std::string m = inputError([&] { readImage(dir.path() / "huge.exr"); });
  EXPECT_NE(m.find("30000x30000"), std::string::npos) << m;
}

// --------------------------------------------------------------------------------------------- outputs

// A link named as an output is replaced by the file, as mv replaces it: nothing is written through it
// (test_outputs.cpp has the attacks this closes).
TEST(Hardening, AWriteToALinkReplacesTheLinkNotItsFile) {
  test::TempDir dir("hardening");
  ::symlink("target.json", (dir.path() / "link.json").c_str());  // dangling
  writeFileAtomic(dir.path() / "link.json", std::string("{}\n"));
  EXPECT_FALSE(fs::is_symlink(dir.path() / "link.json"));
  EXPECT_EQ(slurp(dir.path() / "link.json"), "{}\n");
  EXPECT_FALSE(fs::exists(dir.path() / "target.json"));
}

TEST(Hardening, AWriteToAFifoGoesIntoItAndLeavesItAFifo) {
  test::TempDir dir("hardening");
  const fs::path fifo = dir.path() / "stats.json";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::string received;
  std::thread reader([&] { received = slurp(fifo); });
  writeFileAtomic(fifo, std::string("{\"ok\": true}\n"));
  reader.join();
  EXPECT_EQ(received, "{\"ok\": true}\n");
  struct stat st {};
  ASSERT_EQ(::lstat(fifo.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));
}

// --stats /dev/stdout with stdout appended to a farm log: the log keeps what was before and gets what
// comes after, and stays the same file (reopening it by name, or replacing it, would lose both).
TEST(Hardening, AWriteToAnOpenDescriptorGoesThroughItAtItsOffset) {
  test::TempDir dir("hardening");
  const fs::path log = dir.path() / "farm.log";
  const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  ASSERT_GE(fd, 0);
  struct stat before {};
  ASSERT_EQ(::fstat(fd, &before), 0);
  auto append = [&](const std::string& text) {
    ASSERT_EQ(::write(fd, text.data(), text.size()), ssize_t(text.size()));
  };
  append("earlier\n");
  writeFileAtomic("/dev/fd/" + std::to_string(fd), std::string("{\"a\": 1}\n"));
  writeThroughTemporary("/proc/self/fd/" + std::to_string(fd),
                        [](const fs::path& file) { spit(file, std::string("{\"b\": 2}\n")); });
  append("later\n");
  ::close(fd);
  EXPECT_EQ(slurp(log), "earlier\n{\"a\": 1}\n{\"b\": 2}\nlater\n");
  struct stat after {};
  ASSERT_EQ(::stat(log.c_str(), &after), 0);
  EXPECT_EQ(after.st_ino, before.st_ino);
  for (const fs::path& left : fs::directory_iterator(dir.path())) EXPECT_EQ(left.filename(), "farm.log");
}

TEST(Hardening, AWriteErrorIsAnIoError) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  EXPECT_THROW(writeFileAtomic("/dev/full", std::string(1 << 16, 'x')), IoError);
  EXPECT_TRUE(fs::is_character_file("/dev/full"));
}

TEST(Hardening, ADirectoryIsNotAnOutput) {
  test::TempDir dir("hardening");
  EXPECT_THROW(writeFileAtomic(dir.path(), std::string("x")), InputError);
}

TEST(Hardening, TemporariesOfDeadProcessesAreSweptAndLiveOnesKept) {
  test::TempDir dir("hardening");
  char host[256] = {};
  ::gethostname(host, sizeof host - 1);
  std::string name = host;
  for (char& c : name)
    if (c == '-' || c == '/') c = '_';
  // A PID above the kernel's maximum never runs; our own PID does.
  const fs::path dead = dir.path() / ("coupe.hair.tmp-" + name + "-99999999-0");
  const fs::path live = dir.path() / ("coupe.hair.tmp-" + name + "-" + std::to_string(::getpid()) + "-99");
  const fs::path foreign = dir.path() / "coupe.hair.tmp-otherhost-99999999-0";
  for (const fs::path& p : {dead, live, foreign}) spit(p, "partial");
  writeFileAtomic(dir.path() / "coupe.hair", std::string("whole"));
  EXPECT_FALSE(fs::exists(dead));
  EXPECT_TRUE(fs::exists(live));
  EXPECT_TRUE(fs::exists(foreign));  // another host's process may still be writing
}

TEST(Hardening, AFailedCommandsCommittedOutputsCanBeDiscarded) {
  test::TempDir dir("hardening");
  forgetCommittedOutputs();
  writeFileAtomic(dir.path() / "image.exr", std::string("pixels"));
  writeFileAtomic(dir.path() / "guides.json", std::string("{}"));
  discardCommittedOutputs();
  EXPECT_FALSE(fs::exists(dir.path() / "image.exr"));
  EXPECT_FALSE(fs::exists(dir.path() / "guides.json"));
}

// What a failed command wrote over is put back, whatever it was: a file (its own input), a link; what
// it wrote under a new name is removed; a command that keeps its outputs leaves no backup behind.
TEST(Hardening, AFailedCommandPutsBackWhatItWroteOver) {
  test::TempDir dir("hardening");
  const fs::path input = dir.path() / "coupe.hair", link = dir.path() / "link.json",
                 fresh = dir.path() / "new.exr", notes = dir.path() / "notes.txt";
  spit(input, "the user's coupe");
  spit(notes, "notes");
  ASSERT_EQ(::symlink("notes.txt", link.c_str()), 0);
  struct stat before {};
  ASSERT_EQ(::stat(input.c_str(), &before), 0);
  forgetCommittedOutputs();
  writeFileAtomic(input, std::string("written over"));
  writeFileAtomic(link, std::string("{}"));
  writeThroughTemporary(fresh, [](const fs::path& file) { spit(file, "pixels"); });
  EXPECT_EQ(slurp(input), "written over");
  discardCommittedOutputs();
  EXPECT_EQ(slurp(input), "the user's coupe");
  struct stat after {};
  ASSERT_EQ(::stat(input.c_str(), &after), 0);
  EXPECT_EQ(after.st_ino, before.st_ino);  // the very file, renamed back
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(fs::read_symlink(link), "notes.txt");
  EXPECT_EQ(slurp(notes), "notes");
  EXPECT_FALSE(fs::exists(fresh));
  std::set<std::string> left;
  for (const fs::path& p : fs::directory_iterator(dir.path())) left.insert(p.filename().string());
  EXPECT_EQ(left, (std::set<std::string>{"coupe.hair", "link.json", "notes.txt"}));
  // The same name written twice by one command (an in-place sequence's shared --stats, say): the first
  // file is put back, then what was there before both.
  writeFileAtomic(input, std::string("first"));
  writeFileAtomic(input, std::string("second"));
  discardCommittedOutputs();
  EXPECT_EQ(slurp(input), "the user's coupe");
  // Kept: the new file stays and no backup is left beside it.
  writeFileAtomic(input, std::string("kept"));
  keepCommittedOutputs();
  discardCommittedOutputs();
  EXPECT_EQ(slurp(input), "kept");
  left.clear();
  for (const fs::path& p : fs::directory_iterator(dir.path())) left.insert(p.filename().string());
  EXPECT_EQ(left, (std::set<std::string>{"coupe.hair", "link.json", "notes.txt"}));
  forgetCommittedOutputs();
}

// A library opens its file by name: the file lies in a folder of this process's own (mode 0700), held
// open and named to the library through its descriptor (/proc/PID/fd/N/NAME), so no one can swap the
// file, or the folder, for a link between its creation and the library's opening it; the folder is gone
// after, and a name near the 255-byte limit of a folder entry is written as any other.
TEST(Hardening, AWriteByNameIsInAPrivateFolder) {
  test::TempDir dir("hardening");
  const fs::path target = dir.path() / (std::string(250, 'x') + ".exr");
  writeThroughTemporary(target, [&](const fs::path& file) {
    struct stat st {};
    ASSERT_EQ(::stat(file.parent_path().c_str(), &st), 0);
    EXPECT_TRUE(S_ISDIR(st.st_mode));
    EXPECT_EQ(st.st_mode & 0777, 0700u);
    EXPECT_EQ(st.st_uid, ::geteuid());
    EXPECT_EQ(fs::read_symlink(file.parent_path()).parent_path(), dir.path());
    EXPECT_EQ(file.filename(), target.filename());  // the extension a library may choose its format by
    spit(file, "pixels");
  });
  EXPECT_EQ(slurp(target), "pixels");
  writeFileAtomic(dir.path() / (std::string(248, 'y') + ".hair"), std::string("strands"));
  size_t entries = 0;
  for ([[maybe_unused]] const fs::path& p : fs::directory_iterator(dir.path())) ++entries;
  EXPECT_EQ(entries, 2u);  // no private folder left
}

// The review's attack: while the library writes, someone renames the private folder away and puts a link
// to a user's folder at its name. Nothing reaches the user's folder: the write, the rename into place
// and the cleanup all go through the folder's descriptor.
TEST(Hardening, AFolderSwappedForALinkDuringAWriteByNameTouchesNothingBehindIt) {
  test::TempDir dir("hardening");
  const fs::path victim = dir.path() / "victim", target = dir.path() / "beauty.exr";
  fs::create_directories(victim);
  spit(victim / "notes.txt", "notes");
  spit(victim / "beauty.exr", "the user's");
  writeThroughTemporary(target, [&](const fs::path& file) {
    const fs::path folder = fs::read_symlink(file.parent_path());
    fs::rename(folder, dir.path() / "aside");
    fs::create_directory_symlink(victim, folder);
    spit(file, "pixels");
  });
  EXPECT_EQ(slurp(target), "pixels");
  EXPECT_EQ(slurp(victim / "notes.txt"), "notes");
  EXPECT_EQ(slurp(victim / "beauty.exr"), "the user's");
}

// ---------------------------------------------------------------------------------------------- inputs

TEST(Hardening, AFifoNamedAsAnInputIsRefusedNotWaitedOn) {
  test::TempDir dir("hardening");
  const fs::path fifo = dir.path() / "setup.txt";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::string m = inputError([&] { readConfigText(fifo); });
  EXPECT_NE(m.find("not a regular file"), std::string::npos) << m;
  EXPECT_THROW(readObj(fifo), InputError);
}

TEST(Hardening, TextAsEditorsWriteIt) {
  // A byte-order mark, CRLF and a lone CR (old Mac) line end.
  Hairstyle h = readHairstyle(test::text("\xEF\xBB\xBFHairLengths 0.04\r\nHairDensity 90\rClump 0.5\n"), {});
  EXPECT_EQ(h.hairDensity, 90.0);
  EXPECT_EQ(h.clump, 0.5);
  Mesh m = parseObj("\xEF\xBB\xBFv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "bom.obj");
  EXPECT_EQ(m.vertexCount(), 3u);
  // A lone CR ends the comment: the validator sees the vertex that tinyobjloader would read.
  std::string err =
      inputError([] { parseObj("v 0 0 0\nv 1 0 0\nv 0 1 0\n# x\rv nan nan nan\nf 1 2 3\n", "cr.obj"); });
  EXPECT_NE(err.find("cr.obj:5:"), std::string::npos) << err;
}

TEST(Hardening, JsonOfBytesThatAreNotUtf8IsWrittenNotThrown) {
  nlohmann::ordered_json doc = {{"provenance", std::string("made by \xff\xfe")}};
  std::string text;
  EXPECT_NO_THROW(text = jsonText(doc));
  EXPECT_NE(text.find("\xEF\xBF\xBD"), std::string::npos);  // U+FFFD
}

// ---------------------------------------------------------------------------------------- estimates

TEST(Hardening, AbsurdConfigsAreRefusedBeforeTheWork) {
  Hairstyle style;
  style.hairLengths = {0.04, 0.04, 0.04, 0.04};
  Collision head;
  head.shapes.push_back(
      {ShapeKind::kEllipsoid, 0.0, 10.0, glm::dvec3(0), glm::dvec3(0.1), glm::dmat3(1), {}});
  EXPECT_NO_THROW(requireFits(estimateGrow(style, head, 759, 2), false));
  Hairstyle fine = style;
  fine.collisionStep = 1e-9;
  EXPECT_NE(inputError([&] { requireFits(estimateGrow(fine, head, 759, 2), false); }).find("CollisionStep"),
            std::string::npos);
  fine = style;
  fine.visualityStep = 1e-9;
  EXPECT_NE(inputError([&] { requireFits(estimateGrow(fine, head, 759, 2), true); }).find("VisualityStep"),
            std::string::npos);
  // A guide of more points than a .hair cache holds is refused before it is grown, even with --force
  // (16 cm at 2 µm: 80,001 points; it was grown for seconds, then not written).
  fine = style;
  fine.visualityStep = 2e-6;
  EXPECT_NE(
      inputError([&] { requireFits(estimateGrow(fine, head, 1, 2), true); }).find("holds at most 65536"),
      std::string::npos);
  fine = style;
  fine.hairLengths.assign(256, 0.000625);
  EXPECT_NE(inputError([&] { requireFits(estimateGrow(fine, head, 759, 2), false); }).find("--force"),
            std::string::npos);
  EXPECT_NO_THROW(requireFits(estimateGrow(fine, head, 759, 2), true));  // --force runs it
  // BFGS takes tens of gradients a guide, each two walks along the rod: 256 elements on 759 follicles is
  // estimated at three minutes (32 s measured); on a million follicles, days.
  fine.minimiser = Minimiser::kBfgs;
  EXPECT_NO_THROW(requireFits(estimateGrow(fine, head, 759, 2), false));
  EXPECT_NE(inputError([&] { requireFits(estimateGrow(fine, head, 1000000, 2), false); }).find("--force"),
            std::string::npos);
  fine.hairLengths.assign(8, 0.02);  // the default coupe's: well within
  EXPECT_NO_THROW(requireFits(estimateGrow(fine, head, 759, 2), false));
  fine = style;
  fine.hairDensity = 1e20;
  EXPECT_NE(
      inputError([&] { requireFits(estimateInterpolate(fine, 700.0, 1443, 65), true); }).find("HairDensity"),
      std::string::npos);
  RenderSettings render;
  render.voxelSize = 1e-6;
  EXPECT_NE(inputError([&] {
              requireFits(estimateShade(render, 1000, 64000, glm::dvec3(0.3)), true);
            }).find("VoxelSize"),
            std::string::npos);
  render = {};
  render.resolution = {16384, 16384};
  render.samples = 4;
  EXPECT_THROW(requireFits(estimateRender(render, 50000, 3200000, 31696, 0.5, 0.2, 0.16, 16384), true),
               InputError);
  // A float-to-integer conversion before the overflow guard used to give a bald coupe.
  EXPECT_EQ(strandsInTriangle(1.0, 1e20, 0.5), std::numeric_limits<uint32_t>::max());
}

}  // namespace
}  // namespace hairgen
