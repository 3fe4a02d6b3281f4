// The shot stage: a frame of a simulated shot from its guides, as `run` renders it and `render --guides
// --frames` renders a farm's chunk of it, one function so the two agree by construction (DESIGN §8).
// Reads no files and prints nothing: the caller reads the frame's guides, the shaded rest coupe and the
// head, and renders what it gives.
#pragma once

#include <optional>
#include <string>

#include "libcore/config/params.h"
#include "libcore/model/mesh.h"
#include "libcore/model/strands.h"
#include "libcore/physics/head_motion.h"
#include "stages/render.h"

namespace hairgen {

// What every frame of a shot is made from.
struct ShotInputs {
  const Config* config = nullptr;
  const Mesh* wick = nullptr;           // the wick the guides were grown on, as at rest
  const Strands* shadedRest = nullptr;  // the shaded rest coupe; null when the Setup does not shade
  const Mesh* head = nullptr;           // the head at rest; null without one
  HeadMotion motion;                    // the head's keys (headMotionOf(config))
  bool force = false;                   // interpolate work estimated to take absurdly long
};

// A frame's render inputs: the coupe interpolated from its guides at the head's pose (re-posed from the
// shaded rest when the Setup shades: its normals turned with the strands, its colours kept), and the
// head posed (empty without a head).
struct ShotFrame {
  Strands coupe;
  std::optional<Mesh> head;
};

// Frame `frame` of the shot from its simulated guides (`guidesName` names them in errors). Throws
// InputError when the guides do not fit the wick.
ShotFrame shotFrame(const ShotInputs& inputs, int frame, const Strands& guides,
                    const std::string& guidesName);

// The head at frame `frame`: posed by its keys (a copy when it holds still); empty without a head.
std::optional<Mesh> shotHead(const ShotInputs& inputs, int frame);

// The frame before, for motion vectors, kept from frame to frame: the shot's first frame has nothing
// before it and moves by 0 (its own coupe and head are its frame before).
class ShotMotion {
 public:
  bool started() const { return coupe_.has_value(); }
  // The frame before `current`; the first call with none kept keeps a copy of `current`.
  FrameBefore before(const ShotFrame& current);
  // `frame` is the frame before the next one.
  void keep(ShotFrame&& frame);

 private:
  std::optional<Strands> coupe_;
  std::optional<Mesh> head_;
};

}  // namespace hairgen
