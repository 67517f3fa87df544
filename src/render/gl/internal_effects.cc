#include "render/gl/internal_effects.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <string>
#include <vector>

#include "render/gl/internal_cpu_lens.h"
#include "render/gl/internal_effect_shaders.h"
#include "render/gl/internal_gl_util.h"
#include "saccade/core/error.h"

namespace saccade::render::gl {
namespace {

// Texture units of the effect passes (unit 0 belongs to the scene passes' material textures).
constexpr GLint kSourceUnit = 1;
constexpr GLint kMapUnit = 2;
constexpr GLint kIdsUnit = 3;
constexpr GLint kZUnit = 4;
constexpr GLint kFootprintUnit = 5;
constexpr GLint kGaussUnit = 6;
constexpr GLint kResidualUnit = 7;

// The lens remap's samples of a pixel's footprint (kFinalFragmentSource): one per
// kTapSpacing source pixels of the footprint's side, at most kMaxTaps a side. Up to 1.5 source
// pixels a pixel step, one bilinear sample reads every source pixel the step crosses; beyond,
// it skips some and aliases. Measured on llvmpipe (tests/render/calibration_test.cc): one
// sample everywhere leaves a fisheye's chessboard corners 0.06 px RMS (0.26 px at worst, on
// its rim) from OpenCV's, 1.5 gives 0.027 px (0.10 px), 1.0 0.025 px (0.06 px) and the strong
// radtan lens 0.018 instead of 0.032 px RMS, but samples 2 x 2 almost everywhere: the bench
// scene's distortion then costs 48 ms a stereo frame instead of 20. A lens that compresses
// the source by more than 6 (the rim of a fisheye that sees behind itself) is sampled 4 x 4.
constexpr double kTapSpacing = 1.5;
constexpr int kMaxTaps = 4;

// The map's step from pixel i towards its neighbour at +-stride (same row or column), within
// pixel i's view: central where both neighbours are in it, one-sided where one is, zero where
// none is. `first`/`last`: whether i is at the start/end of its row (or column).
Eigen::Vector2f MapStep(const std::vector<float>& map, std::size_t i, std::size_t stride,
                        bool first, bool last) {
  const float view = map[3 * i + 2];
  const bool use_next = !last && map[3 * (i + stride) + 2] == view;
  const bool use_previous = !first && map[3 * (i - stride) + 2] == view;
  const Eigen::Vector2f at(map[3 * i], map[3 * i + 1]);
  const auto point = [&map](std::size_t j) { return Eigen::Vector2f(map[3 * j], map[3 * j + 1]); };
  if (use_next && use_previous) return 0.5f * (point(i + stride) - point(i - stride));
  if (use_next) return point(i + stride) - at;
  if (use_previous) return at - point(i - stride);
  return Eigen::Vector2f::Zero();
}

}  // namespace

RemapTable MakeRemapTable(const geometry::LensMap& lens) {
  RemapTable table;
  const std::size_t n = static_cast<std::size_t>(lens.width) * lens.height;
  table.map.resize(4 * n);
  table.footprint.assign(4 * n, 0.0f);
  for (int v = 0; v < lens.height; ++v) {
    for (int u = 0; u < lens.width; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * lens.width + u;
      std::copy_n(&lens.map[3 * i], 3, &table.map[4 * i]);
      int nu = 1, nv = 1;
      if (lens.map[3 * i + 2] >= 0.0f) {
        const Eigen::Vector2f du = MapStep(lens.map, i, 1, u == 0, u == lens.width - 1);
        const Eigen::Vector2f dv = MapStep(lens.map, i, lens.width, v == 0, v == lens.height - 1);
        const auto taps = [](const Eigen::Vector2f& step) {
          return std::clamp(static_cast<int>(std::ceil(step.norm() / kTapSpacing)), 1, kMaxTaps);
        };
        nu = taps(du);
        nv = taps(dv);
        table.footprint[4 * i] = du.x();
        table.footprint[4 * i + 1] = du.y();
        table.footprint[4 * i + 2] = dv.x();
        table.footprint[4 * i + 3] = dv.y();
      }
      table.map[4 * i + 3] = static_cast<float>(nu + 16 * nv);
      if (nu * nv > 1) ++table.multi_tap_pixels;
    }
  }
  return table;
}

namespace {

// Builds LensMesh's cells (see internal_effects.h).
class LensMeshBuilder {
 public:
  LensMeshBuilder(const RemapTable& table, int width, int height, double tolerance)
      : table_(table), width_(width), height_(height), tolerance_(tolerance) {
    // The source position at each pixel corner (X, Y) (window coordinates, integers): the
    // map bilinearly interpolated between the four pixel centres around it, extrapolated at the
    // image's edges; invalid where they do not share one view.
    corners_.resize(static_cast<std::size_t>(width + 1) * (height + 1));
    for (int Y = 0; Y <= height; ++Y) {
      for (int X = 0; X <= width; ++X) corners_[Index(X, Y)] = Corner(X, Y);
    }
  }

  LensMesh Build() {
    mesh_.residual.assign(2 * static_cast<std::size_t>(width_) * height_, 0);
    for (int y = 0; y < height_; y += kLensCell) {
      for (int x = 0; x < width_; x += kLensCell) {
        Add(x, y, std::min(kLensCell, width_ - x), std::min(kLensCell, height_ - y));
      }
    }
    return std::move(mesh_);
  }

 private:
  struct Source {
    Eigen::Vector2f p = Eigen::Vector2f::Zero();  // as the vertex holds it
    float view = -1.0f;                           // < 0: invalid
  };

  std::size_t Index(int X, int Y) const { return static_cast<std::size_t>(Y) * (width_ + 1) + X; }
  const float* Map(int u, int v) const {
    return &table_.map[4 * (static_cast<std::size_t>(v) * width_ + u)];
  }

