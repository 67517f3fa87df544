// explore: exploration and mapping (issue 44, seed section 7.2) from the command line. The
// strategies of components/explore_session.h run one after another on the same scene, head
// and ground truth, and are compared in one report (text, and JSON with --json).

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "commands.h"
#include "saccade/components/explore_session.h"
#include "saccade/core/error.h"
#include "saccade/core/temporary_file.h"

namespace saccade::app {
// Named, not anonymous: the unity build puts every command's file in one translation unit.
namespace explore_command {

namespace fs = std::filesystem;
using components::ExploreReport;

struct Options {
  std::string scene = "scenes/explore_room.yaml";
  std::string head;
  std::string config;
  std::vector<std::string> strategies;
  std::optional<double> seconds;
  std::optional<uint64_t> seed;
  std::string json;     // a file, or "-" for standard output
  std::string map_dir;  // each strategy's map as <dir>/<strategy>.ply
  bool quiet = false;
};

double Quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  return values[static_cast<std::size_t>(
      std::min<double>(values.size() - 1, std::floor(q * values.size())))];
}

// Saccade amplitudes (the largest joint change, degrees) in bins.
const std::vector<double> kAmplitudeEdges = {0, 5, 10, 20, 40, 1e9};

std::vector<int> Histogram(const std::vector<double>& values) {
  std::vector<int> counts(kAmplitudeEdges.size() - 1, 0);
  for (double v : values) {
    for (std::size_t b = 0; b + 1 < kAmplitudeEdges.size(); ++b) {
      if (v >= kAmplitudeEdges[b] && v < kAmplitudeEdges[b + 1]) ++counts[b];
    }
  }
  return counts;
}

nlohmann::json ScoreJson(const mapping::MapScore& s) {
  return {{"completeness", s.completeness},
          {"mean_m", s.mean_m},
          {"rms_m", s.rms_m},
          {"p95_m", s.p95_m},
          {"map_points", s.map_points},
          {"truth_samples", s.truth_samples},
          {"outliers", s.outliers}};
}

nlohmann::json ReportJson(const ExploreReport& r) {
  nlohmann::json curve = nlohmann::json::array();
  for (const auto& c : r.curve) {
    curve.push_back(
        {{"time_s", c.time_s}, {"fixations", c.fixations}, {"completeness", c.completeness}});
  }
  const double n = std::max(1, r.fixations);
  return {
      {"strategy", r.strategy},
      {"seconds", r.seconds},
      {"fixations", r.fixations},
      {"unreachable_targets", r.unreachable_targets},
      {"time_to_50_s",
       r.time_to_50_s < 0 ? nlohmann::json(nullptr) : nlohmann::json(r.time_to_50_s)},
      {"time_to_80_s",
       r.time_to_80_s < 0 ? nlohmann::json(nullptr) : nlohmann::json(r.time_to_80_s)},
      {"completeness_curve", curve},
      {"map", ScoreJson(r.score)},
      {"map_1_to_3m", ScoreJson(r.score_1_to_3m)},
      {"map_voxels", r.map_voxels},
      {"map_bytes", r.map_bytes},
      {"saccade_amplitudes_deg", r.saccade_amplitudes_deg},
      {"saccade_amplitude_histogram",
       {{"edges_deg", {0, 5, 10, 20, 40}}, {"counts", Histogram(r.saccade_amplitudes_deg)}}},
      {"cost_ms_per_fixation",
       {{"render", r.costs.render_ms / n},
        {"depth", r.costs.depth_ms / n},
        {"fusion", r.costs.fusion_ms / n},
        {"attention", r.costs.attention_ms / n},
        {"scoring", r.costs.scoring_ms / n}}},
      {"fixations_per_wall_second", r.fixations / std::max(1e-9, r.costs.total_ms / 1000)},
  };
}

std::string Seconds(double s) { return s < 0 ? "never" : fmt::format("{:.1f} s", s); }

void PrintReport(const std::vector<ExploreReport>& reports, const components::ExploreTruth& truth) {
  fmt::print("\n{} truth samples (the surface the head can see, {} views, rendered in {:.1f} s)\n",
             truth.samples_W.size(), truth.views, truth.render_ms / 1000);
  fmt::print("\n{:<10} {:>9} {:>9} {:>9} {:>12} {:>22} {:>22}\n", "strategy", "fixations",
             "to 50 %", "to 80 %", "complete", "map-truth mean/RMS/p95", "at 1-3 m RMS");
  for (const ExploreReport& r : reports) {
    fmt::print("{:<10} {:>9} {:>9} {:>9} {:>11.1f}% {:>8.1f}/{:.1f}/{:.1f} mm {:>19.1f} mm\n",
               r.strategy, r.fixations, Seconds(r.time_to_50_s), Seconds(r.time_to_80_s),
               100 * r.score.completeness, 1000 * r.score.mean_m, 1000 * r.score.rms_m,
               1000 * r.score.p95_m, 1000 * r.score_1_to_3m.rms_m);
  }
  fmt::print(
      "\nsaccade amplitudes (largest joint change), median / 90th percentile / max, and "
      "counts in 0-5-10-20-40-more deg:\n");
  for (const ExploreReport& r : reports) {
    const std::vector<int> h = Histogram(r.saccade_amplitudes_deg);
    fmt::print("  {:<10} {:5.1f} / {:5.1f} / {:5.1f} deg   [{} {} {} {} {}]\n", r.strategy,
               Quantile(r.saccade_amplitudes_deg, 0.5), Quantile(r.saccade_amplitudes_deg, 0.9),
               Quantile(r.saccade_amplitudes_deg, 1.0), h[0], h[1], h[2], h[3], h[4]);
  }
  fmt::print(
      "\ncost per fixation (wall clock, ms): render / depth / fusion / attention / "
      "scoring; fixations per second\n");
  for (const ExploreReport& r : reports) {
    const double n = std::max(1, r.fixations);
    fmt::print("  {:<10} {:6.0f} / {:6.0f} / {:6.0f} / {:6.0f} / {:6.0f};  {:.2f}/s\n", r.strategy,
               r.costs.render_ms / n, r.costs.depth_ms / n, r.costs.fusion_ms / n,
               r.costs.attention_ms / n, r.costs.scoring_ms / n,
               r.fixations / std::max(1e-9, r.costs.total_ms / 1000));
  }
  fmt::print("\ncompleteness over simulated time:\n");
  for (const ExploreReport& r : reports) {
    std::string line;
    for (const auto& c : r.curve) line += fmt::format(" {:.0f}", 100 * c.completeness);
    fmt::print("  {:<10}{}  (%, every sample)\n", r.strategy, line);
  }
}

void WriteJson(const std::string& path, const nlohmann::json& json) {
  if (path == "-") {
    fmt::print("{}\n", json.dump(2));
    return;
  }
  const fs::path temporary = TemporaryPathFor(path, 0);
  {
    std::ofstream out(temporary);
    out << json.dump(2) << "\n";
    if (!out) throw FileError(path, 0, "", "cannot write the report");
  }
  fs::rename(temporary, path);
}

int RunExplore(const Options& o) {
  components::ExploreConfig config;
  if (!o.config.empty()) config = components::LoadExploreConfig(o.config);
  if (!o.strategies.empty()) config.strategies = o.strategies;
  if (o.seconds) config.options.seconds = *o.seconds;
  if (o.seed) config.options.seed = *o.seed;
  for (const std::string& s : config.strategies) {
    components::ExploreOptions check = config.options;
    check.strategy = s;
    std::string error;
    if (!check.IsValid(&error)) throw InvalidArgument(error);
  }
  if (!o.map_dir.empty() && !fs::is_directory(o.map_dir)) {
    throw InvalidArgument("--map-dir " + o.map_dir + ": not a folder");
  }
  scene::LoadOptions load;
  if (!o.head.empty()) load.head = o.head;
  const scene::Scene scene = scene::Scene::Load(ShippedFile(o.scene), load);
  if (!o.quiet) fmt::print(stderr, "explore: rendering the ground truth of {}\n", o.scene);
  const components::ExploreTruth truth = components::MakeExploreTruth(scene, config.options);
  std::vector<ExploreReport> reports;
  for (const std::string& strategy : config.strategies) {
    components::ExploreOptions options = config.options;
    options.strategy = strategy;
    mapping::WorldMap map(options.map);
    int last_second = -1;
    reports.push_back(
        components::Explore(scene, options, truth, &map, [&](int fixations, double time) {
          if (o.quiet || static_cast<int>(time) == last_second) return;
          last_second = static_cast<int>(time);
          fmt::print(stderr, "\rexplore: {:<9} {:5.1f} / {:.0f} s simulated, {} fixations",
                     strategy, time, options.seconds, fixations);
        }));
    if (!o.quiet) fmt::print(stderr, "\n");
    if (!o.map_dir.empty()) map.WritePly(fs::path(o.map_dir) / (strategy + ".ply"));
  }
  if (o.json != "-") PrintReport(reports, truth);
  if (!o.json.empty()) {
    nlohmann::json json = {{"scene", o.scene},
                           {"head", scene.robot()->head.name()},
                           {"seconds", config.options.seconds},
                           {"truth_samples", truth.samples_W.size()},
                           {"strategies", nlohmann::json::array()}};
    for (const ExploreReport& r : reports) json["strategies"].push_back(ReportJson(r));
    WriteJson(o.json, json);
  }
  return 0;
}

}  // namespace explore_command

