// The simulate stage (DESIGN §8): the rest guides stepped through time under Dynamics Info — the wind,
// the keyed head motion, gravity — one guide cache per frame. Model anjyo is Anjyo et al. 1992 §3
// (libcore/physics/anjyo_dynamics.h); Model springs is Petrovic et al. 2006 §5, mass-spring keyhairs
// with velocity smoothing and density targeting (libcore/physics/spring_dynamics.h), toward the
// DensityTarget cache the caller has read.
//
// Frame Frames.first is the rest state: the input guides, moved by the head's pose at that frame. Each
// later frame is one step of 1/FrameRate seconds in Substeps substeps. Every frame carries its frame
// number, its time and the state a restart needs, so a shot split at any frame and resumed gives the
// same bytes as one run.
#pragma once

#include <functional>
#include <string>

#include "libcore/config/params.h"
#include "libcore/model/strands.h"
#include "libcore/physics/head_motion.h"
#include "libcore/util/frames.h"
#include "libcore/util/progress.h"

namespace hairgen {

struct SimulateOptions {
  std::string configDigest;          // recorded in every frame's provenance
  FrameRange frames;                 // the frames to produce, within Dynamics Frames
  const Strands* restart = nullptr;  // frame frames.first − 1 as simulate wrote it, when frames.first is
                                     // after Frames.first
  std::string restartName;           // names it in errors
  Progress* progress = nullptr;      // advanced once per frame
  bool force = false;                // run work estimated to take absurdly long
  const Strands* densityTarget = nullptr;  // Model springs: Dynamics DensityTarget as read (required
                                           // when the Dynamics Info names one)
};

// Calls `frameDone(frame, guides)` for every frame of options.frames, in order; `guides` is valid until
// the call returns (one buffer serves every frame). Every frame's provenance records the rest guides'
// digest, and its state is one a restart accepts (libcore/io/restart_state.h). Throws InputError for
// frames outside Dynamics Frames, guides that cannot move, or a restart cache checkRestartState refuses
// (missing, of another configuration or other rest guides, from an older hairgen, or with values no
// simulation writes); SimulationDiverged (exit 2) when the hair leaves its validity at a frame (a step
// that overflowed, a stretch solve that did not converge: a segment more than kMaxSpringStretch off its
// rest length, a point faster than kMaxSpringSpeed), naming the keys that drove it and their values, the
// frame and the strand; that frame is not delivered, the frames before it were.
void simulate(const Strands& restGuides, const Config& config, const SimulateOptions& options,
              const std::function<void(int frame, const Strands& guides)>& frameDone);

// The head's pose at `frame` for a job: its keys about its centre (Dynamics Info, Collision Info).
HeadMotion headMotionOf(const Config& config);

}  // namespace hairgen
