#pragma once
// ApplyDepthOfField with the choice of its kernel (lens_optics.cc), for tests: where the CPU has
// AVX2 the gather runs 8 pixels of a row at once, elsewhere 4; both give the same bits.

#include "saccade/render/lens_optics.h"

namespace saccade::render {

/// ApplyDepthOfField (render/lens_optics.h); `simd` false: the portable 4-lane kernel even where
/// the CPU has AVX2 (tests: the two agree to the bit).
Image ApplyDepthOfField(const ImageView& rgb, const ImageView& depth, const ThinLensOptions& lens,
                        const geometry::Intrinsics& intrinsics, DepthOfFieldSummary* summary,
                        bool simd);

}  // namespace saccade::render