  Source Corner(int X, int Y) const {
    if (width_ < 2 || height_ < 2) return {};
    const int u0 = std::clamp(X - 1, 0, width_ - 2), v0 = std::clamp(Y - 1, 0, height_ - 2);
    const double a = (X - 0.5) - u0, b = (Y - 0.5) - v0;  // -0.5 or 1.5 at the edges
    Source out;
    out.view = Map(u0, v0)[2];
    if (out.view < 0.0f) return {};
    Eigen::Vector2d p = Eigen::Vector2d::Zero();
    const double w[4] = {(1 - a) * (1 - b), a * (1 - b), (1 - a) * b, a * b};
    const int du[4] = {0, 1, 0, 1}, dv[4] = {0, 0, 1, 1};
    for (int k = 0; k < 4; ++k) {
      const float* m = Map(u0 + du[k], v0 + dv[k]);
      if (m[2] != out.view) return {};
      p += w[k] * Eigen::Vector2d(m[0], m[1]);
    }
    out.p = p.cast<float>();
    return out;
  }

  // The cell [x, x + w) x [y, y + h) as linear, or halved, or exact at the smallest size.
  void Add(int x, int y, int w, int h) {
    double error = 0.0;
    if (Linear(x, y, w, h, &error)) {
      Emit(x, y, w, h, /*linear=*/true);
      Residual(x, y, w, h);
      mesh_.linear_pixels += static_cast<int64_t>(w) * h;
      mesh_.max_error_px = std::max(mesh_.max_error_px, error);
      return;
    }
    if (w <= 4 && h <= 4) {
      Emit(x, y, w, h, /*linear=*/false);
      return;
    }
    const int w0 = w > 4 ? w / 2 : w, h0 = h > 4 ? h / 2 : h;
    for (int j = 0; j < (h > 4 ? 2 : 1); ++j) {
      for (int i = 0; i < (w > 4 ? 2 : 1); ++i) {
        Add(x + i * w0, y + j * h0, i == 0 ? w0 : w - w0, j == 0 ? h0 : h - h0);
      }
    }
  }

  // The position interpolated at pixel (u, v) of the cell, as the rasterizer does over the
  // two triangles (00, 10, 11) and (00, 11, 01).
  Eigen::Vector2d Interpolated(int x, int y, int w, int h, int u, int v) const {
    const Eigen::Vector2d p00 = corners_[Index(x, y)].p.cast<double>();
    const Eigen::Vector2d p10 = corners_[Index(x + w, y)].p.cast<double>();
    const Eigen::Vector2d p01 = corners_[Index(x, y + h)].p.cast<double>();
    const Eigen::Vector2d p11 = corners_[Index(x + w, y + h)].p.cast<double>();
    const double s = (u + 0.5 - x) / w, t = (v + 0.5 - y) / h;
    return s >= t ? p00 + s * (p10 - p00) + t * (p11 - p10)
                  : p00 + s * (p11 - p01) + t * (p01 - p00);
  }

  // The linear cell's residuals: the map's position minus the interpolated one, rounded to
  // tolerance / 127.
  void Residual(int x, int y, int w, int h) {
    const double unit = tolerance_ / 127.0;
    for (int v = y; v < y + h; ++v) {
      for (int u = x; u < x + w; ++u) {
        const float* m = Map(u, v);
        const Eigen::Vector2d e = Eigen::Vector2d(m[0], m[1]) - Interpolated(x, y, w, h, u, v);
        const std::size_t i = 2 * (static_cast<std::size_t>(v) * width_ + u);
        Eigen::Vector2d rest = e;  // what the codes leave
        for (int c = 0; c < 2; ++c) {
          const double code = unit > 0.0 ? std::clamp(std::round(e[c] / unit), -127.0, 127.0) : 0.0;
          mesh_.residual[i + c] = static_cast<int8_t>(code);
          rest[c] -= code * unit;
        }
        mesh_.max_residual_error_px = std::max(mesh_.max_residual_error_px, rest.norm());
      }
    }
  }

  // Whether every pixel of the cell is one sample of one view, within tolerance of the
  // position interpolated over the two triangles (00, 10, 11) and (00, 11, 01) as the
  // rasterizer does at its centre.
  bool Linear(int x, int y, int w, int h, double* error) const {
    const Source& c00 = corners_[Index(x, y)];
    const Source& c10 = corners_[Index(x + w, y)];
    const Source& c01 = corners_[Index(x, y + h)];
    const Source& c11 = corners_[Index(x + w, y + h)];
    const float view = c00.view;
    if (view < 0.0f || c10.view != view || c01.view != view || c11.view != view) return false;
    for (int v = y; v < y + h; ++v) {
      for (int u = x; u < x + w; ++u) {
        const float* m = Map(u, v);
        if (m[2] != view || m[3] != 17.0f) return false;  // 17: one sample (nu = nv = 1)
        const double e = (Interpolated(x, y, w, h, u, v) - Eigen::Vector2d(m[0], m[1])).norm();
        if (e > tolerance_) return false;
        *error = std::max(*error, e);
      }
    }
    return true;
  }