Runner AddExploreCommand(CLI::App& app) {
  auto o = std::make_shared<explore_command::Options>();
  CLI::App* c = app.add_subcommand(
      "explore",
      "Explore a scene and map it (seed 7.2): the head fixates where a strategy says, fuses "
      "each fixation's dense stereo depth into an occupancy map (OctoMap), and the map is "
      "scored against the scene's ground truth: completeness over time (the share of the "
      "visible surface within 2 cm of the map), accuracy (mean, RMS, 95th percentile), the "
      "fixations and their saccade amplitudes. Strategies, compared in one report: raster (a "
      "boustrophedon scan of the head's reach), random (random saccades), saliency (two-stage "
      "attention: spectral-residual saliency zones, novelty from the map's unknown space and "
      "once-seen surfaces, "
      "inhibition of return in 3D). Deterministic in simulated time.");
  c->add_option("--scene", o->scene,
                "scene file (scenes/explore_wall.yaml, explore_shelf.yaml, "
                "explore_room.yaml ship for it)")
      ->capture_default_str();
  c->add_option("--head", o->head, "a head file (robots/*.yaml) in place of the scene's head");
  c->add_option("--config", o->config,
                "settings file (config/explore.yaml documents every key and its default)");
  c->add_option("--strategy", o->strategies,
                "strategies to run and compare (raster, random, saliency; default: all three)")
      ->check(CLI::IsMember(components::ExploreStrategies()));
  c->add_option("--seconds", o->seconds, "simulated seconds each strategy explores (30)");
  c->add_option("--seed", o->seed, "seed of the random saccades (1)");
  c->add_option("--json", o->json,
                "write the report as JSON to this file ('-': standard output "
                "instead of the text)");
  c->add_option("--map-dir", o->map_dir,
                "write each strategy's final map as FOLDER/<strategy>.ply (points, metres, world)");
  c->add_flag("--quiet", o->quiet, "no progress on standard error");
  return [o] { return explore_command::RunExplore(*o); };
}

}  // namespace saccade::app
