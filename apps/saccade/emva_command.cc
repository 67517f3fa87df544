// emva: the EMVA 1288 measurement of a simulated sensor (a scene's camera, a preset or figures
// given as options), or of a real camera's image files (--images DIR).

#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "commands.h"
#include "saccade/core/error.h"
#include "saccade/core/image_io.h"
#include "saccade/core/temporary_file.h"
#include "saccade/render/emva_files.h"
#include "saccade/render/emva_measurement.h"
#include "saccade/render/sensor_model.h"
#include "saccade/scene/scene.h"

namespace saccade::app {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// Exposure a legacy-noise camera is measured at when its scene gives none (seconds).
constexpr double kDefaultLegacyExposure = 0.01;

struct EmvaOptions {
  std::string scene;
  std::string camera;
  std::string preset;
  // Figures given as options: they replace the preset's, or the scene camera's.
  std::optional<double> quantum_efficiency, gain, dark_noise, saturation, dsnu, prnu, black_level,
      photons_per_second;
  std::optional<int> bit_depth;
  uint64_t seed = 0;
  int size = 256;
  render::EmvaSeriesOptions series;
  std::string write_images;
  std::string images;
  std::string photons;
  int channel = 0;
  std::string json_path;
  bool quiet = false;
};

// The camera's sensor of the scene, as an EMVA 1288 sensor; its seed and name into `seed`,
// `name`.
scene::EmvaSensor SceneSensor(const EmvaOptions& o, uint64_t* seed, std::string* name) {
  const scene::Scene scene = scene::Scene::Load(o.scene);
  if (scene.cameras().empty()) throw InvalidArgument("emva: the scene has no camera");
  const scene::CameraSpec* camera =
      o.camera.empty() ? &scene.cameras().front() : scene.FindCamera(o.camera);
  if (camera == nullptr) {
    throw InvalidArgument(
        fmt::format("emva: --camera '{}': no such camera in {}", o.camera, o.scene));
  }
  *seed = camera->sensor.seed;
  *name = camera->name;
  if (camera->sensor.emva) return *camera->sensor.emva;
  if (camera->sensor.gain_dn_per_e > 0.0) {
    const double exposure =
        camera->sensor.exposure > 0.0 ? camera->sensor.exposure : kDefaultLegacyExposure;
    return scene::EmvaFromLegacyNoise(camera->sensor.read_noise_dn, camera->sensor.gain_dn_per_e,
                                      exposure);
  }
  throw InvalidArgument(
      fmt::format("emva: camera '{}' has no sensor to measure: give its sensor an emva block or a "
                  "gain_dn_per_e",
                  camera->name));
}

scene::EmvaSensor SensorFrom(const EmvaOptions& o, uint64_t* seed, std::string* name) {
  scene::EmvaSensor s;
  *seed = o.seed;
  *name = "emva";
  if (!o.scene.empty()) {
    s = SceneSensor(o, seed, name);
  } else if (!o.preset.empty()) {
    const std::optional<scene::EmvaSensor> preset = scene::FindEmvaPreset(o.preset);
    if (!preset) {
      throw InvalidArgument(fmt::format("emva: --preset '{}': the presets are {}", o.preset,
                                        fmt::join(scene::EmvaPresetNames(), ", ")));
    }
    s = *preset;
  }
  if (o.quantum_efficiency) s.quantum_efficiency = *o.quantum_efficiency;
  if (o.gain) s.gain_dn_per_e = *o.gain;
  if (o.dark_noise) s.dark_noise_e = *o.dark_noise;
  if (o.saturation) s.saturation_e = *o.saturation;
  if (o.dsnu) s.dsnu_e = *o.dsnu;
  if (o.prnu) s.prnu_percent = *o.prnu;
  if (o.bit_depth) s.bit_depth = *o.bit_depth;
  if (o.black_level) s.black_level_dn = *o.black_level;
  if (o.photons_per_second) s.photons_per_second = *o.photons_per_second;
  try {
    s.Validate();
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(std::string("emva: the sensor: ") + e.what());
  }
  return s;
}

json SensorJson(const scene::EmvaSensor& s) {
  return {{"preset", s.preset},
          {"quantum_efficiency", s.quantum_efficiency},
          {"gain_dn_per_e", s.gain_dn_per_e},
          {"dark_noise_e", s.dark_noise_e},
          {"saturation_e", s.saturation_e},
          {"dsnu_e", s.dsnu_e},
          {"prnu_percent", s.prnu_percent},
          {"bit_depth", s.bit_depth},
          {"black_level_dn", s.black_level_dn},
          {"photons_per_second", s.photons_per_second}};
}

json ResultJson(const render::EmvaResult& r) {
  const auto number = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
  json points = json::array();
  for (const render::EmvaPoint& p : r.points) {
    points.push_back({{"exposure_s", p.exposure_s},
                      {"photons", number(p.photons)},
                      {"mu_y_dark", p.dark.mean},
                      {"sigma2_y_dark", p.dark.variance},
                      {"mu_y", p.bright.mean},
                      {"sigma2_y", p.bright.variance}});
  }
  const auto stack = [](const render::StackStats& s) {
    return json{{"frames", s.frames},
                {"mean", s.mean},
                {"spatial_variance", s.spatial_variance},
                {"temporal_variance", s.temporal_variance}};
  };
  return {{"gain_dn_per_e", r.gain_dn_per_e},
          {"gain_intercept_dn2", r.gain_intercept},
          {"fit_points", r.fit_points},
          {"dark_noise_e", r.dark_noise_e},
          {"saturation_e", r.saturation_e},
          {"full_well_e", r.full_well_e},
          {"dsnu_e", r.dsnu_e},
          {"dsnu_dn", r.dsnu_dn},
          {"prnu_percent", r.prnu_percent},
          {"quantum_efficiency", number(r.quantum_efficiency)},
          {"mu_y_dark", r.mu_y_dark},
          {"sigma_y_dark", r.sigma_y_dark},
          {"snr_max_db", r.snr_max_db},
          {"dynamic_range_db", r.dynamic_range_db},
          {"saturation_index", r.saturation_index},
          {"dark_stack", stack(r.dark_stack)},
          {"bright_stack", stack(r.bright_stack)},
          {"points", points}};
}

void WriteJsonAtomically(const json& document, const fs::path& path) {
  const fs::path temporary = TemporaryPathFor(path, 0);
  {
    std::ofstream out(temporary);
    out << document.dump(2) << "\n";
    if (!out) {
      std::error_code ignored;
      fs::remove(temporary, ignored);
      throw FileError(path.string(), 0, "", "cannot write the JSON file");
    }
  }
  std::error_code error;
  fs::rename(temporary, path, error);
  if (error) {
    fs::remove(temporary, error);
    throw FileError(path.string(), 0, "", "cannot write the JSON file");
  }
}

// Mode A: the series through the simulated sensor; its frames to `write_images` if given.
render::EmvaResult MeasureSimulated(const EmvaOptions& o, const scene::EmvaSensor& params,
                                    uint64_t seed, const std::string& name) {
  const render::SensorModel sensor(params, seed, name, o.size, o.size, 1);
  render::EmvaFrameSink sink;
  std::ofstream photons_csv;
  const fs::path dir(o.write_images);  // outlives the sink, which refers to it
  if (!o.write_images.empty()) {
    if (fs::exists(dir) && !fs::is_empty(dir)) {
      throw FileError(dir.string(), 0, "", "--write-images: expected a new or empty folder");
    }
    fs::create_directories(dir);
    photons_csv.open(dir / "photons.csv");
    photons_csv << "exposure_us,photons\n";
    sink = [&](const std::string& kind, double exposure_s, int index,
               const std::vector<uint16_t>& raw) {
      const fs::path file = dir / render::EmvaFileName(kind, exposure_s, index);
      const ImageView view(reinterpret_cast<const uint8_t*>(raw.data()), o.size, o.size,
                           PixelFormat::kGray16);
      WritePng(view, file);
      if (kind == "flat" && index == 0) {
        const std::string flat = render::EmvaFileName(kind, exposure_s, index);
        const std::string us = flat.substr(5, flat.size() - 5 - 6);  // flat_<us>_0.png
        photons_csv << fmt::format("{},{}\n", us, params.photons_per_second * exposure_s);
      }
    };
  }
  return render::MeasureSensor(sensor, o.series, sink);
}

int RunEmva(const EmvaOptions& o) {
  if (const std::string error = o.series.Check(); !error.empty()) {
    throw InvalidArgument("emva: " + error);
  }
  json document;
  render::EmvaResult result;
  if (!o.images.empty()) {
    result = render::MeasureImageFiles(o.images, o.photons, o.channel);
    document["source"] = {{"images", o.images}};
  } else {
    uint64_t seed = 0;
    std::string name;
    const scene::EmvaSensor params = SensorFrom(o, &seed, &name);
    result = MeasureSimulated(o, params, seed, name);
    document["source"] = {
        {"sensor", SensorJson(params)}, {"seed", seed}, {"camera", name}, {"size_px", o.size}};
  }
  document["result"] = ResultJson(result);
  if (!o.json_path.empty()) WriteJsonAtomically(document, o.json_path);
  if (!o.quiet) {
    std::cout << "Photon transfer curve (EMVA 1288; DN, DN^2):\n"
              << result.CurveTable() << "\n"
              << result.BriefReport();
  }
  return 0;
}

void AddSensorOptions(CLI::App* emva, EmvaOptions* o) {
  emva->add_option("--quantum-efficiency", o->quantum_efficiency, "eta, electrons per photon");
  emva->add_option("--gain", o->gain, "System gain K, DN per electron");
  emva->add_option("--dark-noise", o->dark_noise, "Temporal dark noise sigma_d, electrons");
  emva->add_option("--saturation", o->saturation, "Saturation capacity (full well), electrons");
  emva->add_option("--dsnu", o->dsnu, "DSNU, electrons");
  emva->add_option("--prnu", o->prnu, "PRNU, percent");
  emva->add_option("--bit-depth", o->bit_depth, "Bits of the raw DN, 8 .. 16");
  emva->add_option("--black-level", o->black_level, "Black level (offset), DN");
  emva->add_option("--photons-per-second", o->photons_per_second,
                   "Photons a pixel collects per second at full white");
}

}  // namespace