  void Emit(int x, int y, int w, int h, bool linear) {
    const auto first = static_cast<uint32_t>(mesh_.vertices.size() / 5);
    const int X[4] = {x, x + w, x, x + w}, Y[4] = {y, y, y + h, y + h};
    for (int k = 0; k < 4; ++k) {
      mesh_.vertices.push_back(static_cast<float>(2.0 * X[k] / width_ - 1.0));
      mesh_.vertices.push_back(static_cast<float>(2.0 * Y[k] / height_ - 1.0));
      const Source& c = corners_[Index(X[k], Y[k])];
      mesh_.vertices.push_back(linear ? c.p.x() : 0.0f);
      mesh_.vertices.push_back(linear ? c.p.y() : 0.0f);
      mesh_.vertices.push_back(linear ? c.view : 0.0f);
    }
    // Corners 0 = 00, 1 = 10, 2 = 01, 3 = 11: triangles (00, 10, 11) and (00, 11, 01).
    std::vector<uint32_t>& indices = linear ? mesh_.linear : mesh_.exact;
    for (const uint32_t k : {0u, 1u, 3u, 0u, 3u, 2u}) indices.push_back(first + k);
  }

  const RemapTable& table_;
  int width_, height_;
  double tolerance_;
  std::vector<Source> corners_;
  LensMesh mesh_;
};

}  // namespace

LensMesh MakeLensMesh(const RemapTable& table, int width, int height, double tolerance_px) {
  return LensMeshBuilder(table, width, height, tolerance_px).Build();
}

std::vector<float> GaussianTable() {
  // Quantile i of the standard normal at probability (i + 1/2) / n, by bisection on erfc (to
  // float precision: 40 halvings of [-9, 0]), then scaled to unit variance (the n quantiles
  // miss the tails beyond 4.5 sigma: their variance is 0.9997).
  constexpr int n = kGaussianTableSide * kGaussianTableSide;
  std::vector<double> z(n);
  double sum2 = 0.0;
  for (int i = 0; i < n / 2; ++i) {
    const double p = (i + 0.5) / n;  // the lower half; the upper half by symmetry
    double lo = -9.0, hi = 0.0;
    for (int k = 0; k < 40; ++k) {
      const double mid = 0.5 * (lo + hi);
      (0.5 * std::erfc(-mid / std::sqrt(2.0)) < p ? lo : hi) = mid;
    }
    z[i] = 0.5 * (lo + hi);
    z[n - 1 - i] = -z[i];
    sum2 += 2.0 * z[i] * z[i];
  }
  const double scale = 1.0 / std::sqrt(sum2 / n);
  // Three channels, each the quantiles in its own order (Fisher-Yates with SplitMix64, fixed
  // seeds), so that the three deviates of one entry are independent.
  std::vector<float> table(3 * static_cast<std::size_t>(n));
  for (int c = 0; c < 3; ++c) {
    std::vector<int> order(n);
    for (int i = 0; i < n; ++i) order[i] = i;
    uint64_t state = 0x5eed0000u + static_cast<uint64_t>(c);
    for (int i = n - 1; i > 0; --i) {
      state += 0x9e3779b97f4a7c15ull;
      uint64_t x = state;
      x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
      x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
      x ^= x >> 31;
      std::swap(order[i], order[static_cast<int>(x % static_cast<uint64_t>(i + 1))]);
    }
    for (int i = 0; i < n; ++i)
      table[3 * static_cast<std::size_t>(i) + c] = static_cast<float>(z[order[i]] * scale);
  }
  return table;
}

const std::vector<uint32_t>& PackedGaussianTable() {
  static const std::vector<uint32_t> packed = PackGaussianTable(GaussianTable());
  return packed;
}

std::vector<uint32_t> PackGaussianTable(const std::vector<float>& table) {
  std::vector<uint32_t> packed(table.size() / 3);
  for (std::size_t i = 0; i < packed.size(); ++i) {
    uint32_t entry = 0;
    for (int c = 0; c < 3; ++c) {
      const double code = std::round((table[3 * i + c] + kGaussianRange) / kGaussianStep);
      if (!(code >= 0.0 && code <= 1023.0)) {
        throw Error(fmt::format("PackGaussianTable: {} is beyond +-{} sigma", table[3 * i + c],
                                kGaussianRange));
      }
      entry |= static_cast<uint32_t>(code) << (10 * c);
    }
    packed[i] = entry;
  }
  return packed;
}

namespace {

std::string Defines(bool identity, bool noise, bool mesh = false, int turn = 0) {
  return fmt::format(
      "#version 330 core\n#define IDENTITY {}\n#define NOISE {}\n#define MESH {}\n"
      "#define TURN {}\n#define GAUSS_RANGE {:.9e}\n#define GAUSS_STEP {:.9e}\n"
      "#define RESIDUAL_SCALE {:.9e}\n",
      identity ? 1 : 0, noise ? 1 : 0, mesh ? 1 : 0, turn, kGaussianRange, kGaussianStep,
      kLensMeshTolerancePx);
}

// Texel-exact sampling only (texelFetch): no filtering, no mipmaps (a texture whose minifying
// filter wants mipmaps it lacks is incomplete and reads as zero).
void NearestNoMipmaps(GLenum target) {
  glTexParameteri(target, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(target, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTexParameteri(target, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(target, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
}

GLuint MakeArray(GLenum internal_format, GLenum format, GLenum type, int width, int height,
                 int layers) {
  GLuint texture = 0;
  glGenTextures(1, &texture);
  glBindTexture(GL_TEXTURE_2D_ARRAY, texture);
  NearestNoMipmaps(GL_TEXTURE_2D_ARRAY);
  glTexImage3D(GL_TEXTURE_2D_ARRAY, 0, static_cast<GLint>(internal_format), width, height, layers,
               0, format, type, nullptr);
  glBindTexture(GL_TEXTURE_2D_ARRAY, 0);
  return texture;
}

GLuint MakeTexture2d(GLenum internal_format, GLenum format, GLenum type, int width, int height,
                     const void* pixels) {
  GLuint texture = 0;
  glGenTextures(1, &texture);
  glBindTexture(GL_TEXTURE_2D, texture);
  NearestNoMipmaps(GL_TEXTURE_2D);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, static_cast<GLint>(internal_format), width, height, 0, format,
               type, pixels);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glBindTexture(GL_TEXTURE_2D, 0);
  return texture;
}

// The scene views are read by the final pass's bilinear fetches (kFinalFragmentSource), and by
// texelFetch, which ignores filtering.
void FilterLinearly(GLuint array) {
  glBindTexture(GL_TEXTURE_2D_ARRAY, array);
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glBindTexture(GL_TEXTURE_2D_ARRAY, 0);
}

void CheckComplete(const char* what, int width, int height) {
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    throw Error(fmt::format("Renderer: the {} x {} {} framebuffer is incomplete: status 0x{:04X}",
                            width, height, what, status));
  }
}

void BindTexture(GLint unit, GLenum target, GLuint texture) {
  glActiveTexture(static_cast<GLenum>(GL_TEXTURE0 + unit));
  glBindTexture(target, texture);
}

}  // namespace

// --- EffectPrograms ---------------------------------------------------------------------

EffectPrograms::EffectPrograms() {
  glGenVertexArrays(1, &vao_);
  accumulate_ =
      BuildProgram("motion blur accumulation", kFullscreenVertexSource, kAccumulateFragmentSource);
  accumulate_layer_ = Uniform(accumulate_, "u_layer");
  accumulate_weight_ = Uniform(accumulate_, "u_weight");
  glUseProgram(accumulate_);
  glUniform1i(Uniform(accumulate_, "u_source"), kSourceUnit);
  turn_blur_ = BuildProgram("motion blur of a turning camera", kFullscreenVertexSource,
                            kTurnBlurFragmentSource);
  turn_blur_layer_ = Uniform(turn_blur_, "u_layer");
  turn_blur_count_ = Uniform(turn_blur_, "u_count");
  turn_blur_weight_ = Uniform(turn_blur_, "u_weight");
  turn_blur_h_ = Uniform(turn_blur_, "u_h");
  glUseProgram(turn_blur_);
  glUniform1i(Uniform(turn_blur_, "u_source"), kSourceUnit);
  truth_.program = BuildProgram("ground truth", kTruthVertexSource, kTruthFragmentSource);
  truth_.mvp = Uniform(truth_.program, "u_mvp");
  truth_.mv = Uniform(truth_.program, "u_mv");
  truth_.depth_axis = Uniform(truth_.program, "u_depth_axis");
  truth_.id = Uniform(truth_.program, "u_id");
  glUseProgram(0);
  const std::vector<uint32_t>& gauss = PackedGaussianTable();
  gauss_ = MakeTexture2d(GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, kGaussianTableSide,
                         kGaussianTableSide, gauss.data());
  CheckGlError("MakeRenderer: building the effect programs");
}

EffectPrograms::~EffectPrograms() {
  glDeleteVertexArrays(1, &vao_);
  glDeleteTextures(1, &gauss_);
  glDeleteProgram(accumulate_);
  glDeleteProgram(turn_blur_);
  glDeleteProgram(truth_.program);
  for (const auto& [variant, final] : finals_) glDeleteProgram(final.program);
  for (const auto& [variant, program] : truth_remaps_) glDeleteProgram(program);
}

const EffectPrograms::Final& EffectPrograms::GetFinal(bool identity, bool noise, bool mesh,
                                                      int turn) {
  mesh = mesh && !identity;
  if (turn < 0 || turn > kMaxTurnBlurSamples) {
    throw Error(
        fmt::format("final pass: {} turn sub-frames, expected 0 to {}", turn, kMaxTurnBlurSamples));
  }
  const int variant = (identity ? 1 : 0) | (noise ? 2 : 0) | (mesh ? 4 : 0) | (turn << 3);
  if (const auto it = finals_.find(variant); it != finals_.end()) return it->second;
  Final f;
  f.program = BuildProgram(fmt::format("final pass (identity {}, noise {}, mesh {}, turn {})",
                                       identity, noise, mesh, turn),
                           identity ? kFullscreenVertexSource : kLensMeshVertexSource,
                           Defines(identity, noise, mesh, turn) + kFinalFragmentSource);
  f.read_sigma = Uniform(f.program, "u_read_sigma");
  f.gain = Uniform(f.program, "u_gain");
  f.key = Uniform(f.program, "u_key");
  f.turn_h = Uniform(f.program, "u_turn_h");
  f.turn_layer = Uniform(f.program, "u_turn_layer");
  glUseProgram(f.program);
  glUniform1i(Uniform(f.program, "u_source"), kSourceUnit);
  glUniform1i(Uniform(f.program, "u_map"), kMapUnit);
  glUniform1i(Uniform(f.program, "u_footprint"), kFootprintUnit);
  glUniform1i(Uniform(f.program, "u_gauss"), kGaussUnit);
  glUniform1i(Uniform(f.program, "u_residual"), kResidualUnit);
  glUseProgram(0);
  CheckGlError("MakeRenderer: building the final pass");
  return finals_.emplace(variant, f).first->second;
}

GLuint EffectPrograms::GetTruthRemap(bool identity) {
  const int variant = identity ? 1 : 0;
  if (const auto it = truth_remaps_.find(variant); it != truth_remaps_.end()) return it->second;
  const GLuint program =
      BuildProgram(fmt::format("truth remap (identity {})", identity), kFullscreenVertexSource,
                   Defines(identity, false) + kTruthRemapFragmentSource);
  glUseProgram(program);
  glUniform1i(Uniform(program, "u_ids"), kIdsUnit);
  glUniform1i(Uniform(program, "u_z"), kZUnit);
  glUniform1i(Uniform(program, "u_map"), kMapUnit);
  glUseProgram(0);
  CheckGlError("MakeRenderer: building the truth remap");
  return truth_remaps_.emplace(variant, program).first->second;
}

void EffectPrograms::DrawFullscreen() const {
  glBindVertexArray(vao_);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindVertexArray(0);
}

// --- PixelBuffers -------------------------------------------------------------------------

PixelBuffers::PixelBuffers(int width, int height, int bytes_per_pixel)
    : width_(width), height_(height), bytes_per_pixel_(bytes_per_pixel) {
  glGenBuffers(CameraTarget::kSlots, buffers_);
  for (GLuint buffer : buffers_) {
    glBindBuffer(GL_PIXEL_PACK_BUFFER, buffer);
    glBufferData(GL_PIXEL_PACK_BUFFER, static_cast<GLsizeiptr>(width_) * height_ * bytes_per_pixel_,
                 nullptr, GL_STREAM_READ);
  }
  glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
}

PixelBuffers::~PixelBuffers() { glDeleteBuffers(CameraTarget::kSlots, buffers_); }

void PixelBuffers::Read(int slot, GLenum format, GLenum type) const {
  Read(slot, format, type, height_, 0);
}

void PixelBuffers::Read(int slot, GLenum format, GLenum type, int rows, std::size_t offset) const {
  glBindBuffer(GL_PIXEL_PACK_BUFFER, buffers_[slot]);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width_, rows, format, type, reinterpret_cast<void*>(offset));
  glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
}

const void* PixelBuffers::Map(int slot) const {
  glBindBuffer(GL_PIXEL_PACK_BUFFER, buffers_[slot]);
  return glMapBufferRange(GL_PIXEL_PACK_BUFFER, 0,
                          static_cast<GLsizeiptr>(width_) * height_ * bytes_per_pixel_,
                          GL_MAP_READ_BIT);
}

void PixelBuffers::Unmap() const {
  glUnmapBuffer(GL_PIXEL_PACK_BUFFER);
  glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
}

// --- EffectTarget -------------------------------------------------------------------------

EffectTarget::EffectTarget(const geometry::LensMap& lens, int samples, bool blur, bool truth,
                           bool lens_on_cpu, bool color_depth)
    : lens_(lens),
      samples_(samples),
      blur_(blur),
      truth_(truth),
      source_width_(lens.views.at(0).intrinsics.width()),
      source_height_(lens.views.at(0).intrinsics.height()),
      layers_(static_cast<int>(lens.views.size())),
      color_buffers_(lens.width, lens.height, 4) {
  GLint max_size = 0, max_layers = 0;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
  glGetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &max_layers);
  if (source_width_ > max_size || source_height_ > max_size || layers_ > max_layers) {
    throw Error(fmt::format(
        "Renderer: the lens needs {} source view(s) of {} x {} pixels, beyond the device's "
        "limit of {} a side",
        layers_, source_width_, source_height_, max_size));
  }
  MakeSourceViews();
  if (blur_) EnableBlur();
  if (lens_.kind != geometry::LensMap::Kind::kIdentity) MakeLensRemap(lens_on_cpu);
  output_color_ = MakeArray(GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE, lens_.width, lens_.height, 1);
  glGenFramebuffers(1, &output_framebuffer_);
  glBindFramebuffer(GL_FRAMEBUFFER, output_framebuffer_);
  glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, output_color_, 0, 0);
  CheckComplete("camera image", lens_.width, lens_.height);
  if (truth_) MakeTruthTargets();
  if (color_depth) {
    const bool identity = lens_.kind == geometry::LensMap::Kind::kIdentity &&
                          source_width_ == lens_.width && source_height_ == lens_.height;
    if (truth_ || samples_ != 0 || layers_ != 1 || (!identity && cpu_lens_ == nullptr)) {
      throw Error(
          "EffectTarget: the colour pass's depth needs one source view without MSAA, the lens "
          "an identity or remapped on the CPU, and no truth pass");
    }
    color_depth_buffers_ = std::make_unique<PixelBuffers>(source_width_, source_height_, 4);
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  CheckGlError(fmt::format("Renderer: making the effect targets ({} view(s) of {} x {})", layers_,
                           source_width_, source_height_));
}

void EffectTarget::MakeSourceViews() {
  const int w = source_width_, h = source_height_;
  source_ = MakeArray(GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE, w, h, layers_);
  FilterLinearly(source_);
  glGenFramebuffers(1, &draw_framebuffer_);
  glBindFramebuffer(GL_FRAMEBUFFER, draw_framebuffer_);
  depth_ = MakeRenderbuffer(GL_DEPTH_COMPONENT32F, w, h, samples_);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_);
  if (samples_ > 0) {
    msaa_color_ = MakeRenderbuffer(GL_RGBA8, w, h, samples_);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, msaa_color_);
    CheckComplete("multisampled source view", w, h);
    glGenFramebuffers(1, &resolve_framebuffer_);
    glBindFramebuffer(GL_FRAMEBUFFER, resolve_framebuffer_);
    glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, source_, 0, 0);
    CheckComplete("source view", w, h);
  } else {
    glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, source_, 0, 0);
    CheckComplete("source view", w, h);
  }
}

