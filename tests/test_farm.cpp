// Shards, their merge and the farm plan: ranges that tile, provenance that round-trips, a merge that
// gives back the whole and refuses parts that do not belong together, and plans whose tasks run in order.
#include <gtest/gtest.h>

#include <chrono>
#include <climits>
#include <fstream>
#include <functional>
#include <set>

#include "farm/done.h"
#include "farm/plan.h"
#include "farm/scheduler.h"
#include "libcore/io/hair_io.h"
#include "libcore/model/shards.h"
#include "libcore/util/error.h"
#include "libcore/util/resources.h"
#include "stages/interpolate.h"
#include "tests/test_util.h"

namespace hairgen {
namespace {

TEST(Shards, RangesTileTheWhole) {
  for (uint64_t total : {0ull, 1ull, 3ull, 759ull, 1443ull})
    for (uint32_t count : {1u, 2u, 4u, 7u, 1000u}) {
      uint64_t next = 0;
      for (uint32_t k = 1; k <= count; ++k) {
        const ShardRange r = shardRange(k, count, total);
        EXPECT_EQ(r.first, next) << k << "/" << count << " of " << total;
        EXPECT_LE(r.first, r.end);
        next = r.end;
      }
      EXPECT_EQ(next, total);
    }
}

TEST(Shards, SpecIsKOfN) {
  EXPECT_EQ(parseShardSpec("2/4", "--shard").index, 2u);
  EXPECT_EQ(parseShardSpec("4/4", "--shard").count, 4u);
  for (const char* bad : {"0/4", "5/4", "1/0", "3", "a/b", "1/4x", "-1/4", "/4", "1/"})
    EXPECT_THROW(parseShardSpec(bad, "--shard"), InputError) << bad;
}

TEST(Shards, ProvenanceRoundTripsAndWholeFilesKeepTheirText) {
  Provenance p = madeByHairgen("interpolate", 7, "0123456789abcdef");
  const std::string whole = provenanceText(p);
  EXPECT_EQ(whole.find("shard"), std::string::npos);
  p.shard = shardRange(3, 4, 1443);
  const Provenance back = parseProvenance(provenanceText(p), "test");
  ASSERT_TRUE(back.shard);
  EXPECT_EQ(*back.shard, *p.shard);
  EXPECT_EQ(back, p);
  EXPECT_THROW(parseProvenance("shard=5/4\n", "test"), InputError);
  EXPECT_THROW(parseProvenance("range=9-3/10\n", "test"), InputError);
}

// A small coupe from the default Setup, interpolated whole and in shards.
struct Coupe {
  test::Job job = test::loadJob("default/setup.txt", SetupUse::kInterpolate);
  Strands guides, whole;
  Coupe() {
    job.config.hairstyle.hairDensity = 5;
    guides.provenance = madeByHairgen("grow", 1, job.config.digest());
    for (size_t i = 0; i < job.wick.vertexCount(); ++i) {
      const glm::vec3 p = job.wick.positions[i], n = job.wick.normals[i];
      guides.addStrand({p, p + 0.01f * n, p + 0.02f * n});
      guides.strandId.push_back(uint32_t(i));
    }
    whole = interpolate(job.wick, guides, job.config.hairstyle, job.config.collision, options({}));
  }
  InterpolateOptions options(std::optional<ShardRange> shard) const {
    InterpolateOptions o;
    o.configDigest = job.config.digest();
    o.shard = shard;
    return o;
  }
  std::vector<ShardPart> shards(uint32_t count) const {
    std::vector<ShardPart> parts;
    for (uint32_t k = 1; k <= count; ++k)
      parts.push_back({"part" + std::to_string(k),
                       interpolate(job.wick, guides, job.config.hairstyle, job.config.collision,
                                   options(shardRange(k, count, job.wick.triangles.size())))});
    return parts;
  }
};

TEST(Shards, InterpolatedShardsMergeIntoTheWholeInAnyOrder) {
  const Coupe c;
  std::vector<ShardPart> parts = c.shards(4);
  std::swap(parts[0], parts[3]);
  const Strands merged = mergeShards(parts);
  EXPECT_EQ(encodeHair(merged), encodeHair(c.whole));
  // Strand ids are global: every id of a shard is the whole run's id at that place.
  std::set<uint32_t> ids(c.whole.strandId.begin(), c.whole.strandId.end());
  for (const ShardPart& p : parts)
    for (uint32_t id : p.strands.strandId) EXPECT_TRUE(ids.count(id));
}

TEST(Shards, MergeRefusesPartsThatDoNotBelong) {
  const Coupe c;
  std::vector<ShardPart> parts = c.shards(3);
  auto refused = [](std::vector<ShardPart> p, const std::string& culprit) {
    try {
      mergeShards(std::move(p));
      ADD_FAILURE() << "merged";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(culprit), std::string::npos) << e.what();
    }
  };
  refused({parts[0], parts[2]}, "part3");                         // a hole before part 3
  refused({parts[0], parts[1]}, "after part2");                   // the last range missing
  refused({parts[0], parts[1], parts[1], parts[2]}, "overlaps");  // a part twice
  std::vector<ShardPart> foreign = parts;
  foreign[1].strands.provenance.configDigest = "ffffffffffffffff";
  foreign[1].name = "foreign";
  refused(foreign, "foreign");
  refused({{"whole", c.whole}}, "whole");
}

TEST(Shards, ProvenanceAloneIsReadWithoutTheArrays) {
  test::TempDir dir("shards");
  const Coupe c;
  Strands part = c.shards(2)[1].strands;
  writeHair(dir.path() / "p.hair", part);
  EXPECT_EQ(readHairProvenance(dir.path() / "p.hair"), part.provenance);
  EXPECT_EQ(readHairProvenance(dir.path() / "p.hair"), readHair(dir.path() / "p.hair").provenance);
}

// A farm asks whether a task's coupe is done by its provenance alone (farm/done.cpp), so a file larger
// than the memory free for reading it whole is no reason to redo the task. (Here the file grows with a
// hole past its chunks: nothing is written, and the reader stops at the PROV chunk.)
TEST(Shards, ProvenanceIsReadFromAFileLargerThanTheMemoryBudget) {
  test::TempDir dir("shards");
  const Coupe c;
  Strands part = c.shards(2)[1].strands;
  const std::filesystem::path file = dir.path() / "p.hair";
  writeHair(file, part);
  std::filesystem::resize_file(file, memoryBudget() + (uint64_t(1) << 20));
  try {
    (void)readHair(file);
    ADD_FAILURE() << "read whole, it is not refused";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("of memory this machine has free"), std::string::npos) << e.what();
  }
  EXPECT_EQ(readHairProvenance(file), part.provenance);
}

