#pragma once
// The effect path of one camera (seed section 4.3), on the GPU:
//
//   scene passes, one per source view (geometry/lens_map.h: the camera itself, a wider
//   pinhole, or cube faces), each into one layer of an RGBA8 texture array (through an MSAA
//   framebuffer and a resolve when MSAA is on)
//     -> with motion blur, repeated per sub-frame and summed with weights into an RGBA32F
//        array (additive blending); with the camera still, the sub-frames after the first
//        only inside the region that the moving items sweep (scissored), the first standing
//        for all of them elsewhere
//   -> one final pass at the camera's size: lens remap (per-pixel map; each pixel the mean of
//      the source over its footprint, RemapTable, by bilinear texture fetches; drawn as the
//      lens mesh's cells, LensMesh, most of which interpolate the map instead of reading it),
//      sensor noise (a hashed table of normal deviates, GaussianTable), quantisation to 8
//      bits (internal_effect_shaders.h)
//   -> readback through pixel buffer objects, one per in-flight slot.
// On a software rasteriser (RendererOptions::lens_on_cpu, noise_on_cpu), when nothing was
// accumulated in float, no ground truth is drawn and the lens has one source view, the final
// pass is skipped: the source view is read back and Retrieve remaps it and adds the noise on
// the CPU (internal_cpu_lens.h, internal_pixels.h).
//
// Ground truth, when asked: one more scene pass per view into an R32UI id array and an RG32F
// depth array (the camera's z and the view's depth; no MSAA: ids are not blended), remapped
// by the same map into R32UI / R32F images at the camera's size, read back the same way.
// The depth of field's depth alone (no ground truth asked) on a software rasteriser, for a
// lens of one source view without MSAA, is the colour pass's own depth buffer read back
// (color_depth): no second scene pass and no remap pass, Retrieve turns it into the camera's
// z and remaps it on the CPU (internal_color_depth.h).
//
// Everything here needs the renderer's context current.

#include <epoxy/gl.h>

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <vector>

#include "render/gl/internal_camera_target.h"
#include "saccade/geometry/lens_map.h"