void EffectTarget::MakeLensRemap(bool lens_on_cpu) {
  const int w = source_width_, h = source_height_;
  const RemapTable table = MakeRemapTable(lens_);
  if (lens_on_cpu && layers_ == 1) {
    cpu_lens_ = std::make_unique<CpuLens>(table, lens_.width, lens_.height, w, h);
    source_buffers_ = std::make_unique<PixelBuffers>(w, h, 4);
  }
  map_ = MakeTexture2d(GL_RGBA32F, GL_RGBA, GL_FLOAT, lens_.width, lens_.height, table.map.data());
  footprint_ = MakeTexture2d(GL_RGBA32F, GL_RGBA, GL_FLOAT, lens_.width, lens_.height,
                             table.footprint.data());
  const LensMesh mesh = MakeLensMesh(table, lens_.width, lens_.height);
  residual_ =
      MakeTexture2d(GL_RG8_SNORM, GL_RG, GL_BYTE, lens_.width, lens_.height, mesh.residual.data());
  std::vector<uint32_t> indices = mesh.linear;
  indices.insert(indices.end(), mesh.exact.begin(), mesh.exact.end());
  mesh_linear_ = static_cast<GLsizei>(mesh.linear.size());
  mesh_exact_ = static_cast<GLsizei>(mesh.exact.size());
  glGenVertexArrays(1, &mesh_vao_);
  glBindVertexArray(mesh_vao_);
  glGenBuffers(1, &mesh_vertices_);
  glBindBuffer(GL_ARRAY_BUFFER, mesh_vertices_);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(mesh.vertices.size() * sizeof(float)),
               mesh.vertices.data(), GL_STATIC_DRAW);
  glGenBuffers(1, &mesh_indices_);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, mesh_indices_);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(indices.size() * sizeof(uint32_t)),
               indices.data(), GL_STATIC_DRAW);
  constexpr GLsizei kStride = 5 * sizeof(float);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, kStride, nullptr);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, kStride,
                        reinterpret_cast<const void*>(2 * sizeof(float)));
  glBindVertexArray(0);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
}

