// Spectral residual saliency on a 1024 x 768 RGB frame (the astronaut, stretched): the map at
// full size, the zones alone, and both. Run: build/bin/saliency_bench
#include <benchmark/benchmark.h>

#include <opencv2/imgproc.hpp>
#include <string>

#include "saccade/core/image_io.h"
#include "saccade/vision/saliency.h"

namespace {

saccade::Image Frame() {
  const saccade::Image photo =
      saccade::ReadImage(std::string(SACCADE_SOURCE_DIR) + "/assets/astronaut.png");
  saccade::Image frame(1024, 768, saccade::PixelFormat::kRgb8);
  const cv::Mat src(photo.height(), photo.width(), CV_8UC3, const_cast<uint8_t*>(photo.data()),
                    photo.stride());
  cv::Mat dst(frame.height(), frame.width(), CV_8UC3, frame.data(), frame.stride());
  cv::resize(src, dst, dst.size(), 0, 0, cv::INTER_LINEAR);
  return frame;
}

void BM_SaliencyMap(benchmark::State& state) {
  const saccade::Image frame = Frame();
  saccade::vision::SpectralResidualSaliency::Options options;
  options.working_width = static_cast<int>(state.range(0));
  const saccade::vision::SpectralResidualSaliency saliency(options);
  for (auto _ : state) benchmark::DoNotOptimize(saliency.Map(frame));
}
BENCHMARK(BM_SaliencyMap)->Arg(64)->Arg(128)->Unit(benchmark::kMillisecond);

void BM_SaliencyZones(benchmark::State& state) {
  const saccade::Image frame = Frame();
  saccade::vision::SpectralResidualSaliency::Options options;
  options.working_width = static_cast<int>(state.range(0));
  const saccade::vision::SpectralResidualSaliency saliency(options);
  for (auto _ : state) benchmark::DoNotOptimize(saliency.Zones(frame));
}
BENCHMARK(BM_SaliencyZones)->Arg(64)->Arg(128)->Unit(benchmark::kMillisecond);

void BM_SaliencyCompute(benchmark::State& state) {
  const saccade::Image frame = Frame();
  const saccade::vision::SpectralResidualSaliency saliency;
  for (auto _ : state) benchmark::DoNotOptimize(saliency.Compute(frame));
}
BENCHMARK(BM_SaliencyCompute)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