namespace saccade::render::gl {

/// What the final pass reads of a lens map (kFinalFragmentSource), per pixel of the camera:
/// - map: (x, y, view, taps), the lens map's entry and the footprint's samples, taps =
///   nu + 16 nv with nu, nv in [1, 4]: ceil(step length / 1.5 source pixels) along the
///   pixel's u and v steps;
/// - footprint: (du.x, du.y, dv.x, dv.y), the source-pixel steps to the neighbouring pixels
///   (central differences within the pixel's view, one-sided at its edge; zero where no
///   neighbour shares it, and for pixels with no ray).
struct RemapTable {
  std::vector<float> map;
  std::vector<float> footprint;
  int64_t multi_tap_pixels = 0;  ///< pixels with more than one sample
};
RemapTable MakeRemapTable(const geometry::LensMap& lens);

/// The lens remap as cells drawn by the rasterizer (kLensMeshVertexSource): the camera's image
/// cut into rectangles of pixels (edges on pixel boundaries, so every pixel centre falls in
/// exactly one), each two triangles whose corners carry the source position (x, y, view).
/// - linear cells: one view, one sample a pixel, and the position interpolated linearly over
///   each triangle within `tolerance` source pixels of the map's at every pixel centre (checked
///   here as the rasterizer interpolates), the rest of the way to the map in `residual`; drawn
///   with the MESH final pass, no map fetch;
/// - exact cells: the rest (a view's edge, no ray, several samples a pixel, a map that bends
///   too fast), drawn with the map's final pass, pixel by pixel as before.
/// Cells start at kLensCell pixels a side and are halved where they fail, down to 4.
struct LensMesh {
  /// Per vertex: NDC x, y, then source x, y, view (exact cells: zero).
  std::vector<float> vertices;
  std::vector<uint32_t> linear;  ///< triangle indices of the linear cells
  std::vector<uint32_t> exact;   ///< and of the exact ones
  int64_t linear_pixels = 0;
  double max_error_px = 0.0;  ///< the largest error over the linear cells' pixels
  /// Per pixel of the camera, row 0 first, (x, y): what the map's position departs from the
  /// interpolated one at the pixel's centre, in units of tolerance / 127 (so within [-127,
  /// 127]); zero outside the linear cells. The final pass adds it back (RESIDUAL).
  std::vector<int8_t> residual;
  /// The largest error left after the residual is added back (its rounding), source pixels.
  double max_residual_error_px = 0.0;
};
inline constexpr int kLensCell = 64;
/// The interpolation's tolerance, and the residuals' range: they step by 0.5 / 127 px.
inline constexpr double kLensMeshTolerancePx = 0.5;
LensMesh MakeLensMesh(const RemapTable& table, int width, int height,
                      double tolerance_px = kLensMeshTolerancePx);

/// The sensor noise's table (kFinalFragmentSource): kGaussianTableSide^2 entries of three
/// standard normal deviates (RGB), each channel the quantiles at (i + 1/2) / 2^16 scaled to
/// unit variance (mean exactly 0) in an order of its own.
inline constexpr int kGaussianTableSide = 256;
std::vector<float> GaussianTable();
/// The table as the shader reads it: each entry's three deviates z as 10-bit codes
/// round((z + kGaussianRange) / kGaussianStep), channel c in bits 10c..10c+9 (the step is
/// 0.009 of a standard deviation: far below the 8-bit output's quantisation at any sigma the
/// noise test sees, and the codes are symmetric about 0, so the mean stays 0).
inline constexpr double kGaussianRange = 4.6;  // the quantiles reach 4.36 (unit variance)
inline constexpr double kGaussianStep = 2.0 * kGaussianRange / 1023.0;
std::vector<uint32_t> PackGaussianTable(const std::vector<float>& table);
/// PackGaussianTable(GaussianTable()), made once a process (about 40 ms of erfc on the 2-core
/// development machine) and shared by every renderer after: the effect programs' texture and
/// the CPU noise.
const std::vector<uint32_t>& PackedGaussianTable();

/// Programs and the empty vertex array shared by every camera's effect passes.
class EffectPrograms {
 public:
  struct Final {
    GLuint program = 0;
    GLint read_sigma = -1, gain = -1, key = -1;
    GLint turn_h = -1, turn_layer = -1;  // TURN > 0 only
  };
  struct Truth {
    GLuint program = 0;
    GLint mvp = -1, mv = -1, depth_axis = -1, id = -1;
  };

  /// Builds the programs. Throws saccade::Error with the compiler's log on failure.
  EffectPrograms();
  ~EffectPrograms();
  EffectPrograms(const EffectPrograms&) = delete;
  EffectPrograms& operator=(const EffectPrograms&) = delete;

  /// The final pass for an identity map or not, with noise or not, from the lens mesh's
  /// interpolated positions or the map (`mesh`; not with identity) (built on first use). The
  /// passes of a lens draw the lens mesh's cells (kLensMeshVertexSource), the identity one the
  /// full-screen triangle.
  /// `turn` > 0: with that many sub-frames of a turning camera's blur folded in (TURN).
  const Final& GetFinal(bool identity, bool noise, bool mesh = false, int turn = 0);
  /// The truth remap for an identity map or not.
  GLuint GetTruthRemap(bool identity);
  const Truth& truth() const { return truth_; }
  GLuint accumulate() const { return accumulate_; }
  GLint accumulate_layer() const { return accumulate_layer_; }
  GLint accumulate_weight() const { return accumulate_weight_; }
  GLuint turn_blur() const { return turn_blur_; }
  GLint turn_blur_layer() const { return turn_blur_layer_; }
  GLint turn_blur_count() const { return turn_blur_count_; }
  GLint turn_blur_weight() const { return turn_blur_weight_; }
  GLint turn_blur_h() const { return turn_blur_h_; }
  /// PackGaussianTable(GaussianTable()) as a kGaussianTableSide^2 R32UI texture.
  GLuint gauss() const { return gauss_; }
  /// Draws the full-screen triangle (program and framebuffer bound by the caller).
  void DrawFullscreen() const;

