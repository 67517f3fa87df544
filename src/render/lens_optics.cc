#include "saccade/render/lens_optics.h"

#include <fmt/format.h>

#include <Eigen/Core>
#include <algorithm>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "render/internal_chunks.h"
#include "render/internal_lens_optics.h"
#include "saccade/core/error.h"

namespace saccade::render {

namespace {

// A pixel nearer than the output pixel by more than this fraction of the output pixel's depth
// is in front of it (scattered over); closer ones belong to its surface (gathered). Above
// float depth's rounding, below any gap between objects that matters at the scale of a disc.
constexpr float kNearerFraction = 1e-3f;

void CheckLensPositive(double value, const char* field) {
  if (!std::isfinite(value) || value <= 0.0) {
    throw InvalidArgument(fmt::format("{}: expected a finite number > 0, got {}", field, value));
  }
}

// The sum of a disc's coverage (DofRow) over the plane: pi (r^2 + 1/12) for r >= 0.5 (the ramp
// integrated); below, the disc covers its own pixel only, by r + 0.5.
float DiscArea(float radius) {
  constexpr float kPi = std::numbers::pi_v<float>;
  return radius < 0.5f ? radius + 0.5f : kPi * (radius * radius + 1.0f / 12.0f);
}

// One offset of the gather's window: its step in the padded planes (DofPlanes::At) and its
// distance in pixels across (rows scaled by pitch_y / pitch_x, so that a disc on the sensor is
// a circle here).
struct WindowStep {
  std::ptrdiff_t step;
  float distance;
};

// Tiles of kDofTile x kDofTile pixels bound the circles a pixel's gather can meet.
constexpr int kDofTile = 16;
// The most pixels of a row gathered at once (DofRow: 16 with AVX-512, 8 with AVX2, else 4, one
// SSE vector): a divisor of kDofTile, so that a run never straddles two tiles.
constexpr int kDofMaxLanes = 16;
static_assert(kDofTile % kDofMaxLanes == 0);

// GCC vectors of kLanes floats (Vector; Loaded reads or writes one at any float's address), of
// kLanes ints and of their bytes. One specialisation per width: GCC drops a vector_size that
// depends on a template parameter (the type becomes a plain scalar).
template <int kLanes>
struct DofLanes;
// The byte shuffles between colours and ints read an int's low byte first.
static_assert(std::endian::native == std::endian::little);
template <>
struct DofLanes<4> {
  using Vector = float __attribute__((vector_size(16)));
  using Loaded = float __attribute__((vector_size(16), aligned(alignof(float)), may_alias));
  using Ints = int32_t __attribute__((vector_size(16)));
  using Bytes = uint8_t __attribute__((vector_size(16)));
  using LoadedBytes = uint8_t __attribute__((vector_size(16), aligned(1), may_alias));
  using LaneBytes = uint8_t __attribute__((vector_size(4)));  // a byte a lane
};
template <>
struct DofLanes<8> {
  using Vector = float __attribute__((vector_size(32)));
  using Loaded = float __attribute__((vector_size(32), aligned(alignof(float)), may_alias));
  using Ints = int32_t __attribute__((vector_size(32)));
  using Bytes = uint8_t __attribute__((vector_size(32)));
  using LoadedBytes = uint8_t __attribute__((vector_size(32), aligned(1), may_alias));
  using LaneBytes = uint8_t __attribute__((vector_size(8)));  // a byte a lane
};
template <>
struct DofLanes<16> {
  using Vector = float __attribute__((vector_size(64)));
  using Loaded = float __attribute__((vector_size(64), aligned(alignof(float)), may_alias));
  using Ints = int32_t __attribute__((vector_size(64)));
  using Bytes = uint8_t __attribute__((vector_size(64)));
  using LoadedBytes = uint8_t __attribute__((vector_size(64), aligned(1), may_alias));
  using LaneBytes = uint8_t __attribute__((vector_size(16)));  // a byte a lane
};

// What the gather reads per pixel, in planes padded around the image (pad_x, pad_y: at least
// the window's reach) and kDofMaxLanes more on the right, so that a run of pixels reads every
// offset without a bounds test: depth (+inf without a surface, NaN in the padding: neither in
// front of a pixel nor behind it, so its terms weigh 0), the circle's outer edge (radius + 0.5:
// where the coverage's ramp ends; radius in pixels across, capped), its area (DiscArea) and the
// colour's three channels. Also the window's offsets sorted by distance, and per tile the
// largest outer edge of any pixel within the window's reach of the tile (so that a pixel's
// gather stops where no disc, its own or a nearer pixel's, can cover it: the same terms, fewer
// visits).
struct DofPlanes {
  int width = 0, height = 0;
  int pad_x = 0, pad_y = 0, stride = 0;  // stride: padded plane's row, in values
  // The planes one after the other; not zeroed (PrepareDof writes every value once).
  std::unique_ptr<float[]> values;
  float *depth = nullptr, *outer = nullptr, *area = nullptr, *color[3] = {};
  std::vector<WindowStep> window;
  int tiles_x = 0;
  std::vector<float> reach;  // per tile: the largest outer edge in it, then near it
  // The index of image pixel (x, y) in the padded planes.
  std::size_t At(int x, int y) const {
    return static_cast<std::size_t>(y + pad_y) * stride + static_cast<std::size_t>(x + pad_x);
  }
};

// What PrepareDof takes from one part of the rows: the summary's share and the largest radius.
struct DofPart {
  double max_coc_px = 0.0;
  int64_t capped_pixels = 0;
  float max_radius = 0.0f;
};

// CircleOfConfusionPx's terms, in its order, hoisted out of the loop: the circle at infinity in
// pixels, the focus distance, the cap.
struct DofLensTerms {
  double at_infinity_px, focus, max_coc_px;
};

// Values [first, end) of every plane as the padding's: out of the image.
void FillDofPadding(DofPlanes* planes, std::size_t first, std::size_t end) {
  std::fill(planes->depth + first, planes->depth + end, std::numeric_limits<float>::quiet_NaN());
  std::fill(planes->outer + first, planes->outer + end, 0.5f);
  std::fill(planes->area + first, planes->area + end, DiscArea(0.0f));
  for (float* c : planes->color) std::fill(c + first, c + end, 0.0f);
}

// Pixel i of the planes from depth d and colour c; the circle in double, as
// CircleOfConfusionPx (the summary is in double; a radius computed in float could round the
// other way). The scalar form of PrepareDofRow's vectors, for a row's last pixels; inlined (a
// call from AVX code to SSE code costs more than the pixel).
[[gnu::always_inline]] inline void PrepareDofPixel(float d, const uint8_t* c,
                                                   const DofLensTerms& terms, std::size_t i,
                                                   DofPlanes* planes, DofPart* part) {
  const bool surface = std::isfinite(d) && d > 0.0f;
  const double coc =
      surface ? terms.at_infinity_px * std::abs(d - terms.focus) / d : terms.at_infinity_px;
  part->max_coc_px = std::max(part->max_coc_px, coc);
  part->capped_pixels += coc > terms.max_coc_px;
  const auto r = static_cast<float>(0.5 * std::min(coc, terms.max_coc_px));
  part->max_radius = std::max(part->max_radius, r);
  planes->depth[i] = surface ? d : std::numeric_limits<float>::infinity();
  planes->outer[i] = r + 0.5f;
  planes->area[i] = DiscArea(r);
  for (int ch = 0; ch < 3; ++ch) planes->color[ch][i] = c[ch];
}

// Pixels x .. x + 3 of an RGB row (`rgb` at pixel x) into the colour planes' values x ..
// x + 3. kShuffleBytes: the bytes sorted by one shuffle (pshufb with AVX2; plain SSE2 has none,
// and the compiler's stand-in costs more than converting byte by byte).
template <bool kShuffleBytes>
[[gnu::always_inline]] inline void PrepareDofColors(const uint8_t* rgb, int x,
                                                    float* const color_out[3]) {
  using Vector = DofLanes<4>::Vector;
  using Loaded = DofLanes<4>::Loaded;
  using Ints = DofLanes<4>::Ints;
  using Bytes = uint8_t __attribute__((vector_size(16)));
  using LoadedBytes = uint8_t __attribute__((vector_size(16), aligned(1), may_alias));
  if constexpr (kShuffleBytes) {
    // The 4 pixels' 12 bytes (read as 16: the caller leaves 2 more pixels in the row),
    // each channel's 4 widened to ints, then floats.
    const Bytes rgb4 = *reinterpret_cast<const LoadedBytes*>(rgb);
    constexpr Bytes kZero{};
    *reinterpret_cast<Loaded*>(color_out[0] + x) = __builtin_convertvector(
        reinterpret_cast<Ints>(__builtin_shufflevector(rgb4, kZero, 0, 16, 16, 16, 3, 16, 16, 16, 6,
                                                       16, 16, 16, 9, 16, 16, 16)),
        Vector);
    *reinterpret_cast<Loaded*>(color_out[1] + x) = __builtin_convertvector(
        reinterpret_cast<Ints>(__builtin_shufflevector(rgb4, kZero, 1, 16, 16, 16, 4, 16, 16, 16, 7,
                                                       16, 16, 16, 10, 16, 16, 16)),
        Vector);
    *reinterpret_cast<Loaded*>(color_out[2] + x) = __builtin_convertvector(
        reinterpret_cast<Ints>(__builtin_shufflevector(rgb4, kZero, 2, 16, 16, 16, 5, 16, 16, 16, 8,
                                                       16, 16, 16, 11, 16, 16, 16)),
        Vector);
  } else {
    for (int j = 0; j < 4; ++j) {
      for (int ch = 0; ch < 3; ++ch) color_out[ch][x + j] = rgb[3 * j + ch];
    }
  }
}

// CircleOfConfusionPx of depths `dd` (a vector of doubles) into `coc`, lane by lane its
// operations: at infinity where the depth is no surface. Inlined into PrepareDofRow's targets
// (through pointers: a vector returned would change the ABI between targets).
template <typename Doubles, typename Bits>
[[gnu::always_inline]] inline void DofCircles(const Doubles& dd, const DofLensTerms& terms,
                                              Doubles* coc) {
  // std::abs: the sign bit cleared.
  const Doubles distance = reinterpret_cast<Doubles>(reinterpret_cast<Bits>(dd - terms.focus) &
                                                     (Bits{} + ~(uint64_t{1} << 63)));
  // isfinite(d) && d > 0: d > 0 && d < inf (false for NaN).
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  *coc = (dd > 0.0) & (dd < kInfinity) ? terms.at_infinity_px * distance / dd
                                       : Doubles{} + terms.at_infinity_px;
}

// Image row y into the planes, with its padding left and right, 4 pixels at a time (each
// value PrepareDofPixel's: the same operations, lane by lane); each tile's largest outer edge
// into planes->reach. Inlined as DofRow is. kShuffleBytes: PrepareDofColors'.
template <bool kShuffleBytes>
[[gnu::always_inline]] inline void PrepareDofRow(const ImageView& rgb, const ImageView& depth,
                                                 const DofLensTerms& terms, int y,
                                                 DofPlanes* planes, DofPart* part) {
  using Vector = DofLanes<4>::Vector;
  using Loaded = DofLanes<4>::Loaded;
  using Halves = float __attribute__((vector_size(8)));
  using LoadedHalf = float __attribute__((vector_size(8), aligned(alignof(float)), may_alias));
  using Doubles = double __attribute__((vector_size(16)));
  using Bits = uint64_t __attribute__((vector_size(16)));
  using Doubles4 = double __attribute__((vector_size(32)));
  using Bits4 = uint64_t __attribute__((vector_size(32)));
  constexpr float kInfinity = std::numeric_limits<float>::infinity();
  const int w = planes->width;
  const std::size_t row_start = planes->At(0, y);
  const float* d_row = reinterpret_cast<const float*>(depth.row(y));
  const uint8_t* c = rgb.row(y);
  float* const depth_out = planes->depth + row_start;
  float* const outer_out = planes->outer + row_start;
  float* const area_out = planes->area + row_start;
  float* const color_out[3] = {planes->color[0] + row_start, planes->color[1] + row_start,
                               planes->color[2] + row_start};
  Doubles max_coc = Doubles{} + part->max_coc_px;
  Bits capped{};
  Doubles4 max_coc4 = Doubles4{} + part->max_coc_px;
  Bits4 capped4{};
  Vector max_radius = Vector{} + part->max_radius;
  float* const tile = &planes->reach[static_cast<std::size_t>(y / kDofTile) * planes->tiles_x];
  for (int first = 0; first < w; first += kDofTile) {
    const int end = std::min(w, first + kDofTile);
    Vector tile_outer = Vector{} + tile[first / kDofTile];
    int x = first;
    for (; x + 4 <= end && x + 6 <= w; x += 4) {
      const Vector d = *reinterpret_cast<const Loaded*>(d_row + x);
      // The circle in double (CircleOfConfusionPx), four at a time with AVX, else two at a
      // time (one SSE vector: wider ones are split by the compiler, badly without AVX).
      Vector r;
      if constexpr (kShuffleBytes) {
        const Doubles4 dd = __builtin_convertvector(d, Doubles4);
        Doubles4 coc;
        DofCircles<Doubles4, Bits4>(dd, terms, &coc);
        max_coc4 = max_coc4 < coc ? coc : max_coc4;
        capped4 -= reinterpret_cast<Bits4>(coc > terms.max_coc_px);  // -1 where capped
        r = __builtin_convertvector(
            0.5 * (terms.max_coc_px < coc ? Doubles4{} + terms.max_coc_px : coc), Vector);
      } else {
        Halves radius[2];
#pragma GCC unroll 2
        for (int h = 0; h < 2; ++h) {
          const Doubles dd = __builtin_convertvector(
              *reinterpret_cast<const LoadedHalf*>(d_row + x + 2 * h), Doubles);
          Doubles coc;
          DofCircles<Doubles, Bits>(dd, terms, &coc);
          max_coc = max_coc < coc ? coc : max_coc;
          capped -= reinterpret_cast<Bits>(coc > terms.max_coc_px);  // -1 where capped
          radius[h] = __builtin_convertvector(
              0.5 * (terms.max_coc_px < coc ? Doubles{} + terms.max_coc_px : coc), Halves);
        }
        r = __builtin_shufflevector(radius[0], radius[1], 0, 1, 2, 3);
      }
      max_radius = max_radius < r ? r : max_radius;
      *reinterpret_cast<Loaded*>(depth_out + x) =
          (d > 0.0f) & (d < kInfinity) ? d : Vector{} + kInfinity;
      const Vector outer = r + 0.5f;
      *reinterpret_cast<Loaded*>(outer_out + x) = outer;
      tile_outer = tile_outer < outer ? outer : tile_outer;
      // DiscArea.
      *reinterpret_cast<Loaded*>(area_out + x) =
          r < 0.5f ? r + 0.5f : std::numbers::pi_v<float> * (r * r + 1.0f / 12.0f);
      PrepareDofColors<kShuffleBytes>(c + 3 * x, x, color_out);
    }
    float m = std::max({tile_outer[0], tile_outer[1], tile_outer[2], tile_outer[3]});
    // The row's last 2 to 5 pixels (PrepareDofColors reads 2 pixels past its 4).
    for (; x < end; ++x) {
      PrepareDofPixel(d_row[x], c + 3 * x, terms, row_start + x, planes, part);
      m = std::max(m, outer_out[x]);
    }
    tile[first / kDofTile] = m;
  }
  for (int j = 0; j < 2; ++j) {
    part->max_coc_px = std::max(part->max_coc_px, max_coc[j]);
    part->capped_pixels += static_cast<int64_t>(capped[j]);
  }
  for (int j = 0; j < 4; ++j) {
    part->max_coc_px = std::max(part->max_coc_px, max_coc4[j]);
    part->capped_pixels += static_cast<int64_t>(capped4[j]);
  }
  for (int j = 0; j < 4; ++j) part->max_radius = std::max(part->max_radius, max_radius[j]);
  FillDofPadding(planes, row_start - planes->pad_x, row_start);
  FillDofPadding(planes, row_start + w, row_start + w + planes->pad_x + kDofMaxLanes);
}

void PrepareDofRowsPortable(const ImageView& rgb, const ImageView& depth, const DofLensTerms& terms,
                            int first, int end, DofPlanes* planes, DofPart* part) {
  for (int y = first; y < end; ++y) PrepareDofRow<false>(rgb, depth, terms, y, planes, part);
}

#if defined(__x86_64__)
// No "fma" (DofRowsAvx2).
__attribute__((target("avx2"))) void PrepareDofRowsAvx2(const ImageView& rgb,
                                                        const ImageView& depth,
                                                        const DofLensTerms& terms, int first,
                                                        int end, DofPlanes* planes, DofPart* part) {
  for (int y = first; y < end; ++y) PrepareDofRow<true>(rgb, depth, terms, y, planes, part);
}
#endif

// DofPlanes::reach: from each tile's largest outer edge (PrepareDofRows), the largest over the
// tiles the window reaches from it.
void PrepareTileReach(DofPlanes* planes, int reach_x, int reach_y) {
  const int tiles_x = planes->tiles_x;
  const int tiles_y = (planes->height + kDofTile - 1) / kDofTile;
  const std::vector<float> tile_max = planes->reach;
  const int tx_reach = (reach_x + kDofTile - 1) / kDofTile;
  const int ty_reach = (reach_y + kDofTile - 1) / kDofTile;
  for (int ty = 0; ty < tiles_y; ++ty) {
    for (int tx = 0; tx < tiles_x; ++tx) {
      float m = 0.0f;
      for (int j = std::max(0, ty - ty_reach); j <= std::min(tiles_y - 1, ty + ty_reach); ++j) {
        for (int i = std::max(0, tx - tx_reach); i <= std::min(tiles_x - 1, tx + tx_reach); ++i) {
          m = std::max(m, tile_max[static_cast<std::size_t>(j) * tiles_x + i]);
        }
      }
      planes->reach[static_cast<std::size_t>(ty) * tiles_x + tx] = m;
    }
  }
}

// The reach of a circle of outer edge `edge` (pixels across) across and down, each no more
// than `limit` (in double: a huge circle's reach overflows an int).
int DofReach(float edge, double aspect, int limit) {
  return static_cast<int>(std::min(std::ceil(edge / aspect), static_cast<double>(limit)));
}

// The window's offsets within the largest circle, sorted by distance (stable: rows then
// columns where distances tie, the order of the scalar gather). Offsets a whole image away
// land in the padding from every pixel: left out (their terms are 0).
void PrepareWindow(DofPlanes* planes, float max_radius, double aspect) {
  const int reach_x = DofReach(max_radius + 0.5f, 1.0, planes->width - 1);
  const int reach_y = DofReach(max_radius + 0.5f, aspect, planes->height - 1);
  for (int dy = -reach_y; dy <= reach_y; ++dy) {
    for (int dx = -reach_x; dx <= reach_x; ++dx) {
      const auto distance = static_cast<float>(std::hypot(dx, dy * aspect));
      if (distance < max_radius + 0.5f) {
        planes->window.push_back({static_cast<std::ptrdiff_t>(dy) * planes->stride + dx, distance});
      }
    }
  }
  std::stable_sort(
      planes->window.begin(), planes->window.end(),
      [](const WindowStep& a, const WindowStep& b) { return a.distance < b.distance; });
  PrepareTileReach(planes, reach_x, reach_y);
}

// rows(slot, first, end) over [0, height) in tiles' rows on every core (ForEachChunk: each
// row is computed alone, the same bits): the halves of an image cost differently (a blurred
// foreground below a sharp background), so that threads claim a tile's rows at a time; claims
// at a tile's edge keep each tile to one thread.
template <typename Rows>
void ShareDofRows(int height, const Rows& rows) {
  internal::ForEachRowChunk(height, rows, kDofTile);
}

DofPlanes PrepareDof(const ImageView& rgb, const ImageView& depth, const ThinLensOptions& lens,
                     const geometry::Intrinsics& k, bool wide, DepthOfFieldSummary* summary) {
  DofPlanes planes;
  planes.width = depth.width();
  planes.height = depth.height();
  // Padded for the capped circle, so that one pass fills the planes: the window, cut at the
  // largest circle found (a radius <= cap, rounded the same way), reaches no farther, nor past
  // the image's size (PrepareWindow).
  const double aspect = lens.pixel_pitch_m > 0.0 ? 1.0 : k.fx() / k.fy();  // pitch_y / pitch_x
  const auto cap = static_cast<float>(
      std::min(0.5 * lens.max_coc_px, static_cast<double>(std::numeric_limits<float>::max())));
  planes.pad_x = DofReach(cap + 0.5f, 1.0, planes.width);
  planes.pad_y = DofReach(cap + 0.5f, aspect, planes.height);
  planes.stride = planes.width + 2 * planes.pad_x + kDofMaxLanes;
  const std::size_t n =
      static_cast<std::size_t>(planes.stride) * (planes.height + 2 * planes.pad_y);
  planes.values = std::make_unique_for_overwrite<float[]>(6 * n);
  planes.depth = planes.values.get();
  planes.outer = planes.depth + n;
  planes.area = planes.outer + n;
  for (int ch = 0; ch < 3; ++ch) planes.color[ch] = planes.area + (ch + 1) * n;
  planes.tiles_x = (planes.width + kDofTile - 1) / kDofTile;
  planes.reach.assign(
      static_cast<std::size_t>(planes.tiles_x) * ((planes.height + kDofTile - 1) / kDofTile), 0.0f);
  const DofLensTerms terms{CircleOfConfusionPx(lens, k, 0.0), lens.focus_distance_m,
                           lens.max_coc_px};
  std::vector<DofPart> parts(static_cast<std::size_t>(internal::ChunkSlots()));
  ShareDofRows(planes.height, [&](int part, int first, int end) {
    if (first == 0) FillDofPadding(&planes, 0, planes.At(-planes.pad_x, 0));
#if defined(__x86_64__)
    if (wide) {
      PrepareDofRowsAvx2(rgb, depth, terms, first, end, &planes, &parts[part]);
    } else {
      PrepareDofRowsPortable(rgb, depth, terms, first, end, &planes, &parts[part]);
    }
#else
    static_cast<void>(wide);
    PrepareDofRowsPortable(rgb, depth, terms, first, end, &planes, &parts[part]);
#endif
    if (end == planes.height) FillDofPadding(&planes, planes.At(-planes.pad_x, end), n);
  });
  DofPart all;  // the parts' maxima and sums: the same whatever rows each part took
  for (const DofPart& part : parts) {
    all.max_coc_px = std::max(all.max_coc_px, part.max_coc_px);
    all.capped_pixels += part.capped_pixels;
    all.max_radius = std::max(all.max_radius, part.max_radius);
  }
  summary->max_coc_px = all.max_coc_px;
  summary->capped_pixels = all.capped_pixels;
  PrepareWindow(&planes, all.max_radius, aspect);
  return planes;
}

// Whether any lane of a comparison's mask is true (GCC reduces it with vector ORs).
template <typename Ints>
[[gnu::always_inline]] inline bool AnyLane(const Ints& mask) {
  uint64_t words[sizeof(Ints) / sizeof(uint64_t)];
  std::memcpy(words, &mask, sizeof(mask));
  uint64_t any = 0;
  for (const uint64_t word : words) any |= word;
  return any != 0;
}

// A run of kLanes pixels' rounded channels into an RGB row at pixel x: each lane's RGB in its
// int's low 3 bytes, packed to the front of the vector; stored whole where the row has room
// (the bytes past the run's are the next run's, written after).
template <int kLanes>
[[gnu::always_inline]] inline void DofStoreRgb(const typename DofLanes<kLanes>::Ints rounded[3],
                                               int x, int width, uint8_t* out) {
  using Ints = typename DofLanes<kLanes>::Ints;
  using Bytes = typename DofLanes<kLanes>::Bytes;
  using LoadedBytes = typename DofLanes<kLanes>::LoadedBytes;
  const Ints rgb = rounded[0] | rounded[1] << 8 | rounded[2] << 16;
  const Bytes bytes = reinterpret_cast<Bytes>(rgb);
  uint8_t* const run_out = out + 3 * x;
  if (3 * x + static_cast<int>(sizeof(Bytes)) <= 3 * width) {
    if constexpr (kLanes == 16) {
      *reinterpret_cast<LoadedBytes*>(run_out) = __builtin_shufflevector(
          bytes, bytes, 0, 1, 2, 4, 5, 6, 8, 9, 10, 12, 13, 14, 16, 17, 18, 20, 21, 22, 24, 25, 26,
          28, 29, 30, 32, 33, 34, 36, 37, 38, 40, 41, 42, 44, 45, 46, 48, 49, 50, 52, 53, 54, 56,
          57, 58, 60, 61, 62, 3, 7, 11, 15, 19, 23, 27, 31, 35, 39, 43, 47, 51, 55, 59, 63);
    } else if constexpr (kLanes == 8) {
      *reinterpret_cast<LoadedBytes*>(run_out) =
          __builtin_shufflevector(bytes, bytes, 0, 1, 2, 4, 5, 6, 8, 9, 10, 12, 13, 14, 16, 17, 18,
                                  20, 21, 22, 24, 25, 26, 28, 29, 30, 3, 7, 11, 15, 19, 23, 27, 31);
    } else {
      *reinterpret_cast<LoadedBytes*>(run_out) = __builtin_shufflevector(
          bytes, bytes, 0, 1, 2, 4, 5, 6, 8, 9, 10, 12, 13, 14, 3, 7, 11, 15);
    }
  } else {
    for (int j = 0; j < std::min(kLanes, width - x); ++j) {
      for (int ch = 0; ch < 3; ++ch) run_out[3 * j + ch] = static_cast<uint8_t>(rounded[ch][j]);
    }
  }
}

// Lanes 0, 2, 4, ... of the kLanes floats at `even_at` and 1, 3, 5, ... of those at `odd_at`
// (unaligned) into `out`: two loads and one blend (a select by a constant mask, which g++ builds
// from single floats instead).
template <int kLanes>
[[gnu::always_inline]] inline void DofAlternate(const float* even_at, const float* odd_at,
                                                typename DofLanes<kLanes>::Vector* out) {
  using Loaded = typename DofLanes<kLanes>::Loaded;
  const typename DofLanes<kLanes>::Vector even = *reinterpret_cast<const Loaded*>(even_at),
                                          odd = *reinterpret_cast<const Loaded*>(odd_at);
  if constexpr (kLanes == 16) {
    *out = __builtin_shufflevector(even, odd, 0, 17, 2, 19, 4, 21, 6, 23, 8, 25, 10, 27, 12, 29, 14,
                                   31);
  } else if constexpr (kLanes == 8) {
    *out = __builtin_shufflevector(even, odd, 0, 9, 2, 11, 4, 13, 6, 15);
  } else {
    *out = __builtin_shufflevector(even, odd, 0, 5, 2, 7);
  }
}

// The colours a run's gather sums: the three planes of an RGB image, or (a mosaic's) one
// channel a pixel, the row's two channels alternating lane by lane (a run starts at an even
// pixel). `cell`: the filter's 2 x 2 cell (CfaChannel), or null for RGB.
// A mosaic's: plane[0] at even pixels, plane[1] at odd ones (DofRow's kChannels says which).
struct DofChannels {
  const float* plane[3];
};
inline DofChannels ChannelsOf(const DofPlanes& planes, const int* cell, int y) {
  if (cell == nullptr) return {{planes.color[0], planes.color[1], planes.color[2]}};
  return {{planes.color[cell[(y & 1) * 2]], planes.color[cell[(y & 1) * 2 + 1]], nullptr}};
}

// Row y of the image, kLanes output pixels at a time (the header's gather of what is behind,
// scatter of what is in front), into `out`: RGB (kChannels 3) or the mosaic's one value a pixel
// (kChannels 1: each lane's own channel of `channels`, the same sums as that channel's of the
// RGB gather, so the same bits as its mosaic). The tile's reach bounds every pixel's own circle
// and those near it (the window is sorted by distance): beyond it every term is 0. Each term is
// the scalar gather's, in its order: the same bits as pixel by pixel, with 4 lanes, 8 or 16.
// Inlined into DofRowsPortable, DofRowsAvx2 and DofRowsAvx512, so that each is compiled for its
// target; the vectors are never passed to a function (their ABI differs with and without AVX).
template <int kLanes, int kChannels>
[[gnu::always_inline]] inline void DofRow(const DofPlanes& planes, const DofChannels& channels,
                                          int y, uint8_t* out) {
  using Vector = typename DofLanes<kLanes>::Vector;
  using Loaded = typename DofLanes<kLanes>::Loaded;
  using Ints = typename DofLanes<kLanes>::Ints;
  const float* tile_reach = &planes.reach[static_cast<std::size_t>(y / kDofTile) * planes.tiles_x];
  // Locals: the stores below could alias the planes' pointers, which would be reloaded.
  const float *const depth = planes.depth, *const outer = planes.outer, *const area = planes.area;
  const float* const color[3] = {channels.plane[0], channels.plane[1], channels.plane[2]};
  for (int x = 0; x < planes.width; x += kLanes) {
    const std::size_t p = planes.At(x, y);
    const Vector outer_p = *reinterpret_cast<const Loaded*>(outer + p);
    const Vector nearer = *reinterpret_cast<const Loaded*>(depth + p) * (1.0f - kNearerFraction);
    Vector back_weight{}, front_weight{}, back[kChannels] = {}, front[kChannels] = {};
    const float limit = tile_reach[x / kDofTile];
    for (const WindowStep& o : planes.window) {
      if (o.distance >= limit) break;
      const std::size_t q = p + o.step;
      const Vector depth_q = *reinterpret_cast<const Loaded*>(depth + q);
      // How much of p each disc covers, anti-aliased over one pixel: radius + 0.5 - distance,
      // clamped to [0, 1]; q's disc and p's.
      Vector cover_q = *reinterpret_cast<const Loaded*>(outer + q) - o.distance;
      cover_q = cover_q < 0.0f ? Vector{} : cover_q;
      cover_q = cover_q > 1.0f ? Vector{} + 1.0f : cover_q;
      Vector cover_p = outer_p - o.distance;
      cover_p = cover_p < 0.0f ? Vector{} : cover_p;
      cover_p = cover_p > 1.0f ? Vector{} + 1.0f : cover_p;
      // In front: q's disc over p, weighed by 1 / its area; behind (or at p's depth): p's disc
      // over q. Padding is neither. A side no lane is on is skipped: its terms are +0, which
      // leave the sums (+0 or more) as they are.
      const Ints in_front = depth_q < nearer, behind = depth_q >= nearer;
      // q's colours, lane by lane (a mosaic's: each lane's own channel).
      Vector color_q[kChannels];
      if constexpr (kChannels == 3) {
#pragma GCC unroll 3
        for (int ch = 0; ch < 3; ++ch)
          color_q[ch] = *reinterpret_cast<const Loaded*>(color[ch] + q);
      } else {
        DofAlternate<kLanes>(color[0] + q, color[1] + q, &color_q[0]);
      }
      if (AnyLane(in_front)) {
        const Vector f = in_front ? cover_q / *reinterpret_cast<const Loaded*>(area + q) : Vector{};
        front_weight += f;
#pragma GCC unroll 3
        for (int ch = 0; ch < kChannels; ++ch) front[ch] += f * color_q[ch];
      }
      if (AnyLane(behind)) {
        const Vector b = behind ? cover_p : Vector{};
        back_weight += b;
#pragma GCC unroll 3
        for (int ch = 0; ch < kChannels; ++ch) back[ch] += b * color_q[ch];
      }
    }
    // The average behind, and over it what is in front with the opacity its weights sum to
    // (at most 1); lane by lane the scalar gather's operations (std::min, std::clamp as their
    // comparisons), the lanes without a weight's division discarded.
    const Vector alpha = front_weight < 1.0f ? front_weight : Vector{} + 1.0f;
    Ints rounded[kChannels];
#pragma GCC unroll 3
    for (int ch = 0; ch < kChannels; ++ch) {
      Vector value = back_weight > 0.0f ? back[ch] / back_weight : Vector{};
      value =
          front_weight > 0.0f ? alpha * front[ch] / front_weight + (1.0f - alpha) * value : value;
      value = value < 0.0f ? Vector{} : value;
      value = value > 255.0f ? Vector{} + 255.0f : value;
      // lround of a value in [0, 255]: its integer part, + 1 where the fraction (exact: the
      // difference of two floats within a factor of 2, or the value below 1) is >= 0.5.
      const Ints whole = __builtin_convertvector(value, Ints);
      rounded[ch] = whole - (value - __builtin_convertvector(whole, Vector) >= 0.5f);
    }
    if constexpr (kChannels == 1) {
      // Each lane's byte; stored whole where the row has room.
      using LaneBytes = typename DofLanes<kLanes>::LaneBytes;
      const LaneBytes bytes = __builtin_convertvector(rounded[0], LaneBytes);
      if (x + kLanes <= planes.width) {
        std::memcpy(out + x, &bytes, sizeof(bytes));
      } else {
        for (int j = 0; j < planes.width - x; ++j) out[x + j] = bytes[j];
      }
    } else {
      DofStoreRgb<kLanes>(rounded, x, planes.width, out);
    }
  }
}

// Rows [first, end) of DofRow's output into `out` (kRgb8, or the mosaic of `cell`).
template <int kLanes>
[[gnu::always_inline]] inline void DofRows(const DofPlanes& planes, const int* cell, int first,
                                           int end, Image* out) {
  for (int y = first; y < end; ++y) {
    const DofChannels channels = ChannelsOf(planes, cell, y);
    if (cell == nullptr) {
      DofRow<kLanes, 3>(planes, channels, y, out->row(y));
    } else {
      DofRow<kLanes, 1>(planes, channels, y, out->row(y));
    }
  }
}

void DofRowsPortable(const DofPlanes& planes, const int* cell, int first, int end, Image* out) {
  DofRows<4>(planes, cell, first, end, out);
}

#if defined(__x86_64__)
// No "fma" in the targets: a fused multiply-add would round once where the gather rounds twice
// (and -std=c++20 contracts none).
__attribute__((target("avx2"))) void DofRowsAvx2(const DofPlanes& planes, const int* cell,
                                                 int first, int end, Image* out) {
  DofRows<8>(planes, cell, first, end, out);
}
__attribute__((target("avx512f,avx512bw,avx512dq,avx512vl"))) void DofRowsAvx512(
    const DofPlanes& planes, const int* cell, int first, int end, Image* out) {
  DofRows<16>(planes, cell, first, end, out);
}
#endif

// Pixels [first, end) of a row of ApplyVignetting: each value times its pixel's factor, clamped
// to [0, 255] and rounded half away from zero (value + 0.5 is exact in double, its truncation
// the rounding).
void VignetteRow(uint8_t* row, const float* f, int first, int end) {
  for (int x = first; x < end; ++x) {
    for (int ch = 0; ch < 3; ++ch) {
      const float value = std::clamp(row[3 * x + ch] * f[x], 0.0f, 255.0f);
      row[3 * x + ch] = static_cast<uint8_t>(static_cast<double>(value) + 0.5);
    }
  }
}

#if defined(__x86_64__)
// The same, 8 pixels (24 values) at a time: the factors spread to the values by permutation,
// the same float product, clamp and rounding in double as VignetteRow (no FMA: the same bits).
// Returns the first pixel left for VignetteRow.
__attribute__((target("avx2"))) int VignetteRowAvx2(uint8_t* row, const float* f, int width) {
  const __m256i spread[3] = {_mm256_setr_epi32(0, 0, 0, 1, 1, 1, 2, 2),
                             _mm256_setr_epi32(2, 3, 3, 3, 4, 4, 4, 5),
                             _mm256_setr_epi32(5, 5, 6, 6, 6, 7, 7, 7)};
  const __m256 low = _mm256_setzero_ps(), high = _mm256_set1_ps(255.0f);
  const __m256d half = _mm256_set1_pd(0.5);
  int x = 0;
  for (; x + 8 <= width; x += 8) {
    const __m256 factors = _mm256_loadu_ps(f + x);
    uint8_t* values = row + 3 * x;
    for (int k = 0; k < 3; ++k) {
      const __m128i bytes = _mm_loadl_epi64(reinterpret_cast<const __m128i*>(values + 8 * k));
      const __m256 v = _mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_cvtepu8_epi32(bytes)),
                                     _mm256_permutevar8x32_ps(factors, spread[k]));
      const __m256 c = _mm256_max_ps(_mm256_min_ps(v, high), low);
      const __m128i a =
          _mm256_cvttpd_epi32(_mm256_add_pd(_mm256_cvtps_pd(_mm256_castps256_ps128(c)), half));
      const __m128i b =
          _mm256_cvttpd_epi32(_mm256_add_pd(_mm256_cvtps_pd(_mm256_extractf128_ps(c, 1)), half));
      const __m128i words = _mm_packs_epi32(a, b);
      _mm_storel_epi64(reinterpret_cast<__m128i*>(values + 8 * k), _mm_packus_epi16(words, words));
    }
  }
  return x;
}
#endif

}  // namespace

