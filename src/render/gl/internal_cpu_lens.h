#pragma once
// The lens remap of the final pass (kFinalFragmentSource) on the CPU, for a lens of one
// source view: the renderer reads the source view back instead of running the pass, and
// Retrieve remaps it row by row, then adds the noise (internal_pixels.h). On a software
// rasteriser the pass costs 7-10 ms an eye at 1024 x 768 (the bench scene's lens); the same
// bilinear samples on the CPU, two pixels at a time with AVX2, cost a few.
//
// Each pixel is what the pass computes from the map (RemapTable): the mean of nu x nv
// bilinear samples over its footprint (one for most pixels), each with the source clamped to
// its edge and weighed with 8 fractional bits (a position within 1/512 pixel, as the texture
// units of llvmpipe and GPUs weigh), black where the pixel has no ray. The pass rounds each
// sample to 8 bits and then the mean; here the mean is rounded once, so the two images differ
// by at most one DN on a multi-sample pixel, and on a one-sample pixel where a device rounds
// a sample the other way (tests/render/effects_test.cc compares them).

#include <cstdint>
#include <vector>

#include "render/gl/internal_effects.h"

namespace saccade::render::gl {

class CpuLens {
 public:
  /// The remap of a camera of `width` x `height` from one source view of `source_width` x
  /// `source_height` RGBA8 pixels (row 0 first); `table` is the lens's (one view only).
  CpuLens(const RemapTable& table, int width, int height, int source_width, int source_height);

  /// Row `y` of the camera's image into `rgba_row` (width RGBA8 pixels). `simd` false: the
  /// portable loop even where the CPU has AVX2 (tests: the two agree to the bit).
  void RemapRow(const uint8_t* source, int y, uint8_t* rgba_row, bool simd = true) const;

  /// Row `y` of the camera's z from the source view's (`source_z`: source-size floats, row 0
  /// first, 0 where no surface) into `z_row` (width floats), as the truth remap
  /// (kTruthRemapFragmentSource) without ids: bilinear where the four source pixels around
  /// the pixel's sample are surfaces within 2 % of each other's depth, the nearest one's
  /// otherwise (no depth mixed across an edge); a pixel of several samples takes its first,
  /// one without a ray 0. `simd` false: the portable loop even where the CPU has AVX2 (tests:
  /// the two agree to the bit).
  void RemapDepthRow(const float* source_z, int y, float* z_row, bool simd = true) const;

  /// Pixels remapped with more than one sample or none (no ray).
  std::size_t special_pixels() const { return special_pixel_.size(); }

 private:
  struct Sample {
    uint32_t offset;   // byte offset of the top-left source pixel of the 2 x 2
    uint32_t weights;  // fx | fy << 16, each in [0, 256]
  };
  Sample MakeSample(double x, double y) const;

  int width_, height_, source_width_, source_height_;
  // Per pixel of the camera (row 0 first): its sample (the first for a multi-sample pixel,
  // any valid one for a pixel with no ray), so that a row is remapped in one pass...
  std::vector<Sample> samples_;
  // ...and then the special pixels are overwritten: index, and their samples in
  // special_samples_ [special_first_[k], special_first_[k + 1]) (none: black), row by row
  // (row y's are [row_first_[y], row_first_[y + 1])).
  std::vector<uint32_t> special_pixel_;
  std::vector<uint32_t> special_first_;
  std::vector<Sample> special_samples_;
  std::vector<uint32_t> row_first_;
};

}  // namespace saccade::render::gl
