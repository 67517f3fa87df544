#pragma once
// The lens's photometric side (issue 45; docs/camera-pixels.md): vignetting, and the depth of
// field of a thin lens that focuses. CPU only, on images read back (no GL, no OpenCV); both work
// on linear values, before the colour filter and the tone curve (render/color_filter.h).
//
// Vignetting multiplies each pixel by its relative illumination:
//   kCos4:       cos^4(theta), theta the angle between the pixel's ray (the camera model's
//                Unproject: distortion included) and the optical axis; the natural fall-off of
//                a thin lens imaging a plane of uniform radiance;
//   kPolynomial: 1 + a1 r^2 + a2 r^4 + a3 r^6, r the distance from the principal point (cx,
//                cy) divided by the largest distance from it to a corner of the image
//                ([-0.5, width - 0.5] x [-0.5, height - 0.5]), so r = 1 at the farthest corner
//                (the normalisation of DNG's FixVignetteRadial opcode).
//
// Depth of field (thin lens): a point at depth d (its z in the camera's optical frame, metres,
// as renderer.h's Frame::depth) is imaged as a disc, the circle of confusion, of diameter
//   c(d) = A f |d - s| / (d (s - f)),   A = f / N
// on the sensor (f focal length, N f-number, s focus distance, all metres); d = 0 (no surface)
// and d = inf give the limit A f / (s - f). In pixels: c / pitch, the pitch given or f / fx
// (and f / fy vertically: the disc is an ellipse where fx != fy).

#include <array>
#include <cstdint>
#include <string_view>

#include "saccade/core/image.h"
#include "saccade/geometry/camera_model.h"
#include "saccade/geometry/intrinsics.h"
#include "saccade/scene/camera_optics.h"

namespace saccade::render {

/// How vignetting is modelled (kNone, kCos4, kPolynomial). The scene's type
/// (scene/camera_optics.h).
using VignettingModel = scene::VignettingModel;
/// "none", "cos4", "polynomial".
const char* ToString(VignettingModel model);
/// A model from "none", "cos4" or "polynomial"; throws InvalidArgument naming `field`.
VignettingModel ParseVignettingModel(std::string_view text,
                                     std::string_view field = "vignetting.model");

/// Vignetting of a camera.
struct VignettingOptions {
  VignettingModel model = VignettingModel::kNone;
  /// a1, a2, a3 of kPolynomial (r normalised as the file's header says).
  std::array<double, 3> coefficients{0.0, 0.0, 0.0};
  /// Throws InvalidArgument naming "vignetting.coefficients" when one is not finite or the
  /// polynomial is negative somewhere on r in [0, 1] (checked at 1001 radii).
  void Validate() const;
  /// The relative illumination at normalised radius r (kPolynomial; 1 for the others).
  double Polynomial(double r) const;
};

/// The relative illumination of every pixel of `camera`'s image (intrinsics' size): kFloat32,
/// 1 at the principal point; all ones for kNone; 0 where kCos4 finds no ray (outside the
/// distortion's invertible region). Throws as VignettingOptions::Validate.
Image VignettingFactors(const geometry::CameraModel& camera, const VignettingOptions& options);

/// Multiplies an RGB image by `factors` (VignettingFactors), rounded to nearest and clipped to
/// 255. Throws InvalidArgument when `rgb` is not kRgb8, `factors` not kFloat32, or the sizes
/// differ.
void ApplyVignetting(Image& rgb, const Image& factors);

/// A thin lens that focuses. Lengths in metres.
struct ThinLensOptions {
  double focal_length_m = 0.008;  ///< f: finite, > 0
  double f_number = 2.8;          ///< N: finite, > 0 (the aperture's diameter is f / N)
  double focus_distance_m = 2.0;  ///< s: where the lens focuses; finite, > f
  /// The sensor's pixel pitch (square pixels); 0: from the intrinsics, f / fx across and
  /// f / fy down (so that the focal length in pixels is K's). Finite, >= 0.
  double pixel_pitch_m = 0.0;
  /// The largest circle of confusion drawn, diameter in pixels (larger ones are drawn this
  /// large: the cost grows with its square). Finite, >= 1.
  double max_coc_px = 32.0;
  /// Throws InvalidArgument naming the field ("thin_lens.f_number: ...") and its value.
  void Validate() const;
};

/// The circle of confusion's diameter on the sensor (m) of a point at depth `depth_m` (z in the
/// camera frame; 0 or +inf: at infinity). Options must be valid.
double CircleOfConfusion(const ThinLensOptions& lens, double depth_m);
/// The same in pixels across (the pitch, or f / fx).
double CircleOfConfusionPx(const ThinLensOptions& lens, const geometry::Intrinsics& intrinsics,
                           double depth_m);

/// What ApplyDepthOfField did.
struct DepthOfFieldSummary {
  double max_coc_px = 0.0;    ///< the largest circle of confusion of the image, before capping
  int64_t capped_pixels = 0;  ///< pixels whose circle was capped at max_coc_px
};

/// The image as the thin lens sees it: each pixel blurred by the circles of confusion of its
/// depth. A gather that keeps occlusion (docs/camera-pixels.md):
///  - pixels at the depth of the output pixel p or behind it are averaged over p's own circle
///    (a gather), so that a blurred background never takes an in-focus foreground's colour and
///    an in-focus foreground stays sharp over a blurred background;
///  - pixels nearer than p (by more than 0.1 % of p's depth) are spread over their own circles
///    (a scatter, each weighted by 1 / its circle's area) and laid over that average with the
///    opacity their weights sum to (at most 1), so that a blurred foreground spreads over what
///    is behind it.
/// On one depth it is exactly a blur by the disc of that depth (pixels weighted by their
/// coverage of the disc, anti-aliased over one pixel). `depth` is kFloat32 of the same size (a
/// renderer's Frame::depth); `intrinsics` give the pitch when pixel_pitch_m is 0. Each pixel
/// visits only the offsets that a disc near it can reach, the rows run in chunks on every core,
/// and 16 pixels of a row at once where the CPU has AVX-512, 8 where it has AVX2, else 4 (the
/// same bits either way). Throws InvalidArgument on invalid options, formats or sizes.
Image ApplyDepthOfField(const ImageView& rgb, const ImageView& depth, const ThinLensOptions& lens,
                        const geometry::Intrinsics& intrinsics,
                        DepthOfFieldSummary* summary = nullptr);

/// The same image as a colour filter array samples it: Mosaic(ApplyDepthOfField(...), pattern)
/// (render/color_filter.h) to the bit, a BayerFormat(pattern, 8) image, with a third of the
/// gather's sums (each pixel's own colour only). What a Bayer camera's sensor exposes. Throws
/// as ApplyDepthOfField, and InvalidArgument for pattern kNone.
Image ApplyDepthOfFieldToMosaic(const ImageView& rgb, const ImageView& depth,
                                const ThinLensOptions& lens, const geometry::Intrinsics& intrinsics,
                                scene::CfaPattern pattern, DepthOfFieldSummary* summary = nullptr);

}  // namespace saccade::render