const char* ToString(VignettingModel model) {
  switch (model) {
    case VignettingModel::kNone:
      return "none";
    case VignettingModel::kCos4:
      return "cos4";
    case VignettingModel::kPolynomial:
      return "polynomial";
  }
  return "unknown";
}

VignettingModel ParseVignettingModel(std::string_view text, std::string_view field) {
  std::string name(text);
  for (char& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  for (VignettingModel m :
       {VignettingModel::kNone, VignettingModel::kCos4, VignettingModel::kPolynomial}) {
    if (name == ToString(m)) return m;
  }
  throw InvalidArgument(fmt::format(
      "{}: unknown vignetting model '{}', expected none, cos4 or polynomial", field, text));
}

double VignettingOptions::Polynomial(double r) const {
  if (model != VignettingModel::kPolynomial) return 1.0;
  const double r2 = r * r;
  return 1.0 + r2 * (coefficients[0] + r2 * (coefficients[1] + r2 * coefficients[2]));
}

void VignettingOptions::Validate() const {
  for (std::size_t i = 0; i < coefficients.size(); ++i) {
    if (!std::isfinite(coefficients[i])) {
      throw InvalidArgument(fmt::format(
          "vignetting.coefficients: a{} is {}, expected a finite number", i + 1, coefficients[i]));
    }
  }
  for (int i = 0; i <= 1000; ++i) {
    const double r = i / 1000.0;
    if (Polynomial(r) < 0.0) {
      throw InvalidArgument(fmt::format(
          "vignetting.coefficients: 1 + {} r^2 + {} r^4 + {} r^6 is {} at r = {}, expected a "
          "relative illumination >= 0 for r in [0, 1]",
          coefficients[0], coefficients[1], coefficients[2], Polynomial(r), r));
    }
  }
}

Image VignettingFactors(const geometry::CameraModel& camera, const VignettingOptions& options) {
  options.Validate();
  const geometry::Intrinsics& k = camera.intrinsics();
  Image factors(k.width(), k.height(), PixelFormat::kFloat32);
  double farthest = 0.0;  // principal point to the farthest corner of the image
  for (const double u : {-0.5, k.width() - 0.5}) {
    for (const double v : {-0.5, k.height() - 0.5}) {
      farthest = std::max(farthest, std::hypot(u - k.cx(), v - k.cy()));
    }
  }
  // Each pixel alone (an iterative undistortion for cos^4: a renderer's start), in chunks of
  // rows on every core.
  internal::ForEachRowChunk(k.height(), [&](int, int first, int end) {
    for (int y = first; y < end; ++y) {
      float* row = reinterpret_cast<float*>(factors.row(y));
      for (int x = 0; x < k.width(); ++x) {
        double factor = 1.0;
        if (options.model == VignettingModel::kCos4) {
          const std::optional<Eigen::Vector3d> ray = camera.Unproject(Eigen::Vector2d(x, y));
          const double cos_theta = ray ? std::max(0.0, ray->z() / ray->norm()) : 0.0;
          factor = std::pow(cos_theta, 4);
        } else if (options.model == VignettingModel::kPolynomial) {
          factor = options.Polynomial(std::hypot(x - k.cx(), y - k.cy()) / farthest);
        }
        row[x] = static_cast<float>(factor);
      }
    }
  });
  return factors;
}

void ApplyVignetting(Image& rgb, const Image& factors) { ApplyVignetting(rgb, factors, true); }

void ApplyVignetting(Image& rgb, const Image& factors, bool simd) {
  if (rgb.format() != PixelFormat::kRgb8 || factors.format() != PixelFormat::kFloat32) {
    throw InvalidArgument(
        fmt::format("ApplyVignetting: formats {} and {}, expected rgb8 and float32 factors",
                    ToString(rgb.format()), ToString(factors.format())));
  }
  if (rgb.width() != factors.width() || rgb.height() != factors.height()) {
    throw InvalidArgument(
        fmt::format("ApplyVignetting: a {} x {} image with {} x {} factors, expected the same size",
                    rgb.width(), rgb.height(), factors.width(), factors.height()));
  }
#if defined(__x86_64__)
  static const bool avx2 = __builtin_cpu_supports("avx2");  // asked once
  const bool vectors = avx2 && simd;
#else
  static_cast<void>(simd);
  const bool vectors = false;
#endif
  // Each row alone, in chunks on every core.
  internal::ForEachRowChunk(rgb.height(), [&](int, int first, int end) {
    for (int y = first; y < end; ++y) {
      uint8_t* row = rgb.row(y);
      const float* f = reinterpret_cast<const float*>(factors.row(y));
      int x = 0;
#if defined(__x86_64__)
      if (vectors) x = VignetteRowAvx2(row, f, rgb.width());
#endif
      VignetteRow(row, f, x, rgb.width());
    }
  });
}

void ThinLensOptions::Validate() const {
  CheckLensPositive(focal_length_m, "thin_lens.focal_length_m");
  CheckLensPositive(f_number, "thin_lens.f_number");
  if (!std::isfinite(focus_distance_m) || focus_distance_m <= focal_length_m) {
    throw InvalidArgument(fmt::format(
        "thin_lens.focus_distance_m: expected a finite distance beyond the focal length ({} m), "
        "got {}",
        focal_length_m, focus_distance_m));
  }
  if (!std::isfinite(pixel_pitch_m) || pixel_pitch_m < 0.0) {
    throw InvalidArgument(
        fmt::format("thin_lens.pixel_pitch_m: expected a finite number >= 0 (0: from K), got {}",
                    pixel_pitch_m));
  }
  if (!std::isfinite(max_coc_px) || max_coc_px < 1.0) {
    throw InvalidArgument(
        fmt::format("thin_lens.max_coc_px: expected a finite number >= 1, got {}", max_coc_px));
  }
}

double CircleOfConfusion(const ThinLensOptions& lens, double depth_m) {
  const double f = lens.focal_length_m, s = lens.focus_distance_m;
  const double aperture = f / lens.f_number;
  const double at_infinity = aperture * f / (s - f);
  if (!(depth_m > 0.0) || std::isinf(depth_m)) return at_infinity;
  return at_infinity * std::abs(depth_m - s) / depth_m;
}

double CircleOfConfusionPx(const ThinLensOptions& lens, const geometry::Intrinsics& intrinsics,
                           double depth_m) {
  const double pitch =
      lens.pixel_pitch_m > 0.0 ? lens.pixel_pitch_m : lens.focal_length_m / intrinsics.fx();
  // The circle at infinity in pixels, then scaled by the depth (one division a pixel in
  // ApplyDepthOfField's loops, which compute it in this order).
  const double at_infinity_px = CircleOfConfusion(lens, 0.0) / pitch;
  if (!(depth_m > 0.0) || std::isinf(depth_m)) return at_infinity_px;
  return at_infinity_px * std::abs(depth_m - lens.focus_distance_m) / depth_m;
}

Image ApplyDepthOfField(const ImageView& rgb, const ImageView& depth, const ThinLensOptions& lens,
                        const geometry::Intrinsics& intrinsics, DepthOfFieldSummary* summary) {
  return ApplyDepthOfField(rgb, depth, lens, intrinsics, summary, kDofMaxLanes);
}

Image ApplyDepthOfFieldToMosaic(const ImageView& rgb, const ImageView& depth,
                                const ThinLensOptions& lens, const geometry::Intrinsics& intrinsics,
                                CfaPattern pattern, DepthOfFieldSummary* summary) {
  if (pattern == CfaPattern::kNone) {
    throw InvalidArgument("ApplyDepthOfFieldToMosaic: pattern none, expected a Bayer pattern");
  }
  return ApplyDepthOfField(rgb, depth, lens, intrinsics, summary, kDofMaxLanes, pattern);
}

int DepthOfFieldLanes(int max_lanes) {
#if defined(__x86_64__)
  static const bool avx2 = __builtin_cpu_supports("avx2");  // asked once
  static const bool avx512 =
      __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
      __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl");
  if (max_lanes >= 16 && avx512) return 16;
  if (max_lanes >= 8 && avx2) return 8;
#else
  static_cast<void>(max_lanes);
#endif
  return 4;
}

Image ApplyDepthOfField(const ImageView& rgb, const ImageView& depth, const ThinLensOptions& lens,
                        const geometry::Intrinsics& intrinsics, DepthOfFieldSummary* summary,
                        int max_lanes, CfaPattern pattern) {
  lens.Validate();
  if (rgb.format() != PixelFormat::kRgb8 || depth.format() != PixelFormat::kFloat32) {
    throw InvalidArgument(fmt::format(
        "ApplyDepthOfField: formats {} and {}, expected an rgb8 image and its float32 depth",
        ToString(rgb.format()), ToString(depth.format())));
  }
  if (rgb.width() != depth.width() || rgb.height() != depth.height()) {
    throw InvalidArgument(fmt::format(
        "ApplyDepthOfField: a {} x {} image with a {} x {} depth, expected the same size",
        rgb.width(), rgb.height(), depth.width(), depth.height()));
  }
  DepthOfFieldSummary local;
  DepthOfFieldSummary* out_summary = summary != nullptr ? summary : &local;
  *out_summary = {};
  const int lanes = DepthOfFieldLanes(max_lanes);
  const DofPlanes planes = PrepareDof(rgb, depth, lens, intrinsics, lanes >= 8, out_summary);
  // RGB, or the mosaic's cell (CfaChannel of its 2 x 2 pixels, row by row).
  const bool mosaic = pattern != CfaPattern::kNone;
  const std::array<int, 4> cell = {CfaChannel(pattern, 0, 0), CfaChannel(pattern, 1, 0),
                                   CfaChannel(pattern, 0, 1), CfaChannel(pattern, 1, 1)};
  Image out(rgb.width(), rgb.height(), mosaic ? BayerFormat(pattern, 8) : PixelFormat::kRgb8);
  if (rgb.metadata() != nullptr) out.metadata() = *rgb.metadata();
  const int* cell_or_rgb = mosaic ? cell.data() : nullptr;
  ShareDofRows(rgb.height(), [&](int, int first, int end) {
#if defined(__x86_64__)
    if (lanes == 16) {
      DofRowsAvx512(planes, cell_or_rgb, first, end, &out);
      return;
    }
    if (lanes == 8) {
      DofRowsAvx2(planes, cell_or_rgb, first, end, &out);
      return;
    }
#endif
    DofRowsPortable(planes, cell_or_rgb, first, end, &out);
  });
  return out;
}

}  // namespace saccade::render
