// Outputs under attack (issue 32): a cleanup removes only the files this process made, a link named as
// an output is replaced and never written through, and a frame pattern numbers frames at any width.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fstream>
#include <sstream>

#include "libcore/util/error.h"
#include "libcore/util/file_util.h"
#include "libcore/util/frames.h"
#include "libcore/util/signal_slots.h"
#include "tests/test_util.h"

namespace hairgen {
namespace {

namespace fs = std::filesystem;

std::string readText(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

void writeText(const fs::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
}

// ---------------------------------------------------------------------------------------- frame names

TEST(Outputs, AFramePatternOfAnyWidthGivesEachFrameItsOwnName) {
  const std::string wide(40, '#');
  EXPECT_EQ(framePath("c." + wide + ".hair", 7).filename().string(), "c." + std::string(39, '0') + "7.hair");
  EXPECT_NE(framePath("c." + wide + ".hair", 7), framePath("c." + wide + ".hair", 8));
  EXPECT_EQ(framePath("c.%040d.hair", 12).filename().string(), "c." + std::string(38, '0') + "12.hair");
  // The width counts a negative frame's sign; a number wider than the placeholder is written whole.
  EXPECT_EQ(framePath("c.####.hair", -5).filename().string(), "c.-005.hair");
  EXPECT_EQ(framePath("c.##.hair", 12345).filename().string(), "c.12345.hair");
  EXPECT_EQ(framePath("c.%d.hair", -12).filename().string(), "c.-12.hair");
}

TEST(Outputs, AFrameNameLongerThanAFileNameCanBeIsRefused) {
  EXPECT_THROW(framePath("c." + std::string(300, '#') + ".hair", 1), InputError);
  EXPECT_THROW(framePath("c.%0999999999999999999999d.hair", 1), InputError);  // no overflow on the way
}

// ------------------------------------------------------------------------------------------ links

TEST(Outputs, ALinkNamedAsTheOutputIsReplacedAndItsFileKept) {
  test::TempDir dir("outputs");
  writeText(dir / "notes.txt", "the user's");
  ASSERT_EQ(::symlink((dir / "notes.txt").c_str(), (dir / "link.json").c_str()), 0);
  writeFileAtomic(dir / "link.json", std::string("{}\n"));
  EXPECT_FALSE(fs::is_symlink(dir / "link.json"));
  EXPECT_EQ(readText(dir / "link.json"), "{}\n");
  EXPECT_EQ(readText(dir / "notes.txt"), "the user's");
  // Through a library that writes by name, the same.
  ASSERT_EQ(::symlink((dir / "notes.txt").c_str(), (dir / "link.exr").c_str()), 0);
  writeThroughTemporary(dir / "link.exr", [](const fs::path& file) { writeText(file, "pixels"); });
  EXPECT_FALSE(fs::is_symlink(dir / "link.exr"));
  EXPECT_EQ(readText(dir / "notes.txt"), "the user's");
}

TEST(Outputs, ADanglingLinkMakesNoFolder) {
  test::TempDir dir("outputs");
  ASSERT_EQ(::symlink((dir / "nowhere/deeper/x.hair").c_str(), (dir / "frame.hair").c_str()), 0);
  writeFileAtomic(dir / "frame.hair", std::string("hair"));
  EXPECT_FALSE(fs::exists(dir / "nowhere"));
  EXPECT_EQ(readText(dir / "frame.hair"), "hair");
  // A folder on the way that is a link to nowhere is refused, before and while writing.
  ASSERT_EQ(::symlink((dir / "nowhere/sim").c_str(), (dir / "sim").c_str()), 0);
  EXPECT_THROW(requireWritableOutput(dir / "sim/g.0001.hair"), InputError);
  EXPECT_THROW(writeFileAtomic(dir / "sim/g.0001.hair", std::string("hair")), IoError);
  EXPECT_THROW(createOutputFolder(dir / "sim/deeper"), InputError);
  EXPECT_FALSE(fs::exists(dir / "nowhere"));
}

// ---------------------------------------------------------------------------------------- cleanup

TEST(Outputs, ACleanupRemovesOnlyTheFilesThisProcessMade) {
  test::TempDir dir("outputs");
  forgetCommittedOutputs();
  writeFileAtomic(dir / "a.hair", std::string("ours"));
  writeFileAtomic(dir / "b.hair", std::string("ours"));
  writeFileAtomic(dir / "c.hair", std::string("ours"));
  // Since committed, a name has been taken by someone else's file, another by a link to a user's file.
  writeText(dir / "theirs", "someone else's");
  fs::rename(dir / "theirs", dir / "a.hair");
  writeText(dir / "notes.txt", "the user's");
  fs::remove(dir / "b.hair");
  ASSERT_EQ(::symlink((dir / "notes.txt").c_str(), (dir / "b.hair").c_str()), 0);
  discardCommittedOutputs();
  EXPECT_EQ(readText(dir / "a.hair"), "someone else's");
  EXPECT_TRUE(fs::is_symlink(dir / "b.hair"));
  EXPECT_EQ(readText(dir / "notes.txt"), "the user's");
  EXPECT_FALSE(fs::exists(dir / "c.hair"));
}

TEST(Outputs, KeptOutputsSurviveALaterFailure) {
  test::TempDir dir("outputs");
  forgetCommittedOutputs();
  writeFileAtomic(dir / "g.0001.hair", std::string("frame 1"));
  keepCommittedOutputs();
  writeFileAtomic(dir / "g.0002.hair", std::string("frame 2"));
  keepCommittedOutputs();
  writeFileAtomic(dir / "beauty.0003.exr", std::string("half a frame"));
  discardCommittedOutputs();
  EXPECT_EQ(readText(dir / "g.0001.hair"), "frame 1");
  EXPECT_EQ(readText(dir / "g.0002.hair"), "frame 2");
  EXPECT_FALSE(fs::exists(dir / "beauty.0003.exr"));
  // What stays is what --stats of the failed command lists.
  const std::vector<fs::path> kept = committedOutputs();
  ASSERT_EQ(kept.size(), 2u);
  EXPECT_EQ(kept[1], dir / "g.0002.hair");
  forgetCommittedOutputs();
}

TEST(Outputs, AFailedWriteRemovesOnlyItsOwnTemporary) {
  test::TempDir dir("outputs");
  writeText(dir / "g.hair", "before");
  EXPECT_THROW(writeThroughTemporary(dir / "g.hair", [](const fs::path&) { throw IoError("disk gone"); }),
               IoError);
  EXPECT_EQ(readText(dir / "g.hair"), "before");
  for (const fs::path& left : fs::directory_iterator(dir.path())) EXPECT_EQ(left.filename(), "g.hair");
}

// The table a signal handler reads (signal_slots.h): a slot being filled is passed by until it is live,
// a released one is free again, and a full table says so rather than growing.
TEST(SignalSlots, OnlyLiveSlotsAreReadAndAFullTableSaysSo) {
  SignalSlots<int, 3> table;
  const int a = table.claim(), b = table.claim(), c = table.claim();
  ASSERT_TRUE(a >= 0 && b >= 0 && c >= 0);
  EXPECT_EQ(table.claim(), -1) << "full";
  table[a] = 1, table[b] = 2, table[c] = 3;
  table.markLive(a);
  table.markLive(c);
  int sum = 0;
  table.forEachLive([&](int v) { sum += v; });
  EXPECT_EQ(sum, 4) << "the slot being filled is passed by";
  EXPECT_EQ(table.findLive([](int v) { return v == 2; }), nullptr);
  table.markLive(b);
  ASSERT_NE(table.findLive([](int v) { return v == 2; }), nullptr);
  table.release(b);
  EXPECT_EQ(table.findLive([](int v) { return v == 2; }), nullptr) << "released";
  EXPECT_EQ(table.claim(), b) << "a released slot is free again";
  table.release(-1);  // a table that was full gave −1: releasing it does nothing
  table.markLive(-1);
}

}  // namespace
}  // namespace hairgen