void EffectTarget::MakeTruthTargets() {
  const int w = source_width_, h = source_height_;
  truth_ids_ = MakeArray(GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, w, h, layers_);
  truth_z_ = MakeArray(GL_RG32F, GL_RG, GL_FLOAT, w, h, layers_);  // camera z, view depth
  truth_depth_ = MakeRenderbuffer(GL_DEPTH_COMPONENT32F, w, h, 0);
  glGenFramebuffers(1, &truth_framebuffer_);
  glBindFramebuffer(GL_FRAMEBUFFER, truth_framebuffer_);
  glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, truth_ids_, 0, 0);
  glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, truth_z_, 0, 0);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, truth_depth_);
  const GLenum buffers[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
  glDrawBuffers(2, buffers);
  CheckComplete("ground truth", w, h);
  output_ids_ = MakeArray(GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, lens_.width, lens_.height, 1);
  output_z_ = MakeArray(GL_R32F, GL_RED, GL_FLOAT, lens_.width, lens_.height, 1);
  glGenFramebuffers(1, &output_truth_framebuffer_);
  glBindFramebuffer(GL_FRAMEBUFFER, output_truth_framebuffer_);
  glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, output_ids_, 0, 0);
  glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, output_z_, 0, 0);
  glDrawBuffers(2, buffers);
  CheckComplete("ground truth image", lens_.width, lens_.height);
  id_buffers_ = std::make_unique<PixelBuffers>(lens_.width, lens_.height, 4);
  depth_buffers_ = std::make_unique<PixelBuffers>(lens_.width, lens_.height, 4);
}