TEST(FarmPlan, EveryTaskComesAfterWhatItReads) {
  for (const char* setup : {"default/setup.txt", "anjyo/gust/setup.txt"}) {
    const test::Job job = test::loadJob(setup, SetupUse::kRun);
    FarmPlanOptions options;
    options.hairgen = "/usr/bin/hairgen";
    options.setup = "/s/setup.txt";
    options.directory = "/d";
    options.shards = 3;
    options.chunk = 7;
    const FarmPlan plan = planFarm(job.config, job.wick, options);
    std::set<std::string> done, outputs;
    for (const FarmTask& t : plan.tasks) {
      for (const std::string& d : t.deps) EXPECT_TRUE(done.count(d)) << t.id << " runs before " << d;
      for (const std::string& o : t.outputs) EXPECT_TRUE(outputs.insert(o).second) << o << " written twice";
      EXPECT_GE(t.cpus, 1);
      EXPECT_GT(t.memoryMiB, 0u);
      done.insert(t.id);
    }
    const FarmPlan back = farmPlanFromJson(toJson(plan), "plan");
    EXPECT_EQ(toJson(back), toJson(plan));
    if (job.config.dynamics.given) {
      const int frames = job.config.dynamics.lastFrame - job.config.dynamics.firstFrame + 1;
      EXPECT_TRUE(done.count("render." + std::to_string((frames + 6) / 7)));
      EXPECT_FALSE(done.count("render." + std::to_string((frames + 6) / 7 + 1)));
    }
  }
}

// A 152-byte file whose one chunk declares 2^64-16 bytes: the reader must stop at the file's end, not
// seek back onto the chunk's header and read it again for each of the 2^32-1 chunks declared.
TEST(Shards, ProvenanceReaderBoundsEverySeekByTheFileSize) {
  test::TempDir dir("provenance");
  std::string bytes = "HAIR";
  auto u32 = [&](uint32_t v) {
    for (int i = 0; i < 4; ++i) bytes += char(v >> (8 * i));
  };
  for (uint32_t v : {0u, 0u, 2u, 0u}) u32(v);  // no strands, no points, flag 2 (points)
  bytes.resize(128, '\0');
  bytes += "HGEN";
  u32(1);
  u32(0xFFFFFFFFu);
  bytes += "XXXX";
  u32(0xFFFFFFF0u);
  u32(0xFFFFFFFFu);
  ASSERT_EQ(bytes.size(), 152u);
  const auto file = dir.path() / "huge-chunk.hair";
  std::ofstream(file, std::ios::binary) << bytes;
  const auto start = std::chrono::steady_clock::now();
  EXPECT_THROW(readHairProvenance(file), InputError);
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(1));
  // Arrays declared past the end are refused too, rather than taken for a file without chunks.
  bytes.replace(8, 4, std::string("\xff\xff\xff\x0f", 4));
  std::ofstream(file, std::ios::binary) << bytes;
  EXPECT_THROW(readHairProvenance(file), InputError);
}

