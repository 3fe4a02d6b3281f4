// The camera's view of the hair, drawn by hairgen's own integer rasteriser (hair_raster.h, the one the
// light's maps use), so a GPU and llvmpipe see the same hair in the same pixels with the same coverage.
//
// A strand covers a pixel by its analytic coverage: its projected width × its length within the pixel
// (Kajiya & Kay's thin cylinder), so a strand thinner than a pixel is a faint line. Per pixel the
// rasteriser keeps the `kept` nearest fragments in depth order; the pieces one strand leaves in a
// pixel from one segment or the next are one fragment (their coverages summed, at the nearest piece's
// depth, shaded where its largest piece lies), so a strand is not blended with itself. What lies behind the
// kept fragments adds its coverage to the pixel's tail. Each band of rows is drawn by one thread, its
// segments in the order of their first point, so the fragments are the same bits on any thread count.
//
// The shading pass shades every kept fragment with the hair's fragment stage and blends them front to
// back (order-independent transparency over the nearest fragments, as a k-buffer does), passes.h.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "libcore/model/strands.h"
#include "libcore/render/hair_raster.h"
#include "libcore/render/views.h"

namespace hairgen {

// The fragments the shading pass blends per pixel (k-buffer depth): at a real strand's width at 1080p
// (a fifth to a third of a pixel) the eight nearest strands stop most of the light where hair is thick,
// and the tail blends the rest's coverage as one layer (render_reference_test.sh measures the error).
inline constexpr int kKeptFragments = 8;
// The converged reference's (render --reference, with 8 × 8 sub-pixels): every fragment a sub-pixel of
// a coupe sees, to the last per cent of its light.
inline constexpr int kReferenceFragments = 64;
// The bytes a pixel's kept slot takes while its band is drawn (camera_fragments.cpp's Slot), for
// preflight's estimate of what the rasteriser holds.
inline constexpr size_t kSlotBytes = 28;
// The bytes of a pixel's record beside its slots while its band is drawn (camera_fragments.cpp's Pixel).
inline constexpr size_t kPixelRecordBytes = 16;
// Where a fragment lies along its segment, in 1/kSpanUnit of it (15 bits).
inline constexpr uint32_t kSpanUnit = (1u << 15) - 1;
// A fragment's third word: its coverage in kCoverageOne per pixel (hair_raster.h) in the low 17 bits,
// where it lies along its segment (1/kSpanUnit) above them.
inline constexpr int kCoverageBits = 17;

struct CameraFragments {
  int width = 0, height = 0;  // the view's pixels
  // Pixel p's fragments (p = row · width + column, rows from the bottom) are fragments
  // first[p] … first[p + 1] − 1, nearest first (by depth, then the first point of its first segment).
  std::vector<uint32_t> first;  // width · height + 1
  // Three words per fragment: its segment's first point; its depth along the camera's axis, metres, as
  // a float's bits; its coverage and place along the segment (kCoverageBits).
  std::vector<uint32_t> words;
  // Per pixel, the coverage of the fragments behind the kept ones (kCoverageOne per pixel, summed).
  std::vector<uint32_t> tail;
  size_t count() const { return words.size() / 3; }
};

// The fragments of the hair a view's rasteriser has projected and sorted into bands (hair_raster.h:
// projectIntoBands, its width × height pixels, or sub-pixels). `kept`: fragments per pixel, 1 to 255.
// `opaque`: null, or per pixel (rows from the bottom) the depth along the camera's axis of what hides
// the hair behind it (the head), metres: a fragment that deep or deeper is no fragment of the pixel,
// neither kept nor in its tail. `limit`: the most fragments the caller can use (the shading pass's
// atlas); more is refused (InputError naming Render.Samples and Render.Resolution) as soon as the
// bands drawn so far keep more, so `first` (32 bits) never wraps and their words are never all held.
CameraFragments cameraFragments(const raster::Bands& bands, int kept, const float* opaque = nullptr,
                                uint64_t limit = UINT32_MAX);

// Throws InputError (exit 2) when `fragments` kept fragments are more than `limit`, the most the
// shading pass can use.
void requireShadable(uint64_t fragments, uint64_t limit);

// projectIntoBands(hair, camera, strandWidth), then its fragments. `strandWidth`: the strands'
// diameter, metres. A segment with a point nearer than the near plane is dropped.
CameraFragments rasteriseCameraFragments(const Strands& hair, const View& camera, double strandWidth,
                                         int kept, const float* opaque = nullptr);

}  // namespace hairgen
