// grow: follicle frames (§4.1.4.1), minimisation of each guide's energy from its rest shape by
// Rosenbrock's search (§4.1.3) or BFGS on its gradient (Minimiser bfgs), then sampling of the
// Super-Helix every VisualityStep (§4.1.4.2); or, for Model cantilever, Anjyo's beams bent from each wick
// vertex (libcore/physics/cantilever.h).
#include "stages/grow.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "libcore/physics/cantilever.h"
#include "libcore/util/error.h"
#include "stages/preflight/estimate.h"

namespace hairgen {

GuideReport growGuide(const RodFrame& root, double envelope, const Hairstyle& style,
                      const Collision& collision) {
  StrandEnergy energy(style, collision, root, envelope);
  const std::vector<double> q0 = energy.restCoordinates();
  bool finite = true;
  auto checked = [&](double e) {
    if (std::isfinite(e)) return e;
    finite = false;
    return HUGE_VAL;
  };
  MinimiserResult result;
  if (style.minimiser == Minimiser::kBfgs) {
    QuasiNewtonOptions options;
    // MaxIter per coordinate; a search takes 1-2 evaluations, so twice the iterations bounds them.
    const int64_t iterations = std::min<int64_t>(int64_t(style.maxIter) * int64_t(q0.size()), INT_MAX / 4);
    options.maxIterations = static_cast<int>(iterations);
    options.maxEvaluations = static_cast<int>(2 * iterations + 40);
    // The penalties' second derivatives jump wherever a sample crosses a shape's envelope, so BFGS's
    // model predicts far less decrease than is left while samples still cross: stopping at Epsilon's
    // bar left 520 of coupe 3's 759 guides above Rosenbrock's minima by more than 1% of the energy
    // scale, at a tenth of it 203, at a hundredth 1 (README, Minimiser).
    options.tolerance = 1e-2 * style.epsilon * energy.energyScale();
    auto f = [&](std::span<const double> q, std::span<double> gradient) {
      return checked(energy.valueAndGradient(q, gradient));
    };
    std::vector<double> maxStep = energy.initialSteps();
    for (double& step : maxStep) step *= 4.0;  // a radian of bend or twist over an element
    result = minimizeQuasiNewton(f, q0, energy.inverseStiffness(), maxStep, options);
  } else {
    RosenbrockOptions options;
    options.maxStages = style.maxIter;
    options.epsilon = style.epsilon;
    options.energyScale = energy.energyScale();
    auto f = [&](std::span<const double> q) { return checked(energy(q)); };
    result = minimizeRosenbrock(f, q0, energy.initialSteps(), options);
  }
  GuideReport report;
  report.coordinates = result.x;
  report.start = energy.terms(q0);
  report.end = energy.terms(result.x);
  report.stages = result.stages;
  report.evaluations = result.evaluations;
  report.stop = result.stop;
  if (!finite || !std::isfinite(report.start.total()) || !std::isfinite(report.end.total()))
    throw NumericError("the energy is not finite for this guide");
  return report;
}

std::vector<double> follicleEnvelopes(const Mesh& wick) {
  std::vector<double> out(wick.vertexCount(), 0.0);
  if (out.empty()) return out;
  const Bounds box = bounds(wick.positions);
  if (box.max.y > box.min.y)
    for (size_t i = 0; i < out.size(); ++i)
      out[i] = (double(wick.positions[i].y) - box.min.y) / (double(box.max.y) - box.min.y);
  return out;
}

GrowResult grow(const Mesh& wick, const Hairstyle& style, const Collision& collision,
                const GrowOptions& options) {
  const size_t count = wick.vertexCount();
  if (count == 0) throw InputError("the wick has no vertices");
  if (style.hairLengths.empty()) throw InputError("HairLengths is empty");
  for (size_t i = 0; i < count; ++i) {
    const glm::vec3& n = wick.normals[i];
    if (!std::isfinite(n.x) || !std::isfinite(n.y) || !std::isfinite(n.z) || glm::length(n) < 1e-6f)
      throw InputError("wick vertex " + std::to_string(i) +
                       " has a zero or non-finite normal; a follicle needs a direction");
  }
  const size_t first = options.shard ? options.shard->first : 0,
               end = options.shard ? options.shard->end : count;
  if (first > end || end > count) throw InputError("the shard's guides lie outside the wick's vertices");
  requireFits(estimateGrow(style, collision, end - first, size_t(tbb::this_task_arena::max_concurrency())),
              options.force);
  if (style.model == StylingModel::kCantilever) return growCantilever(wick, style, collision, options);
  const std::vector<double> envelopes = follicleEnvelopes(wick);
  GrowResult result;
  result.reports.resize(end - first);
  std::vector<std::string> failures(end - first);
  tbb::parallel_for(first, end, [&](size_t i) {
    const double envelope = envelopes[i];
    const glm::dvec3 rootPos(wick.positions[i]);
    RodFrame root = follicleFrame(rootPos, style.growDirection(rootPos, glm::dvec3(wick.normals[i])));
    try {
      result.reports[i - first] = growGuide(root, envelope, style, collision);
      result.reports[i - first].follicle = static_cast<uint32_t>(i);
    } catch (const NumericError& e) {
      failures[i - first] = e.what();
    }
    if (options.progress) options.progress->advance();
  });
  if (options.progress) options.progress->finish();
  for (size_t i = first; i < end; ++i)
    if (!failures[i - first].empty())
      throw NumericError("guide " + std::to_string(i) + ": " + failures[i - first]);

  // Sample every guide; fixed order, so the output is the same for any thread count.
  const std::vector<double> s = sampleArcLengths(style.totalLength(), style.visualityStep, true);
  Strands& guides = result.guides;
  guides.points.reserve((end - first) * s.size());
  guides.tangents.reserve((end - first) * s.size());
  std::vector<glm::dvec3> positions, tangents;
  for (size_t i = first; i < end; ++i) {
    const GuideReport& report = result.reports[i - first];
    const glm::dvec3 rootPos(wick.positions[i]);
    RodFrame root = follicleFrame(rootPos, style.growDirection(rootPos, glm::dvec3(wick.normals[i])));
    sampleRod(root, style.hairLengths, report.coordinates, s, positions, &tangents);
    for (size_t k = 0; k < s.size(); ++k) {
      guides.points.push_back(glm::vec3(positions[k]));
      guides.tangents.push_back(glm::vec3(tangents[k]));
    }
    guides.firstPoint.push_back(static_cast<uint32_t>(guides.points.size()));
    guides.strandId.push_back(static_cast<uint32_t>(i));
    result.evaluations += report.evaluations;
  }
  guides.defaultThickness = static_cast<float>(style.hairRadius1 + style.hairRadius2);  // a diameter
  guides.provenance = madeByHairgen("grow", style.seed, options.configDigest);
  guides.provenance.shard = options.shard;
  return result;
}

GrowResult growCantilever(const Mesh& wick, const Hairstyle& style, const Collision& collision,
                          const GrowOptions& options) {
  const size_t count = wick.vertexCount();
  const size_t first = options.shard ? options.shard->first : 0,
               end = options.shard ? options.shard->end : count;
  const CollisionShape* head = headShape(collision);  // a Sphere head is an ellipsoid of equal semi-axes
  std::vector<std::vector<glm::dvec3>> hairs(end - first);
  tbb::parallel_for(first, end, [&](size_t i) {
    std::vector<glm::dvec3>& hair = hairs[i - first];
    const glm::dvec3 rootPos(wick.positions[i]);
    hair = bendHair(rootPos, style.growDirection(rootPos, glm::dvec3(wick.normals[i])), style, head);
    cutHair(hair, style, head);
    if (options.progress) options.progress->advance();
  });
  if (options.progress) options.progress->finish();

  GrowResult result;
  result.reports.resize(end - first);
  Strands& guides = result.guides;
  for (size_t i = first; i < end; ++i) {
    const std::vector<glm::dvec3>& h = hairs[i - first];
    for (size_t n = 0; n < h.size(); ++n) {
      if (!std::isfinite(h[n].x) || !std::isfinite(h[n].y) || !std::isfinite(h[n].z))
        throw NumericError("hair " + std::to_string(i) + " has a non-finite node");
      guides.points.push_back(glm::vec3(h[n]));
      glm::dvec3 t = h.size() < 2
                         ? style.growDirection(glm::dvec3(wick.positions[i]), glm::dvec3(wick.normals[i]))
                         : (n + 1 < h.size() ? h[n + 1] - h[n] : h[n] - h[n - 1]);
      guides.tangents.push_back(glm::vec3(glm::normalize(t)));
    }
    guides.firstPoint.push_back(static_cast<uint32_t>(guides.points.size()));
    guides.strandId.push_back(static_cast<uint32_t>(i));
    result.reports[i - first].follicle = static_cast<uint32_t>(i);
    result.reports[i - first].stop = MinimiserStop::kEpsilon;
  }
  guides.defaultThickness = static_cast<float>(style.hairRadius1 + style.hairRadius2);
  guides.provenance = madeByHairgen("grow", style.seed, options.configDigest);
  guides.provenance.shard = options.shard;
  return result;
}

}  // namespace hairgen
