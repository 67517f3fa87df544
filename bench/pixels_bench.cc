// The photometric chain's kernels (issue 45), Google Benchmark, on one 1024 x 768 eye: the EMVA
// sensor exposing a Bayer mosaic and an RGB image, demosaicing, and the thin lens's depth of
// field over a floor from 0.5 to 6 m. Whole frames: build/bin/render_bench.
//   build/bin/pixels_bench [--benchmark_filter=Expose]

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "saccade/core/image.h"
#include "saccade/render/color_filter.h"
#include "saccade/render/lens_optics.h"
#include "saccade/render/sensor_model.h"
#include "saccade/scene/emva_sensor.h"

namespace {

using saccade::Image;
using saccade::PixelFormat;

constexpr int kWidth = 1024, kHeight = 768;

// A smooth gradient with a texture: every 8-bit value occurs.
Image Rendered(PixelFormat format, int channels) {
  Image image(kWidth, kHeight, format);
  for (int y = 0; y < kHeight; ++y) {
    for (int i = 0; i < kWidth * channels; ++i) {
      image.row(y)[i] = static_cast<uint8_t>((i / channels + 3 * y + 37 * (i % channels)) % 256);
    }
  }
  return image;
}

void Expose(benchmark::State& state, int channels) {
  const saccade::scene::EmvaSensor params = *saccade::scene::FindEmvaPreset("imx174");
  const saccade::render::SensorModel sensor(params, 1, "left", kWidth, kHeight, channels);
  const Image rendered =
      Rendered(channels == 3 ? PixelFormat::kRgb8 : PixelFormat::kBayerRggb8, channels);
  Image out(kWidth, kHeight, rendered.format());
  int64_t frame = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(sensor.ExposeRendered(rendered.view(), 0.008, frame++, &out));
  }
  state.SetItemsProcessed(state.iterations() * kWidth * kHeight * channels);
}
void BM_SensorExposeMosaic(benchmark::State& state) { Expose(state, 1); }
BENCHMARK(BM_SensorExposeMosaic)->Unit(benchmark::kMillisecond)->UseRealTime();
void BM_SensorExposeRgb(benchmark::State& state) { Expose(state, 3); }
BENCHMARK(BM_SensorExposeRgb)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_DemosaicEdgeAware(benchmark::State& state) {
  const Image mosaic = Rendered(PixelFormat::kBayerRggb8, 1);
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        saccade::render::Demosaic(mosaic.view(), saccade::render::DemosaicMethod::kEdgeAware));
  }
  state.SetItemsProcessed(state.iterations() * kWidth * kHeight);
}
BENCHMARK(BM_DemosaicEdgeAware)->Unit(benchmark::kMillisecond);

// The bench scene's eye looking at a floor: depth from 6 m at the top row to 0.5 m at the
// bottom; the realistic preset's lens (6 mm, f/1.4, focused at 2 m, circles capped at 8 px).
void BM_DepthOfField(benchmark::State& state) {
  const Image rgb = Rendered(PixelFormat::kRgb8, 3);
  Image depth(kWidth, kHeight, PixelFormat::kFloat32);
  for (int y = 0; y < kHeight; ++y) {
    float* row = reinterpret_cast<float*>(depth.row(y));
    for (int x = 0; x < kWidth; ++x) row[x] = static_cast<float>(6.0 - 5.5 * y / (kHeight - 1));
  }
  saccade::render::ThinLensOptions lens;
  lens.focal_length_m = 0.006;
  lens.f_number = 1.4;
  lens.focus_distance_m = 2.0;
  lens.max_coc_px = 8.0;
  lens.pixel_pitch_m = 5.86e-6;
  const saccade::geometry::Intrinsics k(kWidth, kHeight, 1024.0, 1024.0, 511.5, 383.5);
  for (auto _ : state) {
    benchmark::DoNotOptimize(saccade::render::ApplyDepthOfField(rgb.view(), depth.view(), lens, k));
  }
  state.SetItemsProcessed(state.iterations() * kWidth * kHeight);
}
BENCHMARK(BM_DepthOfField)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
