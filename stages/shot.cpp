#include "stages/shot.h"

#include "stages/interpolate.h"
#include "stages/shade.h"

namespace hairgen {

ShotFrame shotFrame(const ShotInputs& inputs, int frame, const Strands& guides,
                    const std::string& guidesName) {
  const Config& config = *inputs.config;
  const InterpolateOptions interpolation{config.digest(), guidesName, nullptr, inputs.force,
                                         inputs.motion.pose(frame).matrix()};
  ShotFrame out;
  out.coupe = interpolate(*inputs.wick, guides, config.hairstyle, config.collision, interpolation);
  if (inputs.shadedRest) out.coupe = repose(*inputs.shadedRest, out.coupe);
  out.head = shotHead(inputs, frame);
  return out;
}

std::optional<Mesh> shotHead(const ShotInputs& inputs, int frame) {
  if (!inputs.head) return std::nullopt;
  if (inputs.motion.still()) return *inputs.head;
  return posedMesh(*inputs.head, inputs.motion.pose(frame));
}

FrameBefore ShotMotion::before(const ShotFrame& current) {
  if (!coupe_) coupe_ = current.coupe, head_ = current.head;
  return FrameBefore{&*coupe_, head_ ? &*head_ : nullptr};
}

void ShotMotion::keep(ShotFrame&& frame) {
  coupe_ = std::move(frame.coupe);
  head_ = std::move(frame.head);
}

}  // namespace hairgen