 private:
  GLuint vao_ = 0;
  GLuint accumulate_ = 0;
  GLuint gauss_ = 0;
  GLint accumulate_layer_ = -1, accumulate_weight_ = -1;
  GLuint turn_blur_ = 0;
  GLint turn_blur_layer_ = -1, turn_blur_count_ = -1, turn_blur_weight_ = -1, turn_blur_h_ = -1;
  std::map<int, Final> finals_;
  std::map<int, GLuint> truth_remaps_;
  Truth truth_;
};

/// Sensor noise of one frame of one camera (SensorSpec, with the key mixed on the CPU).
struct NoiseParams {
  float read_sigma_dn = 0.0f;
  float gain_dn_per_e = 0.0f;
  uint32_t key = 0;
};

/// Motion blur of a turning camera folded into the final pass (TURN): sub-frame k is stretch
/// layer `layers[k]` seen through `homographies[k]` (a pixel of sub-frame k, pixel centres at
/// integers, to the stretch's drawn instant). At most kMaxTurnBlurSamples sub-frames.
struct TurnSamples {
  std::vector<Eigen::Matrix3f> homographies;
  std::vector<float> layers;
};

class CpuLens;  // internal_cpu_lens.h

/// Pixel buffer objects, one per in-flight slot, for one image of fixed size and format.
class PixelBuffers {
 public:
  PixelBuffers(int width, int height, int bytes_per_pixel);
  ~PixelBuffers();
  PixelBuffers(const PixelBuffers&) = delete;
  PixelBuffers& operator=(const PixelBuffers&) = delete;
  /// Starts the copy of the bound read framebuffer's read buffer into the slot's buffer.
  void Read(int slot, GLenum format, GLenum type) const;
  /// The same for `rows` rows of the read buffer, `offset` bytes into the slot's buffer.
  void Read(int slot, GLenum format, GLenum type, int rows, std::size_t offset) const;
  /// Maps the slot's buffer (after its fence), nullptr on failure; Unmap after use.
  const void* Map(int slot) const;
  void Unmap() const;
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  int width_, height_, bytes_per_pixel_;
  GLuint buffers_[CameraTarget::kSlots] = {0, 0};
};

/// The GL objects of one camera's effect path.
class EffectTarget {
 public:
  /// `samples` 0 for no MSAA; `blur`: allocate the accumulation array; `truth`: the id and
  /// depth arrays and outputs; `lens_on_cpu`: a lens of one source view is remapped on the
  /// CPU (cpu_lens) when nothing was accumulated (its truth on the GPU); `color_depth` (with
  /// `truth` false, `samples` 0, one source view, and the lens an identity or on the CPU): a
  /// buffer for the colour pass's depth (ReadColorDepth). Throws saccade::Error naming the
  /// sizes when the device refuses.
  EffectTarget(const geometry::LensMap& lens, int samples, bool blur, bool truth,
               bool lens_on_cpu = false, bool color_depth = false);
  ~EffectTarget();
  EffectTarget(const EffectTarget&) = delete;
  EffectTarget& operator=(const EffectTarget&) = delete;

  /// Adds the accumulation array (nothing if there is one): motion blur switched on. It is
  /// kept when blur is switched off again, so that switching does not allocate each time.
  void EnableBlur();

  const geometry::LensMap& lens() const { return lens_; }
  bool has_truth() const { return truth_; }
  bool has_color_depth() const { return color_depth_buffers_ != nullptr; }

