#include "stages/render.h"

#include <algorithm>
#include <cmath>

#include "libcore/model/units.h"
#include "libcore/render/views.h"
#include "libcore/util/error.h"
#include "stages/preflight/estimate.h"
#include "stages/preflight/scene.h"

namespace hairgen {

void conform(Strands& hair, bool zUp, double scale) {
  UnitConversion conversion;
  if (scale != 1.0) conversion.metresPerUnit = scale;
  if (zUp) conversion.upAxis = UpAxis::kZ;
  convertToHairgenFrame(hair, conversion);
}

void frameHair(RenderSettings& r, const Strands& hair) {
  if (hair.points.empty()) return;
  const BoundingSphere sphere = boundingSphere(hair, nullptr);
  const double fov = glm::radians(r.fieldOfView) * std::min(1.0, double(r.resolution.x) / r.resolution.y);
  const double distance = sphere.radius / std::sin(0.5 * fov) * 1.05;
  const glm::dvec3 view = r.cameraPosition - r.cameraTarget, toLight = r.lightPosition - r.cameraTarget;
  const double lightRatio = glm::length(toLight) / std::max(glm::length(view), 1e-9);
  r.cameraTarget = sphere.centre;
  r.cameraPosition = sphere.centre + glm::normalize(view) * distance;
  r.lightPosition = sphere.centre + glm::normalize(toLight) * distance * lightRatio;
}

namespace {

// A strand's colour multiplies its reflectances; far beyond 1 it only overflows the half-float image to
// infinity (and NaN where it meets a zero), so colours are clamped to [0, kMaxHairColor].
constexpr float kMaxHairColor = 1000.0f;

bool colorsInRange(const Strands& hair) {
  for (const glm::vec3& c : hair.colors)
    if (!(glm::all(glm::greaterThanEqual(c, glm::vec3(0.0f))) &&
          glm::all(glm::lessThanEqual(c, glm::vec3(kMaxHairColor)))))
      return false;
  return true;
}

// A rendered image must hold numbers: a non-finite pixel is a bug (or an input the checks missed),
// never something to write into an EXR.
void requireFinite(const Image& image) {
  for (size_t c = 0; c < image.channels.size(); ++c) {
    size_t bad = 0;
    for (float v : image.planes[c]) bad += !std::isfinite(v);
    if (bad)
      throw NumericError("rendering produced " + std::to_string(bad) + " non-finite pixels in channel " +
                         image.channels[c] + "; please report it with the command and inputs");
  }
}

// Hair made elsewhere is conformed in a copy, as is hair with colours past what a pixel can hold;
// hairgen's own is rendered as it is. Returns what to render.
const Strands& conformed(const Strands& hair, const RenderOptions& options, std::optional<Strands>& copy) {
  if (!options.zUp && options.scale == 1.0 && colorsInRange(hair)) return hair;
  copy = hair;
  conform(*copy, options.zUp, options.scale);
  for (glm::vec3& c : copy->colors) c = glm::clamp(c, glm::vec3(0.0f), glm::vec3(kMaxHairColor));
  return *copy;
}

}  // namespace

bool sameStrands(const Strands& a, const Strands& b) {
  return a.firstPoint == b.firstPoint && a.points.size() == b.points.size() &&
         (a.strandId.empty() || b.strandId.empty() || a.strandId == b.strandId);
}

RenderOutput render(GlContext& gl, const Strands& hair, const Mesh* head, const Visuality& visuality,
                    const RenderSettings& settings, const CustomShaders& shaders,
                    const RenderOptions& options, const FrameBefore* before) {
  std::optional<Strands> copy, copyBefore;
  RenderInput input;
  input.hair = &conformed(hair, options, copy);
  input.head = head;
  input.visuality = visuality;
  input.settings = settings;
  // The camera (and light) aimed at the hair asked for: a sequence aims at its shot's first frame, so
  // the camera holds still; otherwise at the hair rendered.
  std::optional<Strands> copyFraming;
  const Strands& aim = options.framing ? conformed(*options.framing, options, copyFraming) : *input.hair;
  if (options.frame)
    frameHair(input.settings, aim);
  else if (settings.cameraAuto)
    frameScene(input.settings, aim, head);
  if (before) {
    const std::optional<CustomStage>& vertex = shaders.hairVert ? shaders.hairVert : shaders.headVert;
    if (shaders.hairVert || (head && shaders.headVert))
      throw InputError(vertex->file +
                       ": motion vectors are drawn with hairgen's own vertex stages, and this "
                       "custom " +
                       (shaders.hairVert ? "HairVert" : "HeadVert") + " (named at " + vertex->namedAt +
                       ") may move what they cannot follow; render without --motion");
    if (!before->hair || !sameStrands(hair, *before->hair))
      throw InputError(
          "motion vectors need the frame before to have the same strands, each with as many points");
    if (head && (!before->head || before->head->positions.size() != head->positions.size()))
      throw InputError("motion vectors need the frame before to have the same head mesh");
    PreviousFrame previous;
    previous.hair = &conformed(*before->hair, options, copyBefore);
    previous.head = head ? before->head : nullptr;
    previous.settings = settings;
    // The camera of the frame before: the same when it is aimed at the shot's first frame or fixed;
    // aimed at that frame's hair when each frame aims at its own.
    const Strands& aimBefore = options.framing ? aim : *previous.hair;
    if (options.frame)
      frameHair(previous.settings, aimBefore);
    else if (settings.cameraAuto)
      frameScene(previous.settings, aimBefore, before->head ? before->head : head);
    input.previous = previous;
  }
  input.shaders = shaders;
  input.progress = options.progress;
  input.domResolution = options.domResolution;
  input.keepDom = options.keepDom;
  input.lightMaps = options.lightMaps;
  input.rasteriser = options.rasteriser;
  if (options.reference) {
    input.settings.samples = 64;
    input.keptFragments = kReferenceFragments;
  }
  input.uploaded = [&] {  // render's own copies (conformed, framing) go with the caller's hair
    copy.reset();
    copyBefore.reset();
    copyFraming.reset();
    if (options.uploaded) options.uploaded();
  };
  const WorkEstimate estimate =
      estimateRender(input.settings, *input.hair, head, gl.maxTextureSize(), input.keptFragments);
  requireFits(estimate, options.force);
  RenderOutput out = renderHair(gl, input);
  out.note = estimate.note;
  requireFinite(out.beauty);
  return out;
}

}  // namespace hairgen
