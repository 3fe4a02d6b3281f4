// Shards of a split stage (`grow --shard K/N`, `interpolate --shard K/N`, DESIGN §8) and their merge
// into the file the single run writes, byte for byte.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "libcore/model/strands.h"

namespace hairgen {

// "K/N" with 1 <= K <= N as {index K, count N}. Throws InputError naming `flag`.
struct ShardSpec {
  uint32_t index = 0, count = 0;
};
ShardSpec parseShardSpec(std::string_view text, const std::string& flag);

// One part to merge and the name its messages use (its file).
struct ShardPart {
  std::string name;
  Strands strands;
};

// Joins the shards of one stage into the whole file: parts in any order; strands concatenated in range
// order, offsets rebased, the shard dropped from the provenance. Throws InputError naming the culprit
// when a part is not a shard, comes from another stage, config, seed or split (a different N or total),
// overlaps another, or when a range is missing.
Strands mergeShards(std::vector<ShardPart> parts);

}  // namespace hairgen