  /// Binds the framebuffer that draws source view `view` and sets the viewport; the caller
  /// clears and draws, then calls FinishView.
  void BindViewForDrawing(int view) const;
  /// Resolves MSAA into the view's layer (nothing to do without MSAA).
  void FinishView(int view) const;
  /// Motion blur: writes weight x the view's layer into its accumulation layer, replacing what
  /// is there (the first sub-frame) or adding to it (the others). Honours the scissor test.
  enum class Accumulation { kReplace, kAdd };
  void Accumulate(const EffectPrograms& programs, int view, float weight, Accumulation mode) const;
  /// Motion blur that redrew only regions: copies the view's accumulation layer into its
  /// source layer (to 8 bits, as the scene passes draw), honouring the scissor test; the final
  /// pass then reads the source (Finish with `accumulated` false).
  void WriteBack(const EffectPrograms& programs, int view) const;
  /// Motion blur of a turning camera (kTurnBlurFragmentSource): writes (kReplace) or adds to
  /// (kAdd) the view's accumulation layer `weight` times the sum of its drawn layer seen
  /// through each homography (at most kMaxTurnBlurSamples); the final pass then reads the
  /// accumulation.
  void TurnBlur(const EffectPrograms& programs, int view,
                const std::vector<Eigen::Matrix3f>& homographies, float weight,
                Accumulation mode) const;
  /// Stretches a turning camera's blur may draw for the final pass (Finish with `turn`): the
  /// layers of the stretch array; 0 without blur or with a lens of several source views (a
  /// wide fisheye), which blur through the accumulation (TurnBlur).
  int turn_stretches() const { return stretches_ != 0 ? kMaxTurnStretches : 0; }
  static constexpr int kMaxTurnStretches = 4;
  /// As BindViewForDrawing and FinishView, for stretch `stretch` of the stretch array.
  void BindStretchForDrawing(int stretch) const;
  void FinishStretch(int stretch) const;

  /// Binds the truth framebuffer of `view`, sets the viewport and clears it (id 0, z 0).
  void BindTruthForDrawing(int view) const;

  /// The final pass (from the accumulation array when `accumulated`; from the stretch array
  /// seen through the turn when `turn` is given), the truth remap when the target has truth,
  /// and the start of every readback into `slot`. `noise` and `turn` may be null.
  void Finish(EffectPrograms& programs, bool accumulated, const NoiseParams* noise, int slot,
              const TurnSamples* turn = nullptr) const;

  /// With ReadSource instead of Finish: the truth remap and its readback into `slot`, when the
  /// target has truth (else nothing).
  void FinishTruth(EffectPrograms& programs, int slot) const;

  /// Whether the final pass would only copy the source view (plus noise): an identity lens of
  /// the camera's size; or remap it where the CPU does that (cpu_lens). Then ReadSource, and
  /// FinishTruth for the truth, may replace Finish when nothing was accumulated.
  bool can_read_source() const;
  /// Starts the readback of the source view into `slot`, the pass skipped: an identity lens's
  /// into color_buffers (Finish's pixels without noise), a lens remapped on the CPU's into
  /// source_buffers.
  void ReadSource(int slot) const;
  /// The lens remap on the CPU (RendererOptions::lens_on_cpu); null when the pass remaps.
  const CpuLens* cpu_lens() const { return cpu_lens_.get(); }
  /// With cpu_lens: the source view's RGBA8 pixels after the slot's fence, row 0 first.
  const PixelBuffers& source_buffers() const { return *source_buffers_; }
  /// Starts the readback of the first `count` stretch layers into `slot`, one after the other,
  /// the pass skipped: a turn fetched on the CPU (internal_cpu_turn.h). One source view only.
  void ReadStretches(int slot, int count) const;
  /// After ReadStretches and the slot's fence: the stretches' RGBA8 pixels, row 0 first.
  const PixelBuffers& stretch_buffers() const { return *stretch_buffers_; }

