#pragma once
// Motion blur of a turning camera (the final pass's TURN, kFinalFragmentSource) on the CPU,
// for a camera without lens distortion on a software rasteriser
// (RendererOptions::turn_blur_on_cpu): the stretches are drawn as on a GPU, read back, and
// Retrieve takes each pixel's mean of the bilinear fetches through the sub-frames'
// homographies, row by row, before the noise (internal_pixels.h). On llvmpipe the pass cost
// 31 to 43 ms an eye of `saccade demo` (1024 x 768, 6 or 8 sub-frames, two stretches); eight
// pixels at a time with AVX2 the same fetches cost a few.
//
// The pass and this agree within a DN: the pass's texture unit weighs a fetch's four texels
// with 8 fractional bits and may round each fetch to 8 bits; here they are weighed in float
// and the mean is rounded once (tests/render/effects_test.cc compares the two).

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace saccade::render::gl {

/// One camera's turn as Retrieve remaps it: `layers` holds the stretches read back (RGBA8,
/// each width x height, row 0 at the top, one after the other); sub-frame k is stretch
/// layer[k] seen through homography[k] (a pixel of sub-frame k, centres at integers, to the
/// stretch's; as TurnSamples).
struct CpuTurn {
  std::vector<Eigen::Matrix3f> homographies;
  std::vector<int> layers;
  int stretches = 0;  ///< layers read back
};

/// Row `y` of the blurred image into `rgba_row` (width RGBA8 pixels, alpha 255): each pixel
/// the mean over the sub-frames of the bilinear fetch at H_k (x, y, 1) from its layer of
/// `pixels` (edges clamped, as the pass's CLAMP_TO_EDGE), rounded to 8 bits. `simd` false: the
/// portable loop even where the CPU has AVX2 and FMA (tests: the two give the same bytes).
void TurnBlurRow(const CpuTurn& turn, const uint8_t* pixels, int width, int height, int y,
                 uint8_t* rgba_row, bool simd = true);

}  // namespace saccade::render::gl