Runner AddEmvaCommand(CLI::App& app) {
  auto o = std::make_shared<EmvaOptions>();
  auto* emva = app.add_subcommand(
      "emva",
      "EMVA 1288 measurement, as a camera lab does it: dark and flat-field pairs over a series "
      "of exposures from dark to beyond saturation, and stacks for the nonuniformity; prints "
      "the photon transfer curve and the figures (K, temporal dark noise, saturation "
      "capacity, DSNU1288, PRNU1288, quantum efficiency when photons are known). Of a "
      "simulated sensor (a scene's camera, --preset or the figures as options: uniformly lit, "
      "no lens), or of a real camera's files (--images DIR). docs/sensor.md.");
  emva->add_option("--scene", o->scene, "Scene YAML: measure a camera's sensor")
      ->check(CLI::ExistingFile);
  emva->add_option("--camera", o->camera, "The scene's camera (default: its first)");
  emva->add_option(
      "--preset", o->preset,
      "A sensor preset: " + fmt::format("{}", fmt::join(scene::EmvaPresetNames(), ", ")));
  AddSensorOptions(emva, o.get());
  emva->add_option("--seed", o->seed, "Noise seed without --scene (default 0)");
  emva->add_option("--size", o->size,
                   "Side of the simulated sensor's square region, px (default 256)")
      ->check(CLI::Range(8, 2048));
  emva->add_option("--points", o->series.points, "Exposures of the even series (default 40)");
  emva->add_option("--refine", o->series.refine_points,
                   "More exposures around saturation (default 16)");
  emva->add_option("--stack", o->series.stack_frames,
                   "Frames of each nonuniformity stack, L (default 16)");
  emva->add_option("--write-images", o->write_images,
                   "Also write the simulated frames as 16-bit PNG in --images' naming, with "
                   "photons.csv, into this new folder");
  emva->add_option("--images", o->images,
                   "Measure image files instead: dark_<exposure_us>_<k>.png and "
                   "flat_<exposure_us>_<k>.png, k = 0, 1 (the pair), more at one exposure "
                   "(the stack)");
  emva->add_option("--photons", o->photons,
                   "With --images: CSV of 'exposure_us,photons' (mean photons a pixel) for "
                   "the quantum efficiency")
      ->check(CLI::ExistingFile);
  emva->add_option("--channel", o->channel, "With --images: the colour channel of RGB files")
      ->check(CLI::Range(0, 3));
  emva->add_option("--json", o->json_path, "Write the figures and the curve to this JSON file");
  emva->add_flag("--quiet", o->quiet, "Print nothing (with --json)");
  emva->callback([o] {
    if (!o->images.empty() &&
        (!o->scene.empty() || !o->preset.empty() || !o->write_images.empty())) {
      throw CLI::ValidationError("--images",
                                 "measures files: give no --scene, --preset or --write-images");
    }
    if (!o->scene.empty() && !o->preset.empty()) {
      throw CLI::ValidationError("--preset", "give --scene or --preset, not both");
    }
    if (!o->photons.empty() && o->images.empty()) {
      throw CLI::ValidationError("--photons", "only with --images");
    }
  });
  return [o] { return RunEmva(*o); };
}

}  // namespace saccade::app
