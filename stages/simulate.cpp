#include "stages/simulate.h"

#include <tbb/task_arena.h>

#include "libcore/physics/anjyo_dynamics.h"
#include "libcore/physics/spring_dynamics.h"
#include "libcore/util/error.h"
#include "stages/estimate.h"

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
  requireFits(estimateSimulate(d, restGuides.pointCount() - restGuides.strandCount(), frames,
                               size_t(tbb::this_task_arena::max_concurrency())),
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
    guides.provenance.frame = frame;
    guides.provenance.time = double(frame - d.firstFrame) / d.frameRate;
    frameDone(frame, guides);
    if constexpr (lends) hair.swapState(guides.simulationState);  // taken back before the next step
    if (options.progress) options.progress->advance();
  };

  if (frames.first > d.firstFrame) {
    // A restart: the state of the frame before, as this same shot wrote it.
    const Strands* before = options.restart;
    const FileLoc where{options.restartName, 0};
    if (!before)
      throw InputError("frame " + std::to_string(frames.first) + " follows the shot's first frame " +
                       std::to_string(d.firstFrame) + ": simulate resumes from frame " +
                       std::to_string(frames.first - 1) + "'s cache" +
                       (options.restartName.empty() ? "" : " (" + options.restartName + ")") +
                       ", which is not there; simulate that frame first");
    if (before->provenance.stage != "simulate" || !before->provenance.frame ||
        *before->provenance.frame != frames.first - 1 || before->simulationState.empty())
      throw InputError(where, "is not frame " + std::to_string(frames.first - 1) +
                                  " of a simulation with its restart state; simulate from the first frame");
    if (before->provenance.configDigest != options.configDigest)
      throw InputError(where, "was simulated with another configuration (digest " +
                                  before->provenance.configDigest + ", this one " + options.configDigest +
                                  "); simulate from the first frame");
    if (before->firstPoint != restGuides.firstPoint)
      throw InputError(where, "holds other strands than the guides; restart from a frame of the same guides");
    hair.restore(before->simulationState, options.restartName);
  } else {
    emit(d.firstFrame, false);
  }
  const double dt = 1.0 / (d.frameRate * d.substeps);
  for (int frame = std::max(frames.first, d.firstFrame + 1); frame <= frames.last; ++frame) {
    const Pose pose = head.pose(frame);
    bool posed = false;
    for (int s = 0; s < d.substeps; ++s) {
      // The forces of the substep's start (Störmer-Verlet), in frames since the shot began.
      const double t = double(frame - 1) + double(s) / double(d.substeps);
      const AccelerationField field = headFrameField(head.at(t), windAt(d.wind, t), gravity);
      const bool last = s == d.substeps - 1;
      posed = stepHair(hair, field, dt, frame, s, d.substeps, &pose, last ? &guides : nullptr);
    }
    emit(frame, posed);
  }
}

}  // namespace

}  // namespace hairgen
