#pragma once
// ApplyDepthOfField and ApplyVignetting with the choice of their kernels (lens_optics.cc), for
// tests: where the CPU has AVX2 they run 8 pixels of a row at once, elsewhere 4 or 1; both give
// the same bits.

#include "saccade/render/color_filter.h"
#include "saccade/render/lens_optics.h"

namespace saccade::render {

/// ApplyDepthOfField (render/lens_optics.h), or with `pattern` not kNone
/// ApplyDepthOfFieldToMosaic, gathering at most `max_lanes` pixels at once: 16 where the CPU has
/// AVX-512, 8 where it has AVX2, else 4 (DepthOfFieldLanes; tests: all agree to the bit).
Image ApplyDepthOfField(const ImageView& rgb, const ImageView& depth, const ThinLensOptions& lens,
                        const geometry::Intrinsics& intrinsics, DepthOfFieldSummary* summary,
                        int max_lanes, CfaPattern pattern = CfaPattern::kNone);

/// The pixels ApplyDepthOfField gathers at once on this CPU, at most `max_lanes`: 16, 8 or 4.
int DepthOfFieldLanes(int max_lanes = 16);

/// ApplyVignetting (render/lens_optics.h); `simd` false: the portable loop even where the CPU
/// has AVX2 (8 pixels at a time; tests: the two agree to the bit).
void ApplyVignetting(Image& rgb, const Image& factors, bool simd);

}  // namespace saccade::render
