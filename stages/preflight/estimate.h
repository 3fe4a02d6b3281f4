// The work a stage is about to do, estimated from the config and the sizes of its inputs before any of
// it is done: its peak memory and a rough time on this machine. A stage refuses (InputError, exit 2)
// work that cannot fit the memory free for it, or that would run absurdly long, naming the key to
// change; `force` overrides the time limit, never the memory one. `hairgen check` prints the same
// estimates, and a farm plan asks its scheduler for their memory.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "libcore/config/params.h"
#include "libcore/model/mesh.h"
#include "libcore/model/strands.h"
#include "libcore/render/camera_fragments.h"
#include "libcore/render/views.h"
#include "libcore/util/frames.h"

namespace hairgen {

struct WorkEstimate {
  std::string stage;       // "grow", "interpolate", "shade", "render"
  uint64_t bytes = 0;      // peak memory of the work itself
  double seconds = 0.0;    // rough wall time on this machine's cores
  std::string memoryKey;   // the key that drives the memory, e.g. "Hairstyle.VisualityStep"
  std::string timeKey;     // the key that drives the time
  std::string detail;      // what the figures come from: "759 guides x 65 points"
  std::string refusal;     // work that is wrong whatever it costs, naming the key; --force overrides it
  std::string impossible;  // work whose output cannot be written, naming the key; whatever --force says
  int frames = 0;          // a shot's work: the frames it covers (`seconds` is all of them, `bytes` one's)
  std::string note;        // what the user should hear that is no refusal (hair that looks to be in other
                           // units); empty: nothing
};

// No hair grows longer: a strand past it says the file is in other units (a groom in centimetres read as
// metres).
inline constexpr double kLongestHairMetres = 3.0;

// Beyond this a stage is stopped before it starts unless --force: an hour is far past any coupe or
// frame hairgen's bundled configs make (the slowest takes seconds).
inline constexpr double kTimeLimitSeconds = 3600.0;

// Throws InputError when the work's output cannot be written (`impossible`), needs more memory than is
// free (memoryBudget()), or when it would take longer than kTimeLimitSeconds and `force` is false.
void requireFits(const WorkEstimate& estimate, bool force);

// `threads`: the worker threads the stage may use (each holds its own scratch).
WorkEstimate estimateGrow(const Hairstyle& style, const Collision& collision, size_t follicles,
                          size_t threads);
// `wickAreaCm2`: the wick's area; `pointsPerGuide`: the guides' largest vertex count.
WorkEstimate estimateInterpolate(const Hairstyle& style, double wickAreaCm2, size_t triangles,
                                 size_t pointsPerGuide);
// `span`: the coupe's bounding box size, metres.
WorkEstimate estimateShade(const RenderSettings& render, size_t strands, size_t points,
                           const glm::dvec3& span);
// The sub-pixel fragments `hair`'s ribbons cover in `view` (the camera at its sub-pixels), what the
// render's time grows with: each segment clipped to the near plane and to the image (widened by half the
// ribbon), its length in pixels times its width (`strandWidth` metres, at least `minWidthPx`), at most
// the image's pixels a segment. Off-screen hair costs nothing. `kept`, when given, gets the fragments
// hairgen's rasteriser keeps (what its memory grows with): in each tile of kFootprintTile² pixels, those
// its segments give (a segment's clipped length times its true width plus one, the box filter's reach,
// counted in the tile of its middle), at most kept->perPixel a pixel.
struct KeptFragments {
  int perPixel = kKeptFragments;  // in
  double fragments = 0.0;         // out
};
inline constexpr int kFootprintTile = raster::kBandRows;  // pixels a side: a band's rows
double hairCoverage(const View& view, const Strands& hair, double strandWidth, double minWidthPx,
                    KeptFragments* kept = nullptr);

// The render of `hair` (and `head`, may be null) with `render`'s camera as framed, its time from
// hairCoverage, its memory with what the rasteriser holds for `keptFragments` a sub-pixel (render
// --reference keeps kReferenceFragments) on this process's threads. A strand drawn wider than a quarter
// of the image is a refusal naming Render.StrandWidth. A strand longer than kLongestHairMetres is a
// note: how thin the strands are drawn, and --units (framed, a coupe in centimetres read as metres is
// a nearly empty image: its strands drawn a hundredth of their width).
WorkEstimate estimateRender(const RenderSettings& render, const Strands& hair, const Mesh* head,
                            int maxTextureSize, int keptFragments = kKeptFragments);
// The same predicted before there is hair: `distance` from the camera to the scene's centre, `radius`
// the scene's, `hairLength` the longest strand, metres; each strand covers at most the image.
WorkEstimate estimateRender(const RenderSettings& render, size_t strands, size_t points, size_t headTriangles,
                            double distance, double radius, double hairLength, int maxTextureSize,
                            int keptFragments = kKeptFragments);

// `segments`: the guides' segments (points − strands); `frames`: the frames to simulate; `span`: the
// size of the box that holds the rest guides and Model springs' DensityTarget (metres), which sizes
// the springs' density grids (Dynamics.DensitySpacings) and velocity-smoothing grid; 0 when unknown.
WorkEstimate estimateSimulate(const Dynamics& dynamics, size_t segments, const FrameRange& frames,
                              size_t threads, const glm::dvec3& span = glm::dvec3(0.0));

// The points a grown guide has: one every VisualityStep (Super-Helix), or Segments + 1 (cantilever).
size_t pointsPerGuide(const Hairstyle& style);

// Every stage of `hairgen run` on `wick`, before any of them runs, from the config alone: the coupe's
// size and extent are predicted from the wick, the density and the hair's length.
std::vector<WorkEstimate> estimateRun(const Config& config, const Mesh& wick, bool shade, bool render,
                                      size_t threads);

// Every stage of `hairgen run` on a shot (the Setup names a Dynamics Info): the rest coupe as
// estimateRun's (grown, interpolated, shaded), then the guides simulated over Dynamics Frames and each
// frame interpolated and, with `render`, rendered, those three with `frames` set. A still's is
// estimateRun's.
std::vector<WorkEstimate> estimateShot(const Config& config, const Mesh& wick, bool shade, bool render,
                                       size_t threads);

}  // namespace hairgen