  /// With has_color_depth: starts the readback of the depth buffer the colour pass left (the
  /// view just drawn; window depth in [0, 1], 1 where nothing was drawn) into `slot`.
  void ReadColorDepth(int slot) const;
  /// After the slot's fence: ReadColorDepth's source-size floats, row 0 first.
  const PixelBuffers& color_depth_buffers() const { return *color_depth_buffers_; }

  /// After the slot's fence: the camera-size RGBA8 pixels, ids (uint32) and depth (float),
  /// row 0 at the top; nullptr on failure. Unmap each after use.
  const PixelBuffers& color_buffers() const { return color_buffers_; }
  const PixelBuffers& id_buffers() const { return *id_buffers_; }
  const PixelBuffers& depth_buffers() const { return *depth_buffers_; }

 private:
  // Binds the view's accumulation layer as the target of a full-screen pass that reads the
  // source views (blending onto what is there for kAdd); EndAccumulationPass restores the
  // state the scene passes expect.
  void BeginAccumulationPass(int view, Accumulation mode) const;
  void EndAccumulationPass() const;
  // The draw framebuffer on layer `layer` of `array` (with MSAA: on the multisampled buffer),
  // and the multisampled buffer resolved into that layer (nothing to do without MSAA).
  void BindLayerForDrawing(GLuint array, int layer) const;
  void ResolveInto(GLuint array, int layer) const;
  // The constructor's parts: the source views' array and the framebuffer that draws them
  // (with MSAA, its multisampled buffer and the one that resolves it); the lens remap's map,
  // footprint and mesh (and the remap on the CPU where asked); the truth arrays and outputs.
  void MakeSourceViews();
  void MakeLensRemap(bool lens_on_cpu);
  // The truth's remap pass and readback (the viewport set, the lens's map bound).
  void RemapTruth(EffectPrograms& programs, int slot) const;
  void MakeTruthTargets();

  geometry::LensMap lens_;
  int samples_;
  bool blur_;
  bool truth_;
  int source_width_, source_height_, layers_;
  GLuint source_ = 0;        // RGBA8 array
  GLuint accumulation_ = 0;  // RGBA32F array
  GLuint stretches_ = 0;     // RGBA8 array of kMaxTurnStretches layers (one source view only)
  GLuint map_ = 0;           // RGBA32F, camera size: RemapTable::map
  GLuint footprint_ = 0;     // RGBA32F, camera size: RemapTable::footprint
  GLuint residual_ = 0;      // RG8_SNORM, camera size: LensMesh::residual
  GLuint mesh_vao_ = 0, mesh_vertices_ = 0, mesh_indices_ = 0;  // LensMesh
  GLsizei mesh_linear_ = 0, mesh_exact_ = 0;                    // indices of each kind
  GLuint draw_framebuffer_ = 0;
  GLuint msaa_color_ = 0, depth_ = 0;  // renderbuffers (colour only with MSAA)
  GLuint resolve_framebuffer_ = 0;     // MSAA: the layer to resolve into
  GLuint accumulation_framebuffer_ = 0;
  GLuint truth_ids_ = 0, truth_z_ = 0, truth_depth_ = 0;  // R32UI, RG32F arrays; depth rb
  GLuint truth_framebuffer_ = 0;
  GLuint output_color_ = 0, output_framebuffer_ = 0;  // RGBA8, camera size
  GLuint output_ids_ = 0, output_z_ = 0, output_truth_framebuffer_ = 0;
  PixelBuffers color_buffers_;
  std::unique_ptr<PixelBuffers> id_buffers_, depth_buffers_;
  std::unique_ptr<CpuLens> cpu_lens_;
  std::unique_ptr<PixelBuffers> source_buffers_;       // with cpu_lens_
  std::unique_ptr<PixelBuffers> color_depth_buffers_;  // with color_depth, source size
  // kMaxTurnStretches layers' worth, made by the first ReadStretches.
  mutable std::unique_ptr<PixelBuffers> stretch_buffers_;
};

}  // namespace saccade::render::gl
