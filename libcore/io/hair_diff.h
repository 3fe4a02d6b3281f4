// Cache comparison for `hairgen diff A.hair B.hair` and the stage goldens (golden/README.md): is B the
// same hair as the reference A, up to round-off?
//
// The structure must match exactly: strand count, points per strand, each strand's root (its first point,
// bit for bit) and, where A carries them, the strand ids. Then per point: the distance between A's and
// B's points (metres), the angle between their normals and the largest difference of their colours where
// A carries those. B fails past `HairDiffTolerances`; an attribute A carries and B lacks fails too.
#pragma once

#include <cstddef>
#include <string>

#include "libcore/model/strands.h"
#include "libcore/util/error.h"

namespace hairgen {

struct HairDiffTolerances {
  // 10 µm: a seventh of a hair's diameter (~70 µm) and far below what a render resolves (a golden's
  // pixel covers ~2.5 mm of head), yet ~600 times float's spacing at head scale (1.5e-8 m at 0.2 m), so
  // round-off gathered along a strand's chain of elements passes while a changed minimiser result or
  // dynamics step, which moves points by millimetres, fails.
  double distance = 1.0e-5;
  // 0.1°: a shading normal that turns by this changes a Kajiya-Kay or volumetric lobe by well under one
  // 8-bit step, and is ~100 times the round-off of a normal taken from a float gradient.
  double angleDegrees = 0.1;
};

struct HairDiff {
  size_t strands = 0, points = 0;                // the reference's
  bool structureMatches = false;                 // the statistics below are zero unless it does
  double meanDistance = 0.0, maxDistance = 0.0;  // metres, over every point
  size_t worstStrand = 0, worstPoint = 0;        // where maxDistance is (point index within the strand)
  bool normalsCompared = false;
  double maxAngleDegrees = 0.0;
  bool colorsCompared = false;
  double maxColor = 0.0;               // largest per-channel difference of the linear RGB colours
  std::string reason;                  // why B fails; empty when it passes
  ExitCode code = ExitCode::kSuccess;  // kSuccess, or kDiffFailed
};

// A colour may differ by at most this: less than one step of a 16-bit output (1/65535).
inline constexpr double kHairDiffColorTolerance = 1.0e-5;

// Compares B with the reference A. Never throws: every difference is reported in the result.
HairDiff diffHair(const Strands& a, const Strands& b, const HairDiffTolerances& tolerances);

}  // namespace hairgen
