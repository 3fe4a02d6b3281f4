// The interpolate stage: a full coupe from the guides, filling every wick triangle with strands blended
// from the guides at its corners, clumped toward the nearest guide at the tips, with the thesis' stray
// hairs (Lansink 2010 §4.1.4.3-4.1.4.4, DESIGN §2 and §5).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "libcore/config/params.h"
#include "libcore/model/mesh.h"
#include "libcore/model/strands.h"
#include "libcore/util/progress.h"

namespace hairgen {

struct InterpolateOptions {
  std::string configDigest;      // recorded in the coupe's provenance
  std::string guidesName;        // names the guides in error messages
  Progress* progress = nullptr;  // advanced once per triangle
  bool force = false;            // run work estimated to take absurdly long (never work that cannot fit)
  // A frame of a sequence: the head's pose at it. The guides' roots are checked against the posed wick
  // and stray hairs scale about the posed head centre; counts, roots and weights come from the wick as
  // given, so every frame has the same strands, ids and weights as the rest frame (DESIGN §8).
  glm::dmat4 pose{1.0};
  // Fill only wick triangles [first, end) (`interpolate --shard K/N`), recorded in the provenance. Every
  // random number is keyed by (seed, triangle, strand in it), so a shard's strands, ids and weights are
  // those of the whole run and `hairgen merge` of the shards gives the whole file.
  std::optional<ShardRange> shard{};
};

// Fills every wick triangle. Guide i must be the one grown from wick vertex i. The coupe is ordered by
// triangle, then by strand index k within it; strand k of triangle t has id k·T + t (T triangles), so
// ids are stable when the density changes and the strands with id < m·T are the first m of every
// triangle. Deterministic for any thread count. Throws InputError when the guides do not fit the wick.
Strands interpolate(const Mesh& wick, const Strands& guides, const Hairstyle& style,
                    const Collision& collision, const InterpolateOptions& options);

// The same coupe written into `coupe`, which is overwritten whatever it held (its arrays that
// interpolate does not fill are emptied) and compares equal to what interpolate() returns. Its arrays
// keep their storage: the frames of a sequence interpolated into one Strands touch no new memory after
// the first (a fresh 150,000 × 64 coupe is ~230 MB of pages the kernel must fault in and clear, and that
// the vectors then fill with zeros before the blend writes them). Left unspecified when it throws.
void interpolateInto(const Mesh& wick, const Strands& guides, const Hairstyle& style,
                     const Collision& collision, const InterpolateOptions& options, Strands& coupe);

// The pieces, for tests.

// Strands in a triangle of `areaCm2`: area × density, the fraction rounded up when u < fraction. For a
// fixed u the count never decreases as the density grows.
uint32_t strandsInTriangle(double areaCm2, double density, double u);

// Uniform root barycentrics from two uniforms in [0, 1): a pair past the diagonal is reflected back.
glm::dvec3 rootWeights(double u1, double u2);

// Tip barycentrics (§4.1.4.3): v1, v2 drawn in [0, Clump), folded when their sum passes 1, v3 = 1 − v1
// − v2 for the corner nearest the root. `strayHairs` assigns v1 and v2 to the other two corners by the
// thesis' conditions (its Table 4: in half the orderings v1 lands on both and the sum is not 1);
// otherwise the next corner after the nearest (A→B→C→A) takes v1 and the one after takes v2.
glm::dvec3 tipWeights(const glm::dvec3& root, double v1, double v2, bool strayHairs);

// The three guides of one triangle, read once for all its strands, and the blend of each strand from
// them: n vertices, weights from `root` at vertex 0 to `tip` at vertex n − 1, positions blended about
// `centre` (a weight sum K ≠ 1 scales the blend about it, §4.1.4.4), tangents blended and renormalised.
// prepare() keeps each guide vertex's offset from the centre and its tangent in double, one array per
// component, so blend() runs across vertices in vector registers with the arithmetic of one vertex at a
// time (the same operations in the same order, so the same bits). Reuse one object per thread: its
// arrays keep their capacity, and blending a strand allocates nothing.
struct GuideSpan {
  const glm::vec3* points;
  const glm::vec3* tangents;
};
class TriangleBlend {
 public:
  // The spans must outlive the blends (a tangent that cancels takes the heaviest guide's).
  void prepare(const GuideSpan (&guides)[3], uint32_t n, const glm::dvec3& centre);
  // Writes points[0, n) and tangents[0, n).
  void blend(const glm::dvec3& root, const glm::dvec3& tip, glm::vec3* points, glm::vec3* tangents);

 private:
  GuideSpan guides_[3]{};
  uint32_t n_ = 0;
  glm::dvec3 centre_{0.0};
  std::vector<double> soa_;  // 19 arrays of n: per guide its offsets x, y, z and tangents x, y, z; i/(n−1)
  std::vector<double> lengths_;  // |t| of the strand's vertices, before renormalising
};

// The head centre the stray hairs scale about: the centre of headShape(collision) (params.h),
// or the origin (the thesis puts its origin at the head centre).
glm::dvec3 strayCentre(const Collision& collision);

}  // namespace hairgen