FarmPlan stillPlan(int shards = 2) {
  const test::Job job = test::loadJob("default/setup.txt", SetupUse::kRun);
  FarmPlanOptions options;
  options.hairgen = "/usr/bin/hairgen";
  options.setup = "/s/setup.txt";
  options.directory = "/d";
  options.shards = shards;
  return planFarm(job.config, job.wick, options);
}

// Refused with an InputError whose message holds `culprit` (the task, the field).
void expectRefused(const std::function<void()>& read, const std::string& culprit) {
  try {
    read();
    ADD_FAILURE() << "accepted; expected a refusal naming " << culprit;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(culprit), std::string::npos) << e.what();
  }
}

TEST(FarmPlan, ReadingRefusesWhatCouldReachAShellOrLeaveTheFolder) {
  const nlohmann::ordered_json good = toJson(stillPlan());
  ASSERT_NO_THROW(farmPlanFromJson(good, "plan.json"));
  using Edit = std::function<void(nlohmann::ordered_json&)>;
  auto renameGrow1 = [](const std::string& id) {
    return Edit([id](nlohmann::ordered_json& j) {
      j["tasks"][0]["id"] = id;
      for (auto& t : j["tasks"])
        for (auto& d : t["deps"])
          if (d == "grow.1") d = id;
    });
  };
  const std::vector<std::pair<Edit, std::string>> attacks = {
      {renameGrow1("grow.1$(touch /tmp/x)"), "its id is neither"},
      {renameGrow1("grow.01"), "its id is neither"},
      {renameGrow1("grow.1001"), "its id is neither"},
      {[](auto& j) { j["tasks"][0]["group"] = "../../escaped"; },
       "task \"grow.1\": its group \"../../escaped\""},
      {[](auto& j) { j["tasks"][0]["group"] = "gr--ow"; }, "its group"},
      {[](auto& j) { j["setup"] = "/s/a\ntouch /tmp/x\n/setup.txt"; }, "control character"},
      {[](auto& j) { j["directory"] = "/d\r"; }, "control character"},
      {[](auto& j) { j["directory"] = "/"; }, "its directory"},
      {[](auto& j) { j["tasks"][0]["inputs"][0] = std::string("/s/setup.txt\0", 13); },
       "task \"grow.1\": input"},
      {[](auto& j) { j["tasks"][0]["outputs"][0] = "/etc/passwd"; },
       "task \"grow.1\": output \"/etc/passwd\""},
      {[](auto& j) { j["tasks"][0]["outputs"][0] = "/d/../x.hair"; }, "task \"grow.1\": output"},
      {[](auto& j) { j["tasks"][0]["outputs"][0] = "/d/slurm/grow.sh"; }, "slurm/"},
      {[](auto& j) { j["tasks"][0]["outputs"][0] = "/dx/guides.1.hair"; }, "task \"grow.1\": output"},
      {[](auto& j) { j["tasks"][0]["command"][0] = "/bin/sh"; }, "is not a hairgen executable"},
      {[](auto& j) { j["tasks"][0]["command"][0] = "hairgen"; }, "is not a hairgen executable"},
      {[](auto& j) { j["tasks"][0]["command"][1] = "-c"; }, "its stage"},
      {[](auto& j) { j["tasks"][0]["command"].push_back("--exec"); }, "option \"--exec\""},
      {[](auto& j) { j["tasks"][0]["command"].push_back("/tmp/elsewhere.hair"); }, "command path"},
      {[](auto& j) { j["tasks"][0]["command"].push_back("relative.hair"); }, "command path"},
      {[](auto& j) { j["tasks"][0]["command"].back() = "1; rm -rf ~"; }, "--threads"},
      {[](auto& j) { j["tasks"][0]["cpus"] = 1e300; }, "\"cpus\""},
      {[](auto& j) { j["tasks"][0]["memoryMiB"] = -1; }, "\"memoryMiB\""},
      {[](auto& j) { j["version"] = 1e300; }, "version"},
      {[](auto& j) { j["format"] = 7; }, "not a hairgen farm plan"},
      {[](auto& j) { j["shards"] = 100000; }, "\"shards\""},
      {[](auto& j) { j.erase("chunk"); }, "\"chunk\": "},  // named as itself, not as the field before
      {[](auto& j) {
         j["frames"] = {{"first", INT_MIN}, {"last", INT_MAX}};
       },
       "frames"},
      {[](auto& j) {
         j["overrides"] = {"--exec", "x"};
       },
       "override"},
      {[](auto& j) { j["tasks"][2]["deps"].push_back("grow.1"); }, "twice"},
  };
  for (const auto& [edit, culprit] : attacks) {
    nlohmann::ordered_json j = good;
    edit(j);
    expectRefused([&] { farmPlanFromJson(j, "plan.json"); }, culprit);
    expectRefused([&] { farmPlanFromJson(j, "plan.json"); }, "plan.json");
  }
}

