#include "saccade/render/color_filter.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <string>
#include <utility>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "render/internal_chunks.h"
#include "saccade/core/error.h"

namespace saccade::render {

namespace {

std::string LowerCaseColorName(std::string_view text) {
  std::string out(text);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

// The colours of a pattern's 2 x 2 cell, row by row (0 red, 1 green, 2 blue).
std::array<int, 4> CellOf(CfaPattern pattern) {
  switch (pattern) {
    case CfaPattern::kRggb:
      return {0, 1, 1, 2};
    case CfaPattern::kBggr:
      return {2, 1, 1, 0};
    case CfaPattern::kGrbg:
      return {1, 0, 2, 1};
    case CfaPattern::kGbrg:
      return {1, 2, 0, 1};
    case CfaPattern::kNone:
      break;
  }
  return {-1, -1, -1, -1};
}

void CheckWhiteBalanceGain(double gain, const char* field) {
  if (!std::isfinite(gain) || gain <= 0.0) {
    throw InvalidArgument(fmt::format("{}: expected a finite gain > 0, got {}", field, gain));
  }
}

// The three rows around an interior row y of a mosaic and the colours of its pixels, by the
// parity of x: own[q] at (x, y), across[q] at (x +- 1, y), below[q] at (x, y +- 1).
struct MosaicRows {
  const uint8_t* up;
  const uint8_t* mid;
  const uint8_t* down;
  int own[2], across[2], below[2];

  MosaicRows(const ImageView& in, const std::array<int, 4>& cell, int y)
      : up(in.row(y - 1)), mid(in.row(y)), down(in.row(y + 1)) {
    for (int q = 0; q < 2; ++q) {
      own[q] = cell[(y & 1) * 2 + q];
      across[q] = cell[(y & 1) * 2 + (q ^ 1)];
      below[q] = cell[((y + 1) & 1) * 2 + q];
    }
  }
};

// One interior pixel x of cv::demosaicing's bilinear code (demosaicing.cpp, Bayer2RGB_): the
// pixel's own colour as it is, a missing colour of two neighbours (a + b + 1) >> 1, of four
// (a + b + c + d + 2) >> 2. `m`'s row pointers read the neighbours directly.
inline void BilinearPixel(const MosaicRows& m, int x, uint8_t* rgb) {
  const int q = x & 1, own = m.own[q];
  const int left = m.mid[x - 1], right = m.mid[x + 1], up = m.up[x], down = m.down[x];
  rgb[own] = m.mid[x];
  if (own == 1) {
    rgb[m.across[q]] = static_cast<uint8_t>((left + right + 1) >> 1);
    rgb[m.below[q]] = static_cast<uint8_t>((up + down + 1) >> 1);
    return;
  }
  const int diagonal = m.up[x - 1] + m.up[x + 1] + m.down[x - 1] + m.down[x + 1];
  rgb[1] = static_cast<uint8_t>((left + right + up + down + 2) >> 2);
  rgb[2 - own] = static_cast<uint8_t>((diagonal + 2) >> 2);
}

// One interior pixel of cv::demosaicing's edge-aware code (Bayer2RGB_EdgeAware_T): rounded
// as the bilinear code, but green at a red or blue pixel from one pair only, the pair across
// the smaller difference (the vertical pair when the horizontal difference is larger).
inline void EdgeAwarePixel(const MosaicRows& m, int x, uint8_t* rgb) {
  const int q = x & 1, own = m.own[q];
  const int left = m.mid[x - 1], right = m.mid[x + 1], up = m.up[x], down = m.down[x];
  rgb[own] = m.mid[x];
  if (own == 1) {
    rgb[m.across[q]] = static_cast<uint8_t>((left + right + 1) >> 1);
    rgb[m.below[q]] = static_cast<uint8_t>((up + down + 1) >> 1);
    return;
  }
  const bool vertical = std::abs(left - right) > std::abs(down - up);
  rgb[1] = static_cast<uint8_t>(((vertical ? down + up : left + right) + 1) >> 1);
  const int diagonal = m.up[x - 1] + m.up[x + 1] + m.down[x - 1] + m.down[x + 1];
  rgb[2 - own] = static_cast<uint8_t>((diagonal + 2) >> 2);
}

#if defined(__x86_64__)
// The byte shuffles that interleave three planes of 16 values (R, G, B) into 48 bytes of RGB:
// kInterleave[k][c] puts plane c's bytes where they go in the k-th 16 bytes (0x80: none).
struct InterleaveMasks {
  alignas(16) uint8_t bytes[3][3][16];
  constexpr InterleaveMasks() : bytes{} {
    for (int k = 0; k < 3; ++k) {
      for (int c = 0; c < 3; ++c) {
        for (int j = 0; j < 16; ++j) {
          const int at = 16 * k + j;
          bytes[k][c][j] = at % 3 == c ? static_cast<uint8_t>(at / 3) : 0x80;
        }
      }
    }
  }
};
constexpr InterleaveMasks kInterleave;

// (a + b + c + d + 2) >> 2 of 16 bytes each, in 16 bits.
__attribute__((target("sse4.1"))) inline __m128i Mean4(__m128i a, __m128i b, __m128i c, __m128i d) {
  const __m128i zero = _mm_setzero_si128(), two = _mm_set1_epi16(2);
  const auto sum = [&](auto unpack) {
    const __m128i s = _mm_add_epi16(_mm_add_epi16(unpack(a, zero), unpack(b, zero)),
                                    _mm_add_epi16(unpack(c, zero), unpack(d, zero)));
    return _mm_srli_epi16(_mm_add_epi16(s, two), 2);
  };
  return _mm_packus_epi16(sum([](__m128i x, __m128i z) { return _mm_unpacklo_epi8(x, z); }),
                          sum([](__m128i x, __m128i z) { return _mm_unpackhi_epi8(x, z); }));
}

// Row `m`'s interior pixels 16 at a time from x = 1 with SSE4.1, as BilinearPixel or
// EdgeAwarePixel would give them: the same integer arithmetic (pavgb is (a + b + 1) >> 1, the
// four-term means in 16 bits, |a - b| by saturating differences), each colour's plane chosen
// by the pixel's parity, interleaved into RGB by byte shuffles. Returns the first x not done
// (the caller does the rest pixel by pixel).
__attribute__((target("sse4.1"))) int DemosaicRowSse41(const MosaicRows& m, int w, bool edge_aware,
                                                       uint8_t* row) {
  // The value each colour takes at parity q: 0 the own sample, 1 the pair across, 2 the pair
  // below, 3 green at a red or blue pixel, 4 the four diagonals (BilinearPixel's cases).
  int source[3][2];
  for (int q = 0; q < 2; ++q) {
    if (m.own[q] == 1) {
      source[1][q] = 0;
      source[m.across[q]][q] = 1;
      source[m.below[q]][q] = 2;
    } else {
      source[m.own[q]][q] = 0;
      source[1][q] = 3;
      source[2 - m.own[q]][q] = 4;
    }
  }
  // x = 1, 17, ...: lane i holds x odd where i is even.
  const __m128i odd = _mm_set1_epi16(0x00FF);
  const __m128i flip = _mm_set1_epi8(static_cast<char>(0x80));
  const auto load = [](const uint8_t* p) {
    return _mm_loadu_si128(reinterpret_cast<const __m128i*>(p));
  };
  int x = 1;
  for (; x + 17 <= w; x += 16) {
    const __m128i left = load(m.mid + x - 1), right = load(m.mid + x + 1);
    const __m128i up = load(m.up + x), down = load(m.down + x);
    __m128i value[5];
    value[0] = load(m.mid + x);
    value[1] = _mm_avg_epu8(left, right);
    value[2] = _mm_avg_epu8(up, down);
    if (edge_aware) {
      // |left - right| > |down - up|, unsigned: compared with their top bits flipped.
      const __m128i across = _mm_or_si128(_mm_subs_epu8(left, right), _mm_subs_epu8(right, left));
      const __m128i along = _mm_or_si128(_mm_subs_epu8(down, up), _mm_subs_epu8(up, down));
      const __m128i vertical =
          _mm_cmpgt_epi8(_mm_xor_si128(across, flip), _mm_xor_si128(along, flip));
      value[3] = _mm_blendv_epi8(value[1], value[2], vertical);
    } else {
      value[3] = Mean4(left, right, up, down);
    }
    value[4] =
        Mean4(load(m.up + x - 1), load(m.up + x + 1), load(m.down + x - 1), load(m.down + x + 1));
    __m128i plane[3];
    for (int c = 0; c < 3; ++c) {
      plane[c] = _mm_blendv_epi8(value[source[c][0]], value[source[c][1]], odd);
    }
    uint8_t* out = row + 3 * x;
    for (int k = 0; k < 3; ++k) {
      const auto mask = [&](int c) {
        return _mm_load_si128(reinterpret_cast<const __m128i*>(kInterleave.bytes[k][c]));
      };
      const __m128i bytes = _mm_or_si128(
          _mm_or_si128(_mm_shuffle_epi8(plane[0], mask(0)), _mm_shuffle_epi8(plane[1], mask(1))),
          _mm_shuffle_epi8(plane[2], mask(2)));
      _mm_storeu_si128(reinterpret_cast<__m128i*>(out + 16 * k), bytes);
    }
  }
  return x;
}
#endif

// OpenCV's borders: the first and last columns of the interior rows copied from their
// neighbours, then the first and last rows from theirs.
void CopyBorders(Image& out) {
  const int w = out.width(), h = out.height();
  for (int y = 1; y < h - 1; ++y) {
    uint8_t* row = out.row(y);
    std::copy(row + 3, row + 6, row);
    std::copy(row + 3 * (w - 2), row + 3 * (w - 1), row + 3 * (w - 1));
  }
  std::copy(out.row(1), out.row(1) + out.stride(), out.row(0));
  std::copy(out.row(h - 2), out.row(h - 2) + out.stride(), out.row(h - 1));
}

}  // namespace

const char* ToString(CfaPattern pattern) {
  switch (pattern) {
    case CfaPattern::kNone:
      return "none";
    case CfaPattern::kRggb:
      return "rggb";
    case CfaPattern::kBggr:
      return "bggr";
    case CfaPattern::kGrbg:
      return "grbg";
    case CfaPattern::kGbrg:
      return "gbrg";
  }
  return "unknown";
}

CfaPattern ParseCfaPattern(std::string_view text, std::string_view field) {
  std::string name = LowerCaseColorName(text);
  for (const char* suffix : {"8", "16"}) {
    const std::string prefix = "bayer_";
    if (name.starts_with(prefix) && name.ends_with(suffix) &&
        name.size() == prefix.size() + 4 + std::string_view(suffix).size()) {
      name = name.substr(prefix.size(), 4);
    }
  }
  for (CfaPattern p : {CfaPattern::kNone, CfaPattern::kRggb, CfaPattern::kBggr, CfaPattern::kGrbg,
                       CfaPattern::kGbrg}) {
    if (name == ToString(p)) return p;
  }
  throw InvalidArgument(fmt::format(
      "{}: unknown colour filter pattern '{}', expected none, rggb, bggr, grbg, gbrg or a ROS "
      "Bayer encoding (bayer_rggb8, bayer_bggr16, ...)",
      field, text));
}

PixelFormat BayerFormat(CfaPattern pattern, int bits) {
  if (bits != 8 && bits != 16) {
    throw InvalidArgument(fmt::format("BayerFormat: bits: expected 8 or 16, got {}", bits));
  }
  const bool wide = bits == 16;
  switch (pattern) {
    case CfaPattern::kRggb:
      return wide ? PixelFormat::kBayerRggb16 : PixelFormat::kBayerRggb8;
    case CfaPattern::kBggr:
      return wide ? PixelFormat::kBayerBggr16 : PixelFormat::kBayerBggr8;
    case CfaPattern::kGrbg:
      return wide ? PixelFormat::kBayerGrbg16 : PixelFormat::kBayerGrbg8;
    case CfaPattern::kGbrg:
      return wide ? PixelFormat::kBayerGbrg16 : PixelFormat::kBayerGbrg8;
    case CfaPattern::kNone:
      break;
  }
  throw InvalidArgument(
      "BayerFormat: pattern: 'none' has no mosaic, expected rggb, bggr, grbg "
      "or gbrg");
}

CfaPattern PatternOf(PixelFormat format) {
  switch (format) {
    case PixelFormat::kBayerRggb8:
    case PixelFormat::kBayerRggb16:
      return CfaPattern::kRggb;
    case PixelFormat::kBayerBggr8:
    case PixelFormat::kBayerBggr16:
      return CfaPattern::kBggr;
    case PixelFormat::kBayerGrbg8:
    case PixelFormat::kBayerGrbg16:
      return CfaPattern::kGrbg;
    case PixelFormat::kBayerGbrg8:
    case PixelFormat::kBayerGbrg16:
      return CfaPattern::kGbrg;
    default:
      return CfaPattern::kNone;
  }
}

int CfaChannel(CfaPattern pattern, int x, int y) { return CellOf(pattern)[(y & 1) * 2 + (x & 1)]; }

const char* OpenCVBayerCodeName(CfaPattern pattern) {
  // OpenCV names a code by the cell at (1, 1): one step along the diagonal.
  switch (pattern) {
    case CfaPattern::kRggb:
      return "COLOR_BayerBG2RGB";
    case CfaPattern::kBggr:
      return "COLOR_BayerRG2RGB";
    case CfaPattern::kGrbg:
      return "COLOR_BayerGB2RGB";
    case CfaPattern::kGbrg:
      return "COLOR_BayerGR2RGB";
    case CfaPattern::kNone:
      break;
  }
  return "";
}

const char* ToString(DemosaicMethod method) {
  return method == DemosaicMethod::kEdgeAware ? "edge_aware" : "bilinear";
}

DemosaicMethod ParseDemosaicMethod(std::string_view text, std::string_view field) {
  const std::string name = LowerCaseColorName(text);
  if (name == "bilinear") return DemosaicMethod::kBilinear;
  if (name == "edge_aware" || name == "ea") return DemosaicMethod::kEdgeAware;
  throw InvalidArgument(fmt::format(
      "{}: unknown demosaicing method '{}', expected bilinear or edge_aware", field, text));
}

Image Mosaic(const ImageView& rgb, CfaPattern pattern) {
  if (rgb.format() != PixelFormat::kRgb8) {
    throw InvalidArgument(
        fmt::format("Mosaic: image format {}, expected rgb8", ToString(rgb.format())));
  }
  Image out(rgb.width(), rgb.height(), BayerFormat(pattern, 8));
  const std::array<int, 4> cell = CellOf(pattern);
  internal::ForEachRowChunk(rgb.height(), [&](int, int first, int end) {
    // The width and the row's two channels in locals: a byte store may alias anything, which
    // made the compiler reload them at every pixel.
    const int w = rgb.width();
    for (int y = first; y < end; ++y) {
      const uint8_t* in = rgb.row(y);
      uint8_t* row = out.row(y);
      const int even = cell[(y & 1) * 2], odd = cell[(y & 1) * 2 + 1];
      int x = 0;
      for (; x + 1 < w; x += 2) {
        row[x] = in[3 * x + even];
        row[x + 1] = in[3 * x + 3 + odd];
      }
      if (x < w) row[x] = in[3 * x + even];
    }
  });
  if (rgb.metadata() != nullptr) out.metadata() = *rgb.metadata();
  return out;
}

namespace {

#if defined(__x86_64__)
// ToneBytes' bytes 64 at a time where the CPU has AVX-512 VBMI: two 128-entry byte
// permutations of the table (each index's low 7 bits), the index's top bit choosing between
// them. Returns the first byte left.
__attribute__((target("avx512f,avx512bw,avx512vbmi"))) uint8_t* ToneBytesVbmi(
    uint8_t* p, uint8_t* end, const std::array<uint8_t, 256>& table) {
  const __m512i t0 = _mm512_loadu_si512(table.data()), t1 = _mm512_loadu_si512(table.data() + 64);
  const __m512i t2 = _mm512_loadu_si512(table.data() + 128),
                t3 = _mm512_loadu_si512(table.data() + 192);
  for (; p + 64 <= end; p += 64) {
    const __m512i v = _mm512_loadu_si512(p);
    const __m512i low = _mm512_permutex2var_epi8(t0, v, t1);   // entries 0 to 127
    const __m512i high = _mm512_permutex2var_epi8(t2, v, t3);  // entries 128 to 255
    _mm512_storeu_si512(p, _mm512_mask_blend_epi8(_mm512_movepi8_mask(v), low, high));
  }
  return p;
}
#endif

// Bytes [p, end) through `table` in place, 64 at a time with AVX-512 VBMI, else 8 at a time.
// The table is the caller's local copy: a byte store may alias anything but it, so that nothing
// is reloaded value by value.
void ToneBytes(uint8_t* p, uint8_t* end, const std::array<uint8_t, 256>& table) {
#if defined(__x86_64__)
  static const bool vbmi =
      __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512vbmi");  // asked once
  if (vbmi) p = ToneBytesVbmi(p, end, table);
#endif
  for (; p + 8 <= end; p += 8) {
    uint64_t in;
    std::memcpy(&in, p, 8);
    uint64_t out = 0;
    for (int k = 0; k < 8; ++k) out |= uint64_t{table[(in >> (8 * k)) & 0xff]} << (8 * k);
    std::memcpy(p, &out, 8);
  }
  for (; p < end; ++p) *p = table[*p];
}

// Demosaic's image; with `tone`, each value then looked up in it (a tone curve's table, the
// same for the three colours), row by row while the row is in the cache.
Image DemosaicThroughTable(const ImageView& mosaic, DemosaicMethod method,
                           const std::array<uint8_t, 256>* tone) {
  const CfaPattern pattern = PatternOf(mosaic.format());
  if (pattern == CfaPattern::kNone || BytesPerPixel(mosaic.format()) != 1) {
    throw InvalidArgument(fmt::format(
        "Demosaic: image format {}, expected an 8-bit Bayer mosaic (bayer_rggb8, bayer_bggr8, "
        "bayer_grbg8 or bayer_gbrg8)",
        ToString(mosaic.format())));
  }
  Image out(mosaic.width(), mosaic.height(), PixelFormat::kRgb8);
  if (mosaic.metadata() != nullptr) out.metadata() = *mosaic.metadata();
  const int w = mosaic.width(), h = mosaic.height();
  // Black, as OpenCV leaves it (every tone curve keeps 0 at 0).
  if (w < 3 || h < 3) return out;
  const std::array<int, 4> cell = CellOf(pattern);
#if defined(__x86_64__)
  static const bool sse41 = __builtin_cpu_supports("sse4.1");  // asked once
#endif
  // Rows 1 to h - 2, each alone, in chunks on every core.
  internal::ForEachRowChunk(h - 2, [&](int, int first, int end) {
    std::array<uint8_t, 256> table{};  // the chunk's own copy: no store of ToneBytes reaches it
    if (tone != nullptr) table = *tone;
    for (int y = first + 1; y < end + 1; ++y) {
      const MosaicRows rows(mosaic, cell, y);
      uint8_t* row = out.row(y);
      int x = 1;
#if defined(__x86_64__)
      if (sse41) x = DemosaicRowSse41(rows, w, method == DemosaicMethod::kEdgeAware, row);
#endif
      if (method == DemosaicMethod::kBilinear) {
        for (; x < w - 1; ++x) BilinearPixel(rows, x, row + 3 * x);
      } else {
        for (; x < w - 1; ++x) EdgeAwarePixel(rows, x, row + 3 * x);
      }
      if (tone != nullptr) ToneBytes(row + 3, row + 3 * (w - 1), table);
    }
  });
  CopyBorders(out);  // copies of toned values: toned as the pixels they copy
  return out;
}

}  // namespace

Image Demosaic(const ImageView& mosaic, DemosaicMethod method) {
  return DemosaicThroughTable(mosaic, method, nullptr);
}

void WhiteBalance::Validate() const {
  CheckWhiteBalanceGain(red, "white_balance.red");
  CheckWhiteBalanceGain(green, "white_balance.green");
  CheckWhiteBalanceGain(blue, "white_balance.blue");
}

const char* ToString(ToneCurveKind kind) {
  switch (kind) {
    case ToneCurveKind::kLinear:
      return "linear";
    case ToneCurveKind::kGamma:
      return "gamma";
    case ToneCurveKind::kSrgb:
      return "srgb";
  }
  return "unknown";
}

ToneCurveKind ParseToneCurveKind(std::string_view text, std::string_view field) {
  const std::string name = LowerCaseColorName(text);
  for (ToneCurveKind k : {ToneCurveKind::kLinear, ToneCurveKind::kGamma, ToneCurveKind::kSrgb}) {
    if (name == ToString(k)) return k;
  }
  throw InvalidArgument(
      fmt::format("{}: unknown tone curve '{}', expected linear, gamma or srgb", field, text));
}

void ToneCurve::Validate() const {
  if (kind == ToneCurveKind::kGamma && (!std::isfinite(gamma) || gamma <= 0.0)) {
    throw InvalidArgument(
        fmt::format("tone_curve.gamma: expected a finite number > 0, got {}", gamma));
  }
}

double ToneCurve::Encode(double linear) const {
  const double l = std::clamp(linear, 0.0, 1.0);
  switch (kind) {
    case ToneCurveKind::kLinear:
      return l;
    case ToneCurveKind::kGamma:
      return std::pow(l, 1.0 / gamma);
    case ToneCurveKind::kSrgb:
      // IEC 61966-2-1:1999, the encoding (inverse) transfer function.
      return l <= 0.0031308 ? 12.92 * l : 1.055 * std::pow(l, 1.0 / 2.4) - 0.055;
  }
  return l;
}

std::array<uint8_t, 256> ToneTable(const ToneCurve& curve, double gain) {
  curve.Validate();
  CheckWhiteBalanceGain(gain, "ToneTable: gain");
  std::array<uint8_t, 256> table{};
  for (int v = 0; v < 256; ++v) {
    const double encoded = curve.Encode(std::min(1.0, gain * v / 255.0));
    table[v] = static_cast<uint8_t>(std::lround(std::clamp(encoded, 0.0, 1.0) * 255.0));
  }
  return table;
}

void ApplyWhiteBalanceAndTone(Image& rgb, const WhiteBalance& balance, const ToneCurve& curve) {
  if (rgb.format() != PixelFormat::kRgb8) {
    throw InvalidArgument(fmt::format("ApplyWhiteBalanceAndTone: image format {}, expected rgb8",
                                      ToString(rgb.format())));
  }
  balance.Validate();
  const std::array<std::array<uint8_t, 256>, 3> tables = {ToneTable(curve, balance.red),
                                                          ToneTable(curve, balance.green),
                                                          ToneTable(curve, balance.blue)};
  uint8_t* p = rgb.data();
  const std::size_t pixels = static_cast<std::size_t>(rgb.width()) * rgb.height();
  for (std::size_t i = 0; i < pixels; ++i, p += 3) {
    p[0] = tables[0][p[0]];
    p[1] = tables[1][p[1]];
    p[2] = tables[2][p[2]];
  }
}

void ApplyWhiteBalanceToMosaic(Image& mosaic, const WhiteBalance& balance) {
  const CfaPattern pattern = PatternOf(mosaic.format());
  if (pattern == CfaPattern::kNone || BytesPerPixel(mosaic.format()) != 1) {
    throw InvalidArgument(
        fmt::format("ApplyWhiteBalanceToMosaic: image format {}, expected an 8-bit Bayer mosaic",
                    ToString(mosaic.format())));
  }
  balance.Validate();
  if (balance.red == 1.0 && balance.green == 1.0 && balance.blue == 1.0) return;  // the identity
  const ToneCurve linear;
  const std::array<std::array<uint8_t, 256>, 3> tables = {ToneTable(linear, balance.red),
                                                          ToneTable(linear, balance.green),
                                                          ToneTable(linear, balance.blue)};
  const std::array<int, 4> cell = CellOf(pattern);
  for (int y = 0; y < mosaic.height(); ++y) {
    uint8_t* row = mosaic.row(y);
    for (int x = 0; x < mosaic.width(); ++x) {
      row[x] = tables[cell[(y & 1) * 2 + (x & 1)]][row[x]];
    }
  }
}

void ColorOptions::Validate() const {
  white_balance.Validate();
  tone_curve.Validate();
}

ColorImages ApplyColorPipeline(const ImageView& linear_rgb, const ColorOptions& options) {
  options.Validate();
  if (linear_rgb.format() != PixelFormat::kRgb8) {
    throw InvalidArgument(fmt::format("ApplyColorPipeline: image format {}, expected rgb8",
                                      ToString(linear_rgb.format())));
  }
  ColorImages out;
  if (options.cfa == CfaPattern::kNone) {
    out.rgb = Image(linear_rgb.width(), linear_rgb.height(), PixelFormat::kRgb8, linear_rgb.data(),
                    linear_rgb.stride());
    if (linear_rgb.metadata() != nullptr) out.rgb.metadata() = *linear_rgb.metadata();
    ApplyWhiteBalanceAndTone(out.rgb, options.white_balance, options.tone_curve);
    return out;
  }
  return ApplyColorPipelineToMosaic(Mosaic(linear_rgb, options.cfa), options);
}

ColorImages ApplyColorPipelineToMosaic(Image mosaic, const ColorOptions& options) {
  options.Validate();
  if (options.cfa == CfaPattern::kNone || PatternOf(mosaic.format()) != options.cfa ||
      BytesPerPixel(mosaic.format()) != 1) {
    throw InvalidArgument(fmt::format(
        "ApplyColorPipelineToMosaic: a {} mosaic with the colour filter '{}', expected {}",
        ToString(mosaic.format()), ToString(options.cfa),
        options.cfa == CfaPattern::kNone ? "a filter array" : ToString(BayerFormat(options.cfa))));
  }
  ColorImages out;
  out.raw = std::move(mosaic);
  ApplyWhiteBalanceToMosaic(out.raw, options.white_balance);
  // Demosaiced, then the tone curve (ApplyWhiteBalanceAndTone without a balance: one table).
  const std::array<uint8_t, 256> tone = ToneTable(options.tone_curve, 1.0);
  out.rgb = DemosaicThroughTable(out.raw.view(), options.demosaic, &tone);
  return out;
}

}  // namespace saccade::render
