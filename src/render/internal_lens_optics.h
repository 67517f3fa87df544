#pragma once
// ApplyDepthOfField and ApplyVignetting with the choice of their kernels (lens_optics.cc), for
// tests: where the CPU has AVX2 they run 8 pixels of a row at once, elsewhere 4 or 1; both give
// the same bits.

#include "saccade/render/lens_optics.h"

namespace saccade::render {

/// ApplyDepthOfField (render/lens_optics.h); `simd` false: the portable 4-lane kernel even where
/// the CPU has AVX2 (tests: the two agree to the bit).
Image ApplyDepthOfField(const ImageView& rgb, const ImageView& depth, const ThinLensOptions& lens,
                        const geometry::Intrinsics& intrinsics, DepthOfFieldSummary* summary,
                        bool simd);

/// ApplyVignetting (render/lens_optics.h); `simd` false: the portable loop even where the CPU
/// has AVX2 (8 pixels at a time; tests: the two agree to the bit).
void ApplyVignetting(Image& rgb, const Image& factors, bool simd);

}  // namespace saccade::render