TEST(FarmPlan, MakingRefusesControlCharactersAndBoundsTheSize) {
  const test::Job job = test::loadJob("default/setup.txt", SetupUse::kRun);
  FarmPlanOptions options;
  options.hairgen = "/usr/bin/hairgen";
  options.setup = "/s/setup.txt";
  options.directory = "/d";
  auto refused = [&](FarmPlanOptions o, const std::string& culprit) {
    expectRefused([&] { planFarm(job.config, job.wick, o); }, culprit);
  };
  FarmPlanOptions o = options;
  o.directory = "/d\ntouch /tmp/x\n";
  refused(o, "control character");
  o = options;
  o.setup = "/s\n/setup.txt";
  refused(o, "control character");
  o = options;
  o.hairgen = "/usr/bin/hairgen\x7f";
  refused(o, "control character");
  o = options;
  o.shards = 100000;
  refused(o, "--shards 100000: from 1 to 1000");
  o = options;
  o.chunk = INT_MAX;
  refused(o, "--chunk");
  test::Job shot = test::loadJob("anjyo/gust/setup.txt", SetupUse::kRun);
  shot.config.dynamics.firstFrame = 1;
  shot.config.dynamics.lastFrame = 1000000;
  options.chunk = 1;
  const auto start = std::chrono::steady_clock::now();
  expectRefused([&] { planFarm(shot.config, shot.wick, options); }, "1000000 frames");
  shot.config.dynamics.lastFrame = 5000;
  expectRefused([&] { planFarm(shot.config, shot.wick, options); }, "5000 render tasks");
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(2));
  // At the limits the plan is made, and read back.
  shot.config.dynamics.lastFrame = 1000;
  const FarmPlan plan = planFarm(shot.config, shot.wick, options);
  EXPECT_EQ(toJson(farmPlanFromJson(toJson(plan), "plan.json")), toJson(plan));
}

TEST(FarmPlan, ArrayIndexIsTheIdsNumber) {
  for (const FarmTask& t : stillPlan(3).tasks) {
    const size_t dot = t.id.find('.');
    EXPECT_EQ(farmArrayIndex(t), dot == std::string::npos ? 0 : std::stoi(t.id.substr(dot + 1))) << t.id;
  }
}

// A back end that records what it was asked to submit: the done set is the farm's, not the scheduler's.
class RecordingScheduler : public farm::Scheduler {
 public:
  std::vector<std::string> asked;
  size_t submit(const FarmPlan& plan, const std::vector<bool>& done) override {
    for (size_t i = 0; i < plan.tasks.size(); ++i)
      if (!done[i]) asked.push_back(plan.tasks[i].id);
    return asked.size();
  }
  void wait(const FarmPlan&) override {}
};

TEST(FarmPlan, ABackEndIsAskedOnlyForTasksWhoseOutputsLackThePlansDigest) {
  test::TempDir dir("farm-done");
  const Coupe c;
  FarmPlan plan;
  plan.directory = dir.path().string();
  plan.configDigest = c.job.config.digest();
  Strands stale = c.guides;
  stale.provenance.configDigest = "ffffffffffffffff";
  writeHair(dir.path() / "fresh.hair", c.guides);
  writeHair(dir.path() / "stale.hair", stale);
  std::ofstream(dir.path() / "present.txt") << "x";
  std::ofstream(dir.path() / "garbage.exr") << "not an image";
  auto task = [&](const std::string& id, std::vector<std::string> outputs) {
    FarmTask t;
    t.id = t.group = id;
    for (const std::string& o : outputs) t.outputs.push_back((dir.path() / o).string());
    plan.tasks.push_back(t);
  };
  task("done", {"fresh.hair", "present.txt"});
  task("stale", {"stale.hair"});
  task("missing", {"missing.hair"});
  task("partly", {"fresh.hair", "missing.txt"});
  task("unreadable", {"garbage.exr"});
  task("nothing", {});
  RecordingScheduler scheduler;
  EXPECT_EQ(scheduler.submit(plan, farm::doneTasks(plan)), 4u);
  EXPECT_EQ(scheduler.asked, (std::vector<std::string>{"stale", "missing", "partly", "unreadable"}));
}

}  // namespace
}  // namespace hairgen