void EffectTarget::EnableBlur() {
  if (accumulation_ != 0) return;
  const int w = source_width_, h = source_height_;
  accumulation_ = MakeArray(GL_RGBA32F, GL_RGBA, GL_FLOAT, w, h, layers_);
  FilterLinearly(accumulation_);
  glGenFramebuffers(1, &accumulation_framebuffer_);
  glBindFramebuffer(GL_FRAMEBUFFER, accumulation_framebuffer_);
  glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, accumulation_, 0, 0);
  CheckComplete("motion blur accumulation", w, h);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  if (layers_ == 1) {
    stretches_ = MakeArray(GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE, w, h, kMaxTurnStretches);
    FilterLinearly(stretches_);
  }
  blur_ = true;
}

EffectTarget::~EffectTarget() {
  const GLuint framebuffers[] = {draw_framebuffer_,         resolve_framebuffer_,
                                 accumulation_framebuffer_, truth_framebuffer_,
                                 output_framebuffer_,       output_truth_framebuffer_};
  glDeleteFramebuffers(std::size(framebuffers), framebuffers);
  const GLuint textures[] = {source_,       accumulation_, stretches_, map_,
                             footprint_,    residual_,     truth_ids_, truth_z_,
                             output_color_, output_ids_,   output_z_};
  glDeleteTextures(std::size(textures), textures);
  const GLuint renderbuffers[] = {msaa_color_, depth_, truth_depth_};
  glDeleteRenderbuffers(std::size(renderbuffers), renderbuffers);
  glDeleteVertexArrays(1, &mesh_vao_);
  const GLuint buffers[] = {mesh_vertices_, mesh_indices_};
  glDeleteBuffers(std::size(buffers), buffers);
}

void EffectTarget::BindLayerForDrawing(GLuint array, int layer) const {
  glBindFramebuffer(GL_FRAMEBUFFER, draw_framebuffer_);
  if (samples_ == 0) {
    glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, array, 0, layer);
  }
  glViewport(0, 0, source_width_, source_height_);
}

void EffectTarget::ResolveInto(GLuint array, int layer) const {
  if (samples_ == 0) return;
  glBindFramebuffer(GL_READ_FRAMEBUFFER, draw_framebuffer_);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolve_framebuffer_);
  glFramebufferTextureLayer(GL_DRAW_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, array, 0, layer);
  glBlitFramebuffer(0, 0, source_width_, source_height_, 0, 0, source_width_, source_height_,
                    GL_COLOR_BUFFER_BIT, GL_NEAREST);
}

void EffectTarget::BindViewForDrawing(int view) const { BindLayerForDrawing(source_, view); }

