#include "libcore/model/strands.h"

#include <bit>
#include <cmath>
#include <type_traits>

#include "libcore/util/error.h"

namespace hairgen {
namespace {

bool finite(float v) {
  return std::isfinite(v);
}
bool finite(double v) {
  return std::isfinite(v);
}
bool finite(const glm::vec3& v) {
  return finite(v.x) && finite(v.y) && finite(v.z);
}

// Whether any value of an array of floats or doubles is not finite (all exponent bits set), without a
// branch per value so that it vectorises: a cache's arrays are checked at memory speed.
template <typename T, class A>
bool anyNonFinite(const std::vector<T, A>& values) {
  if constexpr (std::is_same_v<T, uint32_t> || std::is_same_v<T, glm::uvec3>) {
    return false;
  } else {
    using Scalar = std::conditional_t<std::is_same_v<T, double>, double, float>;
    using Bits = std::conditional_t<std::is_same_v<T, double>, uint64_t, uint32_t>;
    constexpr Bits exponent = std::is_same_v<T, double> ? Bits(0x7ff0000000000000ull) : Bits(0x7f800000u);
    static_assert(sizeof(T) % sizeof(Scalar) == 0);
    const size_t n = values.size() * (sizeof(T) / sizeof(Scalar));
    const auto* scalars = reinterpret_cast<const Scalar*>(values.data());
    Bits bad = 0;
    for (size_t i = 0; i < n; ++i) {
      const Bits b = std::bit_cast<Bits>(scalars[i]);
      bad |= Bits((b & exponent) == exponent);
    }
    return bad != 0;
  }
}

template <typename T>
bool finiteEntry(const T& v) {
  if constexpr (std::is_same_v<T, uint32_t> || std::is_same_v<T, glm::uvec3>)
    return true;
  else if constexpr (std::is_same_v<T, glm::vec2>)
    return finite(v.x) && finite(v.y);
  else
    return finite(v);
}

template <class T, class A>
void checkArray(const std::string& source, const char* name, const std::vector<T, A>& values,
                size_t expected) {
  if (values.empty()) return;
  if (values.size() != expected)
    throw InputError({source, 0}, std::string(name) + " has " + std::to_string(values.size()) +
                                      " entries, expected " + std::to_string(expected));
  if (!anyNonFinite(values)) return;
  for (size_t i = 0; i < values.size(); ++i)
    if (!finiteEntry(values[i]))
      throw InputError({source, 0}, std::string(name) + " entry " + std::to_string(i) + " is not finite");
}

}  // namespace

ShardRange shardRange(uint32_t index, uint32_t count, uint64_t total) {
  ShardRange r;
  r.index = index;
  r.count = count;
  r.total = total;
  r.first = (index - 1) * total / count;
  r.end = index * total / count;
  return r;
}

Provenance madeByHairgen(std::string stage, uint64_t seed, std::string configDigest) {
  Provenance p;
  p.producer = "hairgen " HAIRGEN_VERSION;
  p.stage = std::move(stage);
  p.seed = seed;
  p.configDigest = std::move(configDigest);
  return p;
}

void Strands::assignRestKeepingBuffers(const Strands& rest) {
  PointArray keptPoints = std::move(points), keptTangents = std::move(tangents);
  std::vector<double> keptState = std::move(simulationState);
  *this = rest;
  points = std::move(keptPoints);
  tangents = std::move(keptTangents);
  simulationState = std::move(keptState);
  points.resize(rest.firstPoint.back());  // `rest` may hold its attributes only, not its points
  tangents.resize(rest.firstPoint.back());
}

void Strands::addStrand(const std::vector<glm::vec3>& strandPoints) {
  points.insert(points.end(), strandPoints.begin(), strandPoints.end());
  firstPoint.push_back(static_cast<uint32_t>(points.size()));
}

void Strands::validate(const std::string& source) const {
  if (firstPoint.empty() || firstPoint.front() != 0)
    throw InputError({source, 0}, "strand offsets must start at 0");
  for (size_t s = 0; s + 1 < firstPoint.size(); ++s)
    if (firstPoint[s + 1] < firstPoint[s])
      throw InputError({source, 0}, "strand " + std::to_string(s) + " has a negative point count");
  if (firstPoint.back() != points.size())
    throw InputError({source, 0}, "strand offsets cover " + std::to_string(firstPoint.back()) +
                                      " points but there are " + std::to_string(points.size()));
  size_t n = points.size(), s = strandCount();
  checkArray(source, "points", points, n);
  checkArray(source, "tangents", tangents, n);
  checkArray(source, "normals", normals, n);
  checkArray(source, "colors", colors, n);
  checkArray(source, "thickness", thickness, n);
  checkArray(source, "transparency", transparency, n);
  checkArray(source, "strand ids", strandId, s);
  checkArray(source, "root triangles", rootTriangle, s);
  checkArray(source, "root barycentrics", rootBary, s);
  checkArray(source, "root UVs", rootUv, s);
  checkArray(source, "guide ids", guideIds, s);
  checkArray(source, "guide weights", guideWeights, s);
  // The simulation state's layout is its model's, checked where simulate restarts from it.
  checkArray(source, "simulation state", simulationState, simulationState.size());
  if (!std::isfinite(defaultThickness) || !std::isfinite(defaultTransparency) || !finite(defaultColor))
    throw InputError({source, 0}, "header defaults are not finite");
}

Strands keepStrands(const Strands& s, const std::function<bool(size_t strand)>& keep) {
  Strands out;
  std::vector<uint32_t> keptPoints, keptStrands;
  for (size_t i = 0; i < s.strandCount(); ++i) {
    if (!keep(i)) continue;
    keptStrands.push_back(uint32_t(i));
    for (uint32_t p = s.firstPoint[i]; p < s.firstPoint[i + 1]; ++p) keptPoints.push_back(p);
    out.firstPoint.push_back(uint32_t(keptPoints.size()));
  }
  auto pick = [](const auto& from, const std::vector<uint32_t>& at, auto& to) {
    if (from.empty()) return;
    to.resize(at.size());
    for (size_t i = 0; i < at.size(); ++i) to[i] = from[at[i]];
  };
  pick(s.points, keptPoints, out.points);
  pick(s.tangents, keptPoints, out.tangents);
  pick(s.normals, keptPoints, out.normals);
  pick(s.colors, keptPoints, out.colors);
  pick(s.thickness, keptPoints, out.thickness);
  pick(s.transparency, keptPoints, out.transparency);
  pick(s.strandId, keptStrands, out.strandId);
  pick(s.rootTriangle, keptStrands, out.rootTriangle);
  pick(s.rootBary, keptStrands, out.rootBary);
  pick(s.rootUv, keptStrands, out.rootUv);
  pick(s.guideIds, keptStrands, out.guideIds);
  pick(s.guideWeights, keptStrands, out.guideWeights);
  out.defaultThickness = s.defaultThickness;
  out.defaultTransparency = s.defaultTransparency;
  out.defaultColor = s.defaultColor;
  out.provenance = s.provenance;
  return out;
}

size_t onePointStrandCount(const Strands& s) {
  size_t count = 0;
  for (size_t i = 0; i < s.strandCount(); ++i) count += s.pointsOf(i) < 2;
  return count;
}

Strands withoutOnePointStrands(const Strands& s) {
  return keepStrands(s, [&](size_t i) { return s.pointsOf(i) >= 2; });
}

PointArray polylineTangents(const Strands& s) {
  PointArray t(s.pointCount(), glm::vec3(0.0f, 1.0f, 0.0f));
  for (size_t i = 0; i < s.strandCount(); ++i) {
    const uint32_t first = s.firstPoint[i], last = s.firstPoint[i + 1];
    glm::vec3 previous(0.0f, 1.0f, 0.0f);
    for (uint32_t p = first; p < last; ++p) {
      glm::vec3 d = p + 1 < last ? s.points[p + 1] - s.points[p]
                                 : (p > first ? s.points[p] - s.points[p - 1] : previous);
      float len = glm::length(d);
      t[p] = previous = len > 0.0f ? d / len : previous;
    }
  }
  return t;
}

}  // namespace hairgen
