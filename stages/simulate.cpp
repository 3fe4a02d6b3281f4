#include "stages/simulate.h"

#include <cstdio>

#include <tbb/task_arena.h>

#include "libcore/io/restart_state.h"
#include "libcore/physics/anjyo_dynamics.h"
#include "libcore/physics/spring_dynamics.h"
#include "libcore/util/error.h"
#include "libcore/util/text.h"
#include "stages/preflight/estimate.h"

namespace hairgen {

HeadMotion headMotionOf(const Config& config) {
  return HeadMotion(config.dynamics.headKeys, headCentre(config.dynamics, config.collision),
                    config.dynamics.frameRate);
}

namespace {

// One substep's call for each model: Anjyo's keys its fluctuations by the frame, the springs smooth
// their velocities after a frame's last substep. Given `posed`, the frame's last substep also poses the
// new state into it where the model can in the same pass (Anjyo's), and says whether it did.
bool stepHair(AnjyoHair& hair, const AccelerationField& field, double dt, int frame, int substep, int,
              const Pose* pose, Strands* posed) {
  if (!posed) {
    hair.step(field, dt, frame, substep == 0);
    return false;
  }
  hair.stepAndPose(field, dt, frame, substep == 0, *pose, *posed);
  return true;
}
bool stepHair(SpringHair& hair, const AccelerationField& field, double dt, int, int substep, int substeps,
              const Pose*, Strands*) {
  hair.step(field, dt, substep == 0, substep == substeps - 1);
  return false;
}

// How the hair left its validity, where it did (the strand and its point or segment), or nothing
// while it is valid.
std::optional<std::string> faultOf(const SpringHair& hair) {
  const std::optional<SpringHair::Fault>& f = hair.fault();
  if (!f) return std::nullopt;
  const std::string where = "strand " + std::to_string(f->strand) + ", point " + std::to_string(f->point);
  switch (f->kind) {
    case SpringHair::Fault::kStretch:
      return where + " ends a segment " + formatReal(std::round(1000.0 * f->value) / 10.0) +
             "% off its rest length (the bound is " + formatReal(100.0 * kMaxSpringStretch) +
             "%): the stretch solve did not converge";
    case SpringHair::Fault::kSpeed:
      return where + " moves at " + formatSignificant(f->value) + " m/s (the bound is " +
             formatReal(kMaxSpringSpeed) + " m/s)";
    case SpringHair::Fault::kNotFinite:
      break;
  }
  return where + " is not finite: the step overflowed";
}
std::optional<std::string> faultOf(const AnjyoHair& hair) {
  const std::optional<AnjyoHair::Fault> f = hair.fault();
  if (!f) return std::nullopt;
  return "strand " + std::to_string(f->strand) + ", segment " + std::to_string(f->segment) + " holds " +
         (f->angle ? "an angle" : "a turn") + " of " + formatSignificant(f->value) + " rad (the bound is " +
         formatReal(f->angle ? kMaxAnjyoAngle : kMaxAnjyoTurn) + (f->angle ? " rad" : " rad a substep") +
         "): the step overflowed";
}

// The settings that drive a step: its length, and the largest acceleration on the hair (the gravity
// of the moving hair, the strongest Wind, Model springs' DensityStrength), each named as `--set` takes it.
struct Driver {
  std::string key;
  double value = 0.0;
  const char* unit = "";
};
Driver strongestForce(const Config& config, double gravity) {
  const Dynamics& d = config.dynamics;
  const bool springs = d.model == DynamicsModel::kSprings;
  Driver out{springs && !d.gravityAuto ? "Dynamics.Gravity" : "Hairstyle.Gravity", std::abs(gravity), "N/kg"};
  for (const WindKey& w : d.wind)
    if (glm::length(w.acceleration) > out.value) out = {"Dynamics.Wind", glm::length(w.acceleration), "m/s²"};
  if (springs && d.densityTarget.given() && d.densityStrength > out.value)
    out = {"Dynamics.DensityStrength", d.densityStrength, "m/s²"};
  return out;
}

[[noreturn]] void diverged(const Config& config, double gravity, int frame, const std::string& what) {
  const Dynamics& d = config.dynamics;
  const Driver force = strongestForce(config, gravity);
  throw SimulationDiverged(
      "frame " + std::to_string(frame) + ": the simulation left its validity: " + what + ", in steps of " +
      formatSignificant(1.0 / (d.frameRate * d.substeps)) + " s (Dynamics.FrameRate " +
      formatReal(d.frameRate) + " frames/s, Dynamics.Substeps " + std::to_string(d.substeps) + ") under " +
      force.key + " " + formatReal(force.value) + " " + force.unit + "; nothing of frame " +
      std::to_string(frame) +
      " is written. Raise Dynamics.Substeps (or Dynamics.FrameRate) for shorter steps, or lower " +
      force.key);
}

template <class Hair>
void run(Hair& hair, double gravity, const Strands& restGuides, const Config& config,
         const SimulateOptions& options,
         const std::function<void(int frame, const Strands& guides)>& frameDone);

}  // namespace

void simulate(const Strands& restGuides, const Config& config, const SimulateOptions& options,
              const std::function<void(int frame, const Strands& guides)>& frameDone) {
  const Dynamics& d = config.dynamics;
  if (!d.given)
    throw InputError(config.setup.file.string() +
                     ": the Setup names no Dynamics Info; add `DynamicsInfo FILE` "
                     "(Model, Frames, FrameRate, Wind, HeadKey, ...)");
  const FrameRange frames = options.frames;
  if (frames.first < d.firstFrame || frames.last > d.lastFrame)
    throw InputError("frames " + std::to_string(frames.first) + "-" + std::to_string(frames.last) +
                     " are outside the shot's Frames " + std::to_string(d.firstFrame) + "-" +
                     std::to_string(d.lastFrame));
  // The box the springs' grids cover: the rest guides' and the density target's.
  glm::dvec3 lo(0.0), hi(0.0);
  bool any = false;
  for (const Strands* s : {&restGuides, d.densityTarget.given() ? options.densityTarget : nullptr})
    for (size_t p = 0; s && p < s->pointCount(); ++p) {
      const glm::dvec3 x(s->points[p]);
      lo = any ? glm::min(lo, x) : x;
      hi = any ? glm::max(hi, x) : x;
      any = true;
    }
  requireFits(estimateSimulate(d, restGuides.pointCount() - restGuides.strandCount(), frames,
                               size_t(tbb::this_task_arena::max_concurrency()), hi - lo),
              options.force);
  if (d.model == DynamicsModel::kSprings) {
    if (d.densityTarget.given() && !options.densityTarget)
      throw InputError(d.densityTarget.where, "the DensityTarget " + d.densityTarget.path.string() +
                                                  " was not read; pass it in SimulateOptions");
    SpringHair hair(restGuides, config.hairstyle, d, config.collision,
                    d.densityTarget.given() ? options.densityTarget : nullptr);
    run(hair, dynamicsGravity(config.hairstyle, d), restGuides, config, options, frameDone);
  } else {
    AnjyoHair hair(restGuides, config.hairstyle, d, config.collision, config.hairstyle.seed);
    run(hair, config.hairstyle.gravity, restGuides, config, options, frameDone);
  }
}

namespace {

template <class Hair>
void run(Hair& hair, double gravity, const Strands& restGuides, const Config& config,
         const SimulateOptions& options,
         const std::function<void(int frame, const Strands& guides)>& frameDone) {
  const Dynamics& d = config.dynamics;
  const FrameRange frames = options.frames;
  const HeadMotion head = headMotionOf(config);
  const std::string restDigest = restGuidesDigest(restGuides);
  Strands guides;  // every frame's, reused: no fresh pages to fault in per frame
  auto emit = [&](int frame, bool posed) {
    if (!posed) hair.posedInto(head.pose(frame), guides);
    // The restart state: lent to the frame's guides where the model keeps it in the cache's layout,
    // copied where it does not.
    constexpr bool lends = requires {
      hair.swapState(guides.simulationState);
    };
    if constexpr (lends)
      hair.swapState(guides.simulationState);
    else
      hair.stateInto(guides.simulationState);
    guides.provenance = madeByHairgen("simulate", config.hairstyle.seed, options.configDigest);
    guides.provenance.restDigest = restDigest;
    guides.provenance.frame = frame;
    guides.provenance.time = double(frame - d.firstFrame) / d.frameRate;
    frameDone(frame, guides);
    if constexpr (lends) hair.swapState(guides.simulationState);  // taken back before the next step
    if (options.progress) options.progress->advance();
  };

  if (frames.first > d.firstFrame) {
    // A restart: the state of the frame before, as this same shot wrote it.
    const Strands* before = options.restart;
    if (!before)
      throw InputError("frame " + std::to_string(frames.first) + " follows the shot's first frame " +
                       std::to_string(d.firstFrame) + ": simulate resumes from frame " +
                       std::to_string(frames.first - 1) + "'s cache" +
                       (options.restartName.empty() ? "" : " (" + options.restartName + ")") +
                       ", which is not there; simulate that frame first");
    checkRestartState(restGuides, *before,
                      RestartExpectation{d.model, frames.first - 1, options.configDigest, restDigest},
                      options.restartName);
    hair.restore(before->simulationState, options.restartName);
  } else {
    emit(d.firstFrame, false);
  }
  const double dt = 1.0 / (d.frameRate * d.substeps);
  for (int frame = std::max(frames.first, d.firstFrame + 1); frame <= frames.last; ++frame) {
    const Pose pose = head.pose(frame);
    bool posed = false;
    for (int s = 0; s < d.substeps; ++s) {
      // The forces of the substep's start (Anjyo's step is Störmer-Verlet; the springs' BDF2 takes these
      // explicitly, first order), in frames since the shot began.
      const double t = double(frame - 1) + double(s) / double(d.substeps);
      const AccelerationField field = headFrameField(head.at(t), windAt(d.wind, t), gravity);
      const bool last = s == d.substeps - 1;
      posed = stepHair(hair, field, dt, frame, s, d.substeps, &pose, last ? &guides : nullptr);
    }
    // A frame is written only from a valid state: one a restart would accept.
    if (const std::optional<std::string> fault = faultOf(hair)) diverged(config, gravity, frame, *fault);
    emit(frame, posed);
  }
}

}  // namespace

}  // namespace hairgen
