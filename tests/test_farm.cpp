// Shards, their merge and the farm plan: ranges that tile, provenance that round-trips, a merge that
// gives back the whole and refuses parts that do not belong together, and plans whose tasks run in order.
#include <gtest/gtest.h>

#include <set>

#include "libcore/io/hair_io.h"
#include "libcore/model/shards.h"
#include "libcore/util/error.h"
#include "stages/farm_plan.h"
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

}  // namespace
}  // namespace hairgen
