#include "saccade/components/demo/summary.h"

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>

#include "saccade/components/demo/loop_outputs.h"

namespace saccade::components::demo {

using nlohmann::json;

CaptureToCommand::CaptureToCommand(const runtime::PipelineSpec& spec, const std::string& cameras,
                                   const std::string& head) {
  std::string commander;
  for (const runtime::ComponentSpec& c : spec.components) {
    if (c.name != head) continue;
    for (const runtime::ConnectionSpec& input : c.inputs) {
      if (input.to_input == "command") commander = input.from_component;
    }
  }
  for (std::size_t i = 0; i < spec.components.size(); ++i) {
    if (spec.components[i].name == cameras) cameras_index_ = i;
    if (!commander.empty() && spec.components[i].name == commander) commander_index_ = i;
  }
}

void CaptureToCommand::Add(const runtime::StepTiming& timing) {
  if (!cameras_index_ || !commander_index_ || timing.finished.size() <= *commander_index_ ||
      timing.finished.size() <= *cameras_index_) {
    return;
  }
  const double captured = timing.finished[*cameras_index_];
  const double commanded = timing.finished[*commander_index_];
  if (captured > 0.0 && commanded >= captured) ms_.Add(1e3 * (commanded - captured));
}

LoopFigures::LoopFigures(runtime::Pipeline& pipeline) {
  Tap<FacesMessage>(pipeline, [this](const FacesMessage& m) {
    if (m.image) captured_.push_back(m.image->metadata().time);
  });
}

void LoopFigures::AfterStep(double time, const Latest& latest) {
  for (const double captured : captured_) age_ms_.Add(1e3 * std::max(0.0, time - captured));
  captured_.clear();
  for (const auto& [camera, image] : latest.images) {
    if (!image) continue;
    const ImageMetadata& m = image->metadata();
    const auto [last, first] = last_frame_.emplace(camera, m.frame_index);
    if (!first && last->second == m.frame_index) continue;  // counted already
    last->second = m.frame_index;
    ++exposure_samples_[m.exposure_samples];
  }
}

namespace {
// {"1": frames, "3": frames, ...}: frames by their motion-blur sub-frames.
json ExposureJson(const std::map<int, int64_t>& samples) {
  json out = json::object();
  for (const auto& [n, frames] : samples) out[std::to_string(n)] = frames;
  return out;
}
}  // namespace

double DemoSummary::steps_per_second() const {
  return run.steps / std::max(run.wall_seconds, 1e-9);
}

double DemoSummary::real_time_factor() const {
  return sim_time() / std::max(run.wall_seconds, 1e-9);
}

json DemoSummary::Json() const {
  json stages = json::array();
  for (const runtime::ComponentTiming& c : run.components) {
    stages.push_back({{"name", c.name},
                      {"median_ms", c.median_ms},
                      {"p95_ms", c.p95_ms},
                      {"mean_ms", c.mean_ms},
                      {"max_ms", c.max_ms}});
  }
  json scored = json::array();
  for (const Fixation& f : fixations) scored.push_back(FixationJson(f));
  json errors = json::array();
  for (const runtime::StepError& e : run.errors) errors.push_back(e.ToString());
  const StreamingStats& latency = capture_to_command_ms;
  json out = {
      {"pipeline", pipeline},
      {"scene", scene.empty() ? json(nullptr) : json(scene)},
      {"steps", run.steps},
      {"sim_time_s", sim_time()},
      {"wall_s", run.wall_seconds},
      {"real_time_factor", real_time_factor()},
      {"steps_per_second", steps_per_second()},
      {"overruns", realtime ? json(run.overruns) : json(nullptr)},
      {"faces", faces_total},
      {"faces_fixated", faces_fixated},
      {"fixations", scored},
      {"decoys", decoys},
      {"latency_ms",
       {{"capture_to_command",
         {{"median", latency.Quantile(0.5)},
          {"p95", latency.Quantile(0.95)},
          {"max", latency.max()}}},
        {"detection_age",
         {{"count", detection_age_ms.count()},
          {"median", detection_age_ms.Quantile(0.5)},
          {"p95", detection_age_ms.Quantile(0.95)},
          {"max", detection_age_ms.max()}}},
        {"stages", stages}}},
      {"exposure_samples", ExposureJson(exposure_samples)},
      {"overhead_share", run.overhead_share},
      {"overhead_ms", {{"median", run.overhead_median_ms}, {"p95", run.overhead_p95_ms}}},
      {"errors", errors},
      {"hardware", hardware_file.empty() ? json(nullptr) : json(hardware_file)},
      {"ground_truth", truth},
      {"cameras", pair_counts ? json({{"pairs", pair_counts->pairs},
                                      {"dropped_left", pair_counts->dropped_left},
                                      {"dropped_right", pair_counts->dropped_right}})
                              : json(nullptr)},
      {"head", head ? runtime::MessageTraits<HeadStatusMessage>::ToJson(*head) : json(nullptr)},
      {"interrupted", interrupted}};
  if (!record.empty()) {
    out["record"] = {{"folder", record},
                     {"frames", recorded_frames},
                     {"video", (std::filesystem::path(record) / "demo.avi").string()}};
  }
  return out;
}

std::string DemoSummary::BriefReport() const {
  if (truth) {
    return fmt::format(
        "{} of {} faces fixated in {:.2f} s of simulated time ({} steps, {:.1f} s wall)",
        faces_fixated, faces_total, sim_time(), run.steps, run.wall_seconds);
  }
  return fmt::format("{} faces fixated in {:.2f} s ({} steps, {:.1f} s wall)", faces_fixated,
                     sim_time(), run.steps, run.wall_seconds);
}

std::string DemoSummary::FullReport() const {
  std::string out = "\n" + BriefReport() + "\n";
  out += fmt::format("{:.1f} steps per second, real-time factor {:.2f} (simulated s per wall s)\n",
                     steps_per_second(), real_time_factor());
  // The lines above give each fixation's errors as it began; over the whole fixation (pursuit
  // of a moving face included), the largest:
  std::string dwell;
  for (const Fixation& f : fixations) {
    if (!f.has_truth || f.dwell_samples == 0) continue;
    dwell += fmt::format("  {:<16} L {:.3f} R {:.3f} deg  (mean {:.3f} / {:.3f} over {} steps)\n",
                         f.object, f.dwell_max_deg[0], f.dwell_max_deg[1],
                         f.dwell_sum_deg[0] / f.dwell_samples, f.dwell_sum_deg[1] / f.dwell_samples,
                         f.dwell_samples);
  }
  if (!dwell.empty()) out += "eye axis error over each fixation, largest:\n" + dwell;
  if (realtime) {
    // A step that ends after the next tick was due: the loop skips the missed ticks (no
    // backlog, no burst), so this counts the camera periods it could not keep.
    out += fmt::format("real time: {} of {} steps overran their period of {:.1f} ms\n",
                       run.overruns, run.steps, 1e3 * dt);
  }
  if (pair_counts) out += fmt::format("cameras: {}\n", cameras_description);
  if (!exposure_samples.empty()) {
    out += "motion blur: frames by sub-frames drawn";
    for (const auto& [n, frames] : exposure_samples) out += fmt::format("  {}: {}", n, frames);
    out += "\n";
  }
  if (head) {
    const HeadStatusMessage& h = *head;
    out += fmt::format(
        "head: {}{}: {} commands, {} rejected, {} clamped or limited, {} watchdog stops{}{}\n",
        h.driver, h.mirror ? " (mirroring the virtual head)" : "", h.commands, h.rejected_commands,
        h.limited_commands, h.watchdog_trips, h.emergency_stopped ? ", EMERGENCY STOP" : "",
        h.fault.empty() ? "" : ", FAULT: " + h.fault);
  }
  for (const json& d : decoys) {
    out +=
        fmt::format("decoy {}: {} ({} detections on it rejected{})\n", d["name"].get<std::string>(),
                    d["fixated"].get<bool>() ? "FIXATED (not rejected)" : "rejected, never fixated",
                    d["rejected_detections"].get<int>(),
                    d["by_reason"].empty() ? "" : ": " + d["by_reason"].dump());
  }
  out += "\nlatency per stage (ms, wall clock on this machine):\n";
  out += fmt::format("  {:<14} {:>8} {:>8} {:>8}\n", "stage", "median", "p95", "max");
  for (const runtime::ComponentTiming& c : run.components) {
    out += fmt::format("  {:<14} {:>8.2f} {:>8.2f} {:>8.2f}\n", c.name, c.median_ms, c.p95_ms,
                       c.max_ms);
  }
  const StreamingStats& latency = capture_to_command_ms;
  out += fmt::format("  capture -> motor command: median {:.2f} ms, p95 {:.2f} ms, max {:.2f} ms\n",
                     latency.Quantile(0.5), latency.Quantile(0.95), latency.max());
  if (detection_age_ms.count() > 0) {
    out += fmt::format(
        "  age of the faces used (capture -> received): median {:.1f} ms, p95 {:.1f} ms, max "
        "{:.1f} ms\n",
        detection_age_ms.Quantile(0.5), detection_age_ms.Quantile(0.95), detection_age_ms.max());
  }
  out += fmt::format(
      "  outside the components (messaging, scheduling): {:.4f} ms/step median, "
      "{:.3f} % of the loop\n",
      run.overhead_median_ms, 100.0 * run.overhead_share);
  if (!record.empty()) {
    out +=
        fmt::format("\nrecorded to {}: frames/, demo.avi, summary.json, fixation_*.png\n", record);
  }
  return out;
}

std::string FixationText(const Fixation& f, double t) {
  const double took = f.fixated_at ? *f.fixated_at - f.selected_at : 0.0;
  if (f.is_face && !f.has_truth) {
    return fmt::format(
        "t = {:6.2f} s  fixated {:<16} at {:.2f} m  (triangulated; no ground truth)  "
        "took {:.2f} s  ({})\n",
        t, f.object, f.distance_m, took, f.source);
  }
  if (f.is_face) {
    return fmt::format(
        "t = {:6.2f} s  fixated {:<16} at {:.2f} m  3D error {:5.1f} mm  eye axis error "
        "L {:.3f} deg R {:.3f} deg  took {:.2f} s  ({})\n",
        t, f.object, f.distance_m, 1e3 * f.error_3d_m, f.left_error_deg, f.right_error_deg, took,
        f.source);
  }
  return fmt::format("t = {:6.2f} s  fixated {} (not a face)  took {:.2f} s\n", t, f.object, took);
}

}  // namespace saccade::components::demo