void EffectTarget::FinishView(int view) const { ResolveInto(source_, view); }

void EffectTarget::BindStretchForDrawing(int stretch) const {
  BindLayerForDrawing(stretches_, stretch);
}

void EffectTarget::FinishStretch(int stretch) const { ResolveInto(stretches_, stretch); }

void EffectTarget::Accumulate(const EffectPrograms& programs, int view, float weight,
                              Accumulation mode) const {
  BeginAccumulationPass(view, mode);
  glUseProgram(programs.accumulate());
  glUniform1i(programs.accumulate_layer(), view);
  glUniform1f(programs.accumulate_weight(), weight);
  programs.DrawFullscreen();
  EndAccumulationPass();
}

void EffectTarget::BeginAccumulationPass(int view, Accumulation mode) const {
  glBindFramebuffer(GL_FRAMEBUFFER, accumulation_framebuffer_);
  glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, accumulation_, 0, view);
  glViewport(0, 0, source_width_, source_height_);
  glDisable(GL_DEPTH_TEST);
  if (mode == Accumulation::kAdd) {
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
  }
  BindTexture(kSourceUnit, GL_TEXTURE_2D_ARRAY, source_);
}

void EffectTarget::EndAccumulationPass() const {
  glDisable(GL_BLEND);
  glEnable(GL_DEPTH_TEST);
  glActiveTexture(GL_TEXTURE0);
}

void EffectTarget::WriteBack(const EffectPrograms& programs, int view) const {
  const GLuint framebuffer = samples_ > 0 ? resolve_framebuffer_ : draw_framebuffer_;
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
  glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, source_, 0, view);
  glViewport(0, 0, source_width_, source_height_);
  glDisable(GL_DEPTH_TEST);
  glUseProgram(programs.accumulate());
  glUniform1i(programs.accumulate_layer(), view);
  glUniform1f(programs.accumulate_weight(), 1.0f);
  BindTexture(kSourceUnit, GL_TEXTURE_2D_ARRAY, accumulation_);
  programs.DrawFullscreen();
  glEnable(GL_DEPTH_TEST);
  glActiveTexture(GL_TEXTURE0);
}

void EffectTarget::TurnBlur(const EffectPrograms& programs, int view,
                            const std::vector<Eigen::Matrix3f>& homographies, float weight,
                            Accumulation mode) const {
  const int count = static_cast<int>(homographies.size());
  if (count < 1 || count > kMaxTurnBlurSamples) {
    throw Error(
        fmt::format("TurnBlur: {} homographies, expected 1 to {}", count, kMaxTurnBlurSamples));
  }
  std::vector<float> h;  // column-major, as GL takes mat3s without transposing
  h.reserve(9 * homographies.size());
  for (const Eigen::Matrix3f& m : homographies) h.insert(h.end(), m.data(), m.data() + 9);
  BeginAccumulationPass(view, mode);
  glUseProgram(programs.turn_blur());
  glUniform1i(programs.turn_blur_layer(), view);
  glUniform1i(programs.turn_blur_count(), count);
  glUniform1f(programs.turn_blur_weight(), weight);
  glUniformMatrix3fv(programs.turn_blur_h(), count, GL_FALSE, h.data());
  programs.DrawFullscreen();
  EndAccumulationPass();
}

void EffectTarget::BindTruthForDrawing(int view) const {
  glBindFramebuffer(GL_FRAMEBUFFER, truth_framebuffer_);
  glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, truth_ids_, 0, view);
  glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, truth_z_, 0, view);
  glViewport(0, 0, source_width_, source_height_);
  const GLuint zero_id[4] = {0, 0, 0, 0};
  const GLfloat zero_z[4] = {0.0f, 0.0f, 0.0f, 0.0f};
  const GLfloat far_depth = 1.0f;
  glClearBufferuiv(GL_COLOR, 0, zero_id);
  glClearBufferfv(GL_COLOR, 1, zero_z);
  glClearBufferfv(GL_DEPTH, 0, &far_depth);
}

bool EffectTarget::can_read_source() const {
  if (cpu_lens_) return true;
  return lens_.kind == geometry::LensMap::Kind::kIdentity && layers_ == 1 &&
         source_width_ == lens_.width && source_height_ == lens_.height;
}

void EffectTarget::ReadColorDepth(int slot) const {
  glBindFramebuffer(GL_READ_FRAMEBUFFER, draw_framebuffer_);
  color_depth_buffers_->Read(slot, GL_DEPTH_COMPONENT, GL_FLOAT);
}

void EffectTarget::ReadSource(int slot) const {
  // The source layer is resolved (FinishView) and, as the final pass's output, row 0 at the
  // top: the draw (or resolve) framebuffer on it reads it as the pass would have copied it.
  glBindFramebuffer(GL_FRAMEBUFFER, samples_ > 0 ? resolve_framebuffer_ : draw_framebuffer_);
  glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, source_, 0, 0);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, samples_ > 0 ? resolve_framebuffer_ : draw_framebuffer_);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  (cpu_lens_ ? *source_buffers_ : color_buffers_).Read(slot, GL_RGBA, GL_UNSIGNED_BYTE);
}

