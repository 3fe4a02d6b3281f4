// Merging shards: every per-point and per-strand array is concatenated in range order; the cyHair
// defaults and the provenance (but for its shard) must agree, as they do for shards of one run.
#include "libcore/model/shards.h"

#include <algorithm>
#include <charconv>
#include <limits>

#include "libcore/util/error.h"

namespace hairgen {

ShardSpec parseShardSpec(std::string_view text, const std::string& flag) {
  auto number = [&](std::string_view part, uint32_t& value) {
    auto [end, ec] = std::from_chars(part.data(), part.data() + part.size(), value);
    return !part.empty() && ec == std::errc() && end == part.data() + part.size();
  };
  ShardSpec spec;
  const size_t slash = text.find('/');
  if (slash == std::string_view::npos || !number(text.substr(0, slash), spec.index) ||
      !number(text.substr(slash + 1), spec.count) || spec.index < 1 || spec.index > spec.count)
    throw InputError(flag + " '" + std::string(text) + "': write K/N, shard K of N, with 1 <= K <= N");
  return spec;
}

namespace {

std::string rangeText(const ShardRange& r) {
  return std::to_string(r.first) + "-" + std::to_string(r.end);
}

template <typename T, class A>
void append(std::vector<T, A>& to, const std::vector<T, A>& from, bool wanted) {
  if (wanted) to.insert(to.end(), from.begin(), from.end());
}

}  // namespace

Strands mergeShards(std::vector<ShardPart> parts) {
  if (parts.empty()) throw InputError("no shards to merge");
  for (const ShardPart& p : parts)
    if (!p.strands.provenance.shard || p.strands.provenance.shard->count == 0)
      throw InputError({p.name, 0},
                       "is not a shard (its provenance holds no shard=K/N); merge joins the "
                       "outputs of grow or interpolate --shard K/N");
  std::stable_sort(parts.begin(), parts.end(), [](const ShardPart& a, const ShardPart& b) {
    return a.strands.provenance.shard->first < b.strands.provenance.shard->first;
  });
  const ShardPart& lead = parts.front();
  Provenance whole = lead.strands.provenance;
  whole.shard.reset();
  const ShardRange& leadRange = *lead.strands.provenance.shard;
  const std::string unit = whole.stage == "grow" ? "guides" : "triangles";
  for (const ShardPart& p : parts) {
    Provenance mine = p.strands.provenance;
    const ShardRange r = *mine.shard;
    mine.shard.reset();
    if (mine.configDigest != whole.configDigest || mine.seed != whole.seed)
      throw InputError({p.name, 0}, "comes from another config (digest " + mine.configDigest + ", seed " +
                                        std::to_string(mine.seed) + ") than " + lead.name + " (digest " +
                                        whole.configDigest + ", seed " + std::to_string(whole.seed) + ")");
    if (!(mine == whole))
      throw InputError({p.name, 0}, "is a shard of another stage or run (" + mine.stage + ", " +
                                        mine.producer + ") than " + lead.name + " (" + whole.stage + ", " +
                                        whole.producer + ")");
    if (r.count != leadRange.count || r.total != leadRange.total)
      throw InputError({p.name, 0}, "is shard " + std::to_string(r.index) + "/" + std::to_string(r.count) +
                                        " of " + std::to_string(r.total) + " " + unit + ", but " + lead.name +
                                        " is of " + std::to_string(leadRange.count) + " shards of " +
                                        std::to_string(leadRange.total));
    if (r != shardRange(r.index, r.count, r.total))
      throw InputError({p.name, 0}, "declares shard " + std::to_string(r.index) + "/" +
                                        std::to_string(r.count) + " as " + unit + " " + rangeText(r) +
                                        " of " + std::to_string(r.total) + ", but that shard is " + unit +
                                        " " + rangeText(shardRange(r.index, r.count, r.total)));
    const Strands& s = p.strands;
    // What the part holds must be what its range declares: a guide a strand, and a coupe's strands rooted
    // on the range's triangles.
    if (whole.stage == "grow" && s.strandCount() != r.end - r.first)
      throw InputError({p.name, 0}, "holds " + std::to_string(s.strandCount()) + " strands, but its range " +
                                        rangeText(r) + " declares " + std::to_string(r.end - r.first) +
                                        " guides");
    for (size_t i = 0; i < s.rootTriangle.size(); ++i)
      if (s.rootTriangle[i] < r.first || s.rootTriangle[i] >= r.end)
        throw InputError({p.name, 0}, "strand " + std::to_string(i) + " is rooted on triangle " +
                                          std::to_string(s.rootTriangle[i]) + ", outside its range " +
                                          rangeText(r));
    if (s.defaultThickness != lead.strands.defaultThickness ||
        s.defaultTransparency != lead.strands.defaultTransparency ||
        s.defaultColor != lead.strands.defaultColor)
      throw InputError({p.name, 0}, "has other cyHair defaults than " + lead.name);
    auto same = [&](bool a, bool b) { return a == b; };
    if (!same(s.tangents.empty(), lead.strands.tangents.empty()) ||
        !same(s.normals.empty(), lead.strands.normals.empty()) ||
        !same(s.colors.empty(), lead.strands.colors.empty()) ||
        !same(s.thickness.empty(), lead.strands.thickness.empty()) ||
        !same(s.transparency.empty(), lead.strands.transparency.empty()) ||
        !same(s.strandId.empty(), lead.strands.strandId.empty()) ||
        !same(s.rootTriangle.empty(), lead.strands.rootTriangle.empty()) ||
        !same(s.rootBary.empty(), lead.strands.rootBary.empty()) ||
        !same(s.rootUv.empty(), lead.strands.rootUv.empty()) ||
        !same(s.guideIds.empty(), lead.strands.guideIds.empty()) ||
        !same(s.guideWeights.empty(), lead.strands.guideWeights.empty()) || !s.simulationState.empty())
      throw InputError({p.name, 0}, "holds other arrays than " + lead.name);
  }
  // Ranges in order: each must start where the last ended.
  uint64_t covered = 0;
  const ShardPart* previous = nullptr;
  for (const ShardPart& p : parts) {
    const ShardRange& r = *p.strands.provenance.shard;
    if (r.first < covered)
      throw InputError({p.name, 0}, "overlaps " + previous->name + ": " + unit + " " + rangeText(r) +
                                        " (shard " + std::to_string(r.index) + "/" + std::to_string(r.count) +
                                        ") against " + rangeText(*previous->strands.provenance.shard));
    if (r.first > covered)
      throw InputError("a shard is missing: " + unit + " " + std::to_string(covered) + "-" +
                       std::to_string(r.first) + " of " + std::to_string(r.total) + " are in no part (" +
                       (previous ? "after " + previous->name + ", " : "") + "before " + p.name + ")");
    covered = r.end;
    previous = &p;
  }
  if (covered != leadRange.total)
    throw InputError("a shard is missing: " + unit + " " + std::to_string(covered) + "-" +
                     std::to_string(leadRange.total) + " of " + std::to_string(leadRange.total) +
                     " are in no part (after " + previous->name + ")");

  Strands out;
  out.defaultThickness = lead.strands.defaultThickness;
  out.defaultTransparency = lead.strands.defaultTransparency;
  out.defaultColor = lead.strands.defaultColor;
  out.provenance = whole;
  for (const ShardPart& p : parts) {
    const Strands& s = p.strands;
    const uint64_t base = out.points.size();
    if (base + s.points.size() > std::numeric_limits<uint32_t>::max())
      throw InputError({p.name, 0}, "the merged file would hold more points than 32-bit offsets can");
    for (size_t i = 1; i < s.firstPoint.size(); ++i)
      out.firstPoint.push_back(static_cast<uint32_t>(base + s.firstPoint[i]));
    append(out.points, s.points, true);
    const Strands& l = lead.strands;
    append(out.tangents, s.tangents, !l.tangents.empty());
    append(out.normals, s.normals, !l.normals.empty());
    append(out.colors, s.colors, !l.colors.empty());
    append(out.thickness, s.thickness, !l.thickness.empty());
    append(out.transparency, s.transparency, !l.transparency.empty());
    append(out.strandId, s.strandId, !l.strandId.empty());
    append(out.rootTriangle, s.rootTriangle, !l.rootTriangle.empty());
    append(out.rootBary, s.rootBary, !l.rootBary.empty());
    append(out.rootUv, s.rootUv, !l.rootUv.empty());
    append(out.guideIds, s.guideIds, !l.guideIds.empty());
    append(out.guideWeights, s.guideWeights, !l.guideWeights.empty());
  }
  out.validate("the merged shards");
  return out;
}

}  // namespace hairgen