void EffectTarget::ReadStretches(int slot, int count) const {
  if (stretches_ == 0 || count < 1 || count > kMaxTurnStretches) {
    throw Error(fmt::format("ReadStretches: {} stretches, expected 1 to {}{}", count,
                            kMaxTurnStretches,
                            stretches_ == 0 ? " (this target has no stretches)" : ""));
  }
  if (stretch_buffers_ == nullptr) {
    stretch_buffers_ =
        std::make_unique<PixelBuffers>(source_width_, source_height_ * kMaxTurnStretches, 4);
  }
  // As ReadSource: the resolved layer, through the framebuffer the pass would have read.
  const GLuint framebuffer = samples_ > 0 ? resolve_framebuffer_ : draw_framebuffer_;
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, framebuffer);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  const std::size_t layer_bytes = static_cast<std::size_t>(source_width_) * source_height_ * 4;
  for (int g = 0; g < count; ++g) {
    glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, stretches_, 0, g);
    stretch_buffers_->Read(slot, GL_RGBA, GL_UNSIGNED_BYTE, source_height_,
                           static_cast<std::size_t>(g) * layer_bytes);
  }
}

void EffectTarget::Finish(EffectPrograms& programs, bool accumulated, const NoiseParams* noise,
                          int slot, const TurnSamples* turn) const {
  const bool identity = lens_.kind == geometry::LensMap::Kind::kIdentity;
  const int turn_count = turn != nullptr ? static_cast<int>(turn->homographies.size()) : 0;
  std::vector<float> turn_h;  // column-major, as GL takes mat3s without transposing
  if (turn != nullptr) {
    if (stretches_ == 0 || turn_count < 1 || turn_count > kMaxTurnBlurSamples ||
        turn->layers.size() != turn->homographies.size()) {
      throw Error(fmt::format("Finish: {} turn sub-frames with {} layers, expected 1 to {}{}",
                              turn_count, turn->layers.size(), kMaxTurnBlurSamples,
                              stretches_ == 0 ? " (this target has no stretches)" : ""));
    }
    turn_h.reserve(9 * turn->homographies.size());
    for (const Eigen::Matrix3f& m : turn->homographies) {
      turn_h.insert(turn_h.end(), m.data(), m.data() + 9);
    }
  }
  glDisable(GL_DEPTH_TEST);
  glViewport(0, 0, lens_.width, lens_.height);
  if (!identity) {
    BindTexture(kMapUnit, GL_TEXTURE_2D, map_);
    BindTexture(kFootprintUnit, GL_TEXTURE_2D, footprint_);
    BindTexture(kResidualUnit, GL_TEXTURE_2D, residual_);
  }

  glBindFramebuffer(GL_FRAMEBUFFER, output_framebuffer_);
  if (noise != nullptr) BindTexture(kGaussUnit, GL_TEXTURE_2D, programs.gauss());
  BindTexture(kSourceUnit, GL_TEXTURE_2D_ARRAY,
              turn != nullptr ? stretches_ : (accumulated ? accumulation_ : source_));
  // Identity: the full-screen triangle; a lens: its linear cells, then its exact ones.
  const auto pass = [&](bool mesh) {
    const EffectPrograms::Final& final =
        programs.GetFinal(identity, noise != nullptr, mesh, turn_count);
    glUseProgram(final.program);
    if (noise != nullptr) {
      glUniform1f(final.read_sigma, noise->read_sigma_dn);
      glUniform1f(final.gain, noise->gain_dn_per_e);
      glUniform1ui(final.key, noise->key);
    }
    if (turn != nullptr) {
      glUniformMatrix3fv(final.turn_h, turn_count, GL_FALSE, turn_h.data());
      glUniform1fv(final.turn_layer, turn_count, turn->layers.data());
    }
  };
  if (identity) {
    pass(false);
    programs.DrawFullscreen();
  } else {
    glBindVertexArray(mesh_vao_);
    if (mesh_linear_ > 0) {
      pass(true);
      glDrawElements(GL_TRIANGLES, mesh_linear_, GL_UNSIGNED_INT, nullptr);
    }
    if (mesh_exact_ > 0) {
      pass(false);
      glDrawElements(GL_TRIANGLES, mesh_exact_, GL_UNSIGNED_INT,
                     reinterpret_cast<const void*>(mesh_linear_ * sizeof(uint32_t)));
    }
    glBindVertexArray(0);
  }
  glBindFramebuffer(GL_READ_FRAMEBUFFER, output_framebuffer_);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  color_buffers_.Read(slot, GL_RGBA, GL_UNSIGNED_BYTE);

  if (truth_) RemapTruth(programs, slot);
  glUseProgram(0);
  glActiveTexture(GL_TEXTURE0);
  glEnable(GL_DEPTH_TEST);
}

void EffectTarget::RemapTruth(EffectPrograms& programs, int slot) const {
  glBindFramebuffer(GL_FRAMEBUFFER, output_truth_framebuffer_);
  glUseProgram(programs.GetTruthRemap(lens_.kind == geometry::LensMap::Kind::kIdentity));
  BindTexture(kIdsUnit, GL_TEXTURE_2D_ARRAY, truth_ids_);
  BindTexture(kZUnit, GL_TEXTURE_2D_ARRAY, truth_z_);
  programs.DrawFullscreen();
  glBindFramebuffer(GL_READ_FRAMEBUFFER, output_truth_framebuffer_);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  id_buffers_->Read(slot, GL_RED_INTEGER, GL_UNSIGNED_INT);
  glReadBuffer(GL_COLOR_ATTACHMENT1);
  depth_buffers_->Read(slot, GL_RED, GL_FLOAT);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
}

void EffectTarget::FinishTruth(EffectPrograms& programs, int slot) const {
  if (!truth_) return;
  glDisable(GL_DEPTH_TEST);
  glViewport(0, 0, lens_.width, lens_.height);
  if (lens_.kind != geometry::LensMap::Kind::kIdentity) BindTexture(kMapUnit, GL_TEXTURE_2D, map_);
  RemapTruth(programs, slot);
  glUseProgram(0);
  glActiveTexture(GL_TEXTURE0);
  glEnable(GL_DEPTH_TEST);
}

}  // namespace saccade::render::gl
