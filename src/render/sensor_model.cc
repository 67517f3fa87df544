#include "saccade/render/sensor_model.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <numbers>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "render/internal_chunks.h"
#include "render/internal_sensor_model.h"
#include "saccade/core/error.h"

namespace saccade::render {
namespace {

// The most values one sensor holds (two float maps of this size: 2 GiB).
constexpr int64_t kMaxSensorValues = int64_t{1} << 28;
// Values a chunk of a frame's exposure takes (ForParts): some 0.1 ms on one thread.
constexpr std::size_t kSensorChunkValues = std::size_t{1} << 15;
// Streams of the counter-based generator: fixed pattern (PRNU, DSNU) and per frame.
constexpr uint64_t kPrnuStream = 0x5052'4e55'0000'0001ULL;
constexpr uint64_t kDsnuStream = 0x4453'4e55'0000'0002ULL;
constexpr uint64_t kFrameStream = 0x4652'414d'0000'0003ULL;

// SplitMix64's finaliser: a bijective 64-bit mix.
uint64_t SensorMix(uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// A uniform in (0, 1) from 32 bits.
double SensorUniform(uint32_t bits) { return (static_cast<double>(bits) + 0.5) * 0x1p-32; }

// The standard normal quantile (Acklam's rational approximation: relative error below
// 1.15e-9 over (0, 1)).
double NormalQuantile(double p) {
  constexpr double a[] = {-3.969683028665376e+01, 2.209460984245205e+02,  -2.759285104469687e+02,
                          1.383577518672690e+02,  -3.066479806614716e+01, 2.506628277459239e+00};
  constexpr double b[] = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
                          6.680131188771972e+01, -1.328068155288572e+01};
  constexpr double c[] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                          -2.549732539343734e+00, 4.374664141464968e+00,  2.938163982698783e+00};
  constexpr double d[] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                          3.754408661907416e+00};
  constexpr double kLow = 0.02425;
  const auto tail = [&](double q) {  // q = min(p, 1 - p) < kLow: the lower tail's value
    const double r = std::sqrt(-2.0 * std::log(q));
    return (((((c[0] * r + c[1]) * r + c[2]) * r + c[3]) * r + c[4]) * r + c[5]) /
           ((((d[0] * r + d[1]) * r + d[2]) * r + d[3]) * r + 1.0);
  };
  if (p < kLow) return tail(p);
  if (p > 1.0 - kLow) return -tail(1.0 - p);
  const double q = p - 0.5, r = q * q;
  return (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
         (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1.0);
}

// The quantile sampled at kGaussianBins + 1 evenly spaced probabilities (the ends unused).
constexpr int kGaussianBinBits = 12;
constexpr int kGaussianBins = 1 << kGaussianBinBits;

const std::vector<double>& GaussianTable() {
  static const std::vector<double> table = [] {
    std::vector<double> t(kGaussianBins + 1, 0.0);
    for (int i = 1; i < kGaussianBins; ++i) {
      t[i] = NormalQuantile(static_cast<double>(i) / kGaussianBins);
    }
    return t;
  }();
  return table;
}

// GaussianTable as pairs (t[i], t[i + 1] - t[i]), i < kGaussianBins: SensorGaussian's two
// terms with one 16-byte load (ExposeRunAvx2).
const std::vector<double>& GaussianPairs() {
  static const std::vector<double> pairs = [] {
    const std::vector<double>& t = GaussianTable();
    std::vector<double> p(2 * kGaussianBins);
    for (int i = 0; i < kGaussianBins; ++i) {
      p[2 * i] = t[i];
      p[2 * i + 1] = t[i + 1] - t[i];
    }
    return p;
  }();
  return pairs;
}

// A standard normal deviate from 32 bits by inversion: the quantile interpolated linearly
// between kGaussianBins evenly spaced probabilities (its variance within 1e-6 of 1: the
// quantile is nearly straight over a bin), exact in the two outer bins (the tails, to
// +-6.3). A table look-up instead of Box-Muller's logarithm and cosine: 5 times as fast.
// `table`: GaussianTable()'s data (looked up once by the caller).
inline double SensorGaussian(const double* table, uint32_t bits) {
  const uint32_t bin = bits >> (32 - kGaussianBinBits);
  if (bin == 0 || bin == kGaussianBins - 1) [[unlikely]] {
    return NormalQuantile(SensorUniform(bits));
  }
  const double* t = table + bin;
  // The low bits as a fraction of the bin: 2^52 + the bits, by their bit pattern, less 2^52 (an
  // integer's conversion to double would wait on the register's previous value).
  const uint64_t low = bits & ((1u << (32 - kGaussianBinBits)) - 1);
  const double frac = (std::bit_cast<double>(0x4330'0000'0000'0000ULL | low) - 0x1p52 + 0.5) *
                      (1.0 / (1u << (32 - kGaussianBinBits)));
  return t[0] + frac * (t[1] - t[0]);
}

// x >= 0 rounded half up, as std::round, to an integer (without a call into libm).
int64_t RoundNonNegative(double x) { return static_cast<int64_t>(x + 0.5); }

// x in [0, 2^51) rounded to the nearest whole number, ties to even (std::round differs only at
// exact ties, which continuous deviates never are), in double arithmetic: without converting to
// an integer and back, whose conversion to double waits on the register's previous value (a
// dependency from one value to the next).
double RoundWhole(double x) {
  constexpr double kShift = 0x1.8p52;  // adding it leaves no fraction bits (IEEE arithmetic:
  return (x + kShift) - kShift;        // without -ffast-math the sum is not folded away)
}

// A Poisson deviate of mean `lambda` from 32 bits: inversion below kExactPoissonMean, the
// Gaussian approximation (rounded to whole electrons) above.
inline double SensorPoisson(const double* table, double lambda, uint32_t bits) {
  if (lambda <= 0.0) return 0.0;
  if (lambda >= kExactPoissonMean) [[likely]] {
    const double e = lambda + std::sqrt(lambda) * SensorGaussian(table, bits);
    return e > 0.0 ? RoundWhole(e) : 0.0;
  }
  const double u = SensorUniform(bits);
  double p = std::exp(-lambda);
  double cdf = p;
  double k = 0.0;
  const double last = lambda + 12.0 * std::sqrt(lambda) + 20.0;  // beyond: below 1e-30
  while (u > cdf && k < last) {
    k += 1.0;
    p *= lambda / k;
    cdf += p;
  }
  return k;
}

// One frame's terms (SensorModel::Expose), the same for every value.
struct FrameTerms {
  uint64_t key;  // the frame's hash key
  double K;      // DN per electron, the camera's gain included
  double sigma_d;
  double sat;
  double offset;
  double max_dn;
  double to8;  // 255 / max_dn: a raw DN's 8-bit value, before rounding (To8Bit)
  const double* table;
  const double* pairs;  // GaussianPairs()
  const float* prnu;
  const float* dsnu;
};

// Value i's raw DN from its mean electrons `lambda` (eta mu_p (1 + PRNU_i)).
inline uint16_t ExposeValue(const FrameTerms& t, std::size_t i, double lambda) {
  // One 64-bit hash a value: its upper half draws the shot noise, its lower the dark noise.
  const uint64_t h = SensorMix(t.key + static_cast<uint64_t>(i));
  double e = SensorPoisson(t.table, lambda, static_cast<uint32_t>(h >> 32));
  e += t.sigma_d * SensorGaussian(t.table, static_cast<uint32_t>(h)) + t.dsnu[i];
  e = std::min(e, t.sat);  // the full well
  // round() then clamp to [0, max_dn], as one clamp and a rounding of the non-negative.
  return static_cast<uint16_t>(RoundNonNegative(std::clamp(t.K * e + t.offset, 0.0, t.max_dn)));
}

// A raw DN's 8-bit value (To8Bit).
inline uint8_t To8(const FrameTerms& t, uint16_t raw) {
  return static_cast<uint8_t>(RoundNonNegative(static_cast<double>(raw) * t.to8));
}

// A frame's input, value j of a run: mean photons (Expose) ...
struct PhotonInput {
  const float* photons;
  double eta;
};
// ... or 8-bit rendered values through each value's eta mu_p (ExposeRendered).
struct RenderedInput {
  const uint8_t* values;
  const double* eta_photons;  // 256
};

// eta mu_p of value j, as Expose has always multiplied it (eta first, PRNU after).
inline double EtaPhotons(const PhotonInput& in, std::size_t j) {
  return in.eta * std::max(0.0f, in.photons[j]);
}
inline double EtaPhotons(const RenderedInput& in, std::size_t j) {
  return in.eta_photons[in.values[j]];
}

// The values [first, first + n) of a frame, value j of the run from `in`, into raw[j] and,
// where `out8` is not null, their 8-bit values into out8[j] (which may be the input's bytes:
// each is read before it is written). From value j0 on.
template <typename Input>
void ExposeRunPortable(const FrameTerms& t, const Input& in, std::size_t first, std::size_t n,
                       uint16_t* raw, uint8_t* out8, std::size_t j0 = 0) {
  for (std::size_t j = j0; j < n; ++j) {
    const std::size_t i = first + j;
    raw[j] = ExposeValue(t, i, EtaPhotons(in, j) * t.prnu[i]);
    if (out8 != nullptr) out8[j] = To8(t, raw[j]);
  }
}

// Values j + l of a run whose bit l of `lanes_mask` is set (l < lanes), from their mean electrons
// lambdas[l], as ExposeRunPortable exposes them: the vector kernels' lanes that take a rare path.
void RedoLanes(const FrameTerms& t, std::size_t first, std::size_t j, const double* lambdas,
               int lanes, unsigned lanes_mask, uint16_t* raw, uint8_t* out8) {
  for (int l = 0; l < lanes; ++l) {
    if ((lanes_mask >> l & 1) == 0) continue;
    const std::size_t at = j + static_cast<std::size_t>(l);
    raw[at] = ExposeValue(t, first + at, lambdas[l]);
    if (out8 != nullptr) out8[at] = To8(t, raw[at]);
  }
}

#if defined(__x86_64__)
// Groups of 4 values that ExposeRunAvx2 exposes at once.
constexpr int kAvx2Groups = 4;

// The low 64 bits of z * c in each lane, from 32 x 32-bit products (exact, as uint64_t's).
__attribute__((target("avx2"))) inline __m256i MulLow64(__m256i z, uint64_t c) {
  const __m256i c_low = _mm256_set1_epi64x(static_cast<int64_t>(c & 0xffff'ffffULL));
  const __m256i c_high = _mm256_set1_epi64x(static_cast<int64_t>(c >> 32));
  const __m256i cross = _mm256_add_epi64(_mm256_mul_epu32(_mm256_srli_epi64(z, 32), c_low),
                                         _mm256_mul_epu32(z, c_high));
  return _mm256_add_epi64(_mm256_mul_epu32(z, c_low), _mm256_slli_epi64(cross, 32));
}

// table[index] of 4 lanes (the masked gathers: GCC 12 warns of the plain ones' undefined source).
__attribute__((target("avx2"))) inline __m256d Gather4(const double* table, __m256i index) {
  const __m256d all = _mm256_castsi256_pd(_mm256_set1_epi64x(-1));
  return _mm256_mask_i64gather_pd(_mm256_setzero_pd(), table, index, all, 8);
}
__attribute__((target("avx2"))) inline __m256d Gather4(const double* table, __m128i index) {
  const __m256d all = _mm256_castsi256_pd(_mm256_set1_epi64x(-1));
  return _mm256_mask_i32gather_pd(_mm256_setzero_pd(), table, index, all, 8);
}

// SensorMix of 4 lanes.
__attribute__((target("avx2"))) inline __m256i SensorMix4(__m256i z) {
  z = _mm256_add_epi64(z, _mm256_set1_epi64x(static_cast<int64_t>(0x9e3779b97f4a7c15ULL)));
  z = MulLow64(_mm256_xor_si256(z, _mm256_srli_epi64(z, 30)), 0xbf58476d1ce4e5b9ULL);
  z = MulLow64(_mm256_xor_si256(z, _mm256_srli_epi64(z, 27)), 0x94d049bb133111ebULL);
  return _mm256_xor_si256(z, _mm256_srli_epi64(z, 31));
}

// SensorGaussian of 4 lanes' 32 bits (each 64-bit lane's low half, its high half 0) from
// GaussianPairs (`pairs`): each lane's pair with one load (4 loads and 2 shuffles instead of two
// gathers). ORs the lanes whose bin is an outer one (whose deviate SensorGaussian computes
// apart) into `*outer`.
__attribute__((target("avx2"))) inline __m256d SensorGaussian4(const double* pairs, __m256i bits,
                                                               __m256i* outer) {
  constexpr int kLowBits = 32 - kGaussianBinBits;
  const __m256i bin = _mm256_srli_epi64(bits, kLowBits);
  *outer = _mm256_or_si256(
      *outer, _mm256_or_si256(_mm256_cmpeq_epi64(bin, _mm256_setzero_si256()),
                              _mm256_cmpeq_epi64(bin, _mm256_set1_epi64x(kGaussianBins - 1))));
  const __m128i bins01 = _mm256_castsi256_si128(bin), bins23 = _mm256_extracti128_si256(bin, 1);
  const __m256d pairs02 = _mm256_insertf128_pd(
      _mm256_castpd128_pd256(_mm_loadu_pd(pairs + 2 * _mm_cvtsi128_si64(bins01))),
      _mm_loadu_pd(pairs + 2 * _mm_cvtsi128_si64(bins23)), 1);
  const __m256d pairs13 = _mm256_insertf128_pd(
      _mm256_castpd128_pd256(_mm_loadu_pd(pairs + 2 * _mm_extract_epi64(bins01, 1))),
      _mm_loadu_pd(pairs + 2 * _mm_extract_epi64(bins23, 1)), 1);
  const __m256d t0 = _mm256_unpacklo_pd(pairs02, pairs13);     // t[bin]
  const __m256d slope = _mm256_unpackhi_pd(pairs02, pairs13);  // t[bin + 1] - t[bin]
  const __m256i low = _mm256_and_si256(bits, _mm256_set1_epi64x((1 << kLowBits) - 1));
  const __m256d bias = _mm256_castsi256_pd(
      _mm256_or_si256(low, _mm256_set1_epi64x(static_cast<int64_t>(0x4330'0000'0000'0000ULL))));
  const __m256d frac =
      _mm256_mul_pd(_mm256_add_pd(_mm256_sub_pd(bias, _mm256_set1_pd(0x1p52)), _mm256_set1_pd(0.5)),
                    _mm256_set1_pd(1.0 / (1u << kLowBits)));
  return _mm256_add_pd(t0, _mm256_mul_pd(frac, slope));
}

// EtaPhotons of values j to j + 3.
__attribute__((target("avx2"))) inline __m256d EtaPhotons4(const PhotonInput& in, std::size_t j) {
  const __m128 photons = _mm_max_ps(_mm_loadu_ps(in.photons + j), _mm_setzero_ps());  // NaN: 0
  return _mm256_mul_pd(_mm256_set1_pd(in.eta), _mm256_cvtps_pd(photons));
}
__attribute__((target("avx2"))) inline __m256d EtaPhotons4(const RenderedInput& in, std::size_t j) {
  int32_t bytes;
  std::memcpy(&bytes, in.values + j, sizeof(bytes));
  return Gather4(in.eta_photons, _mm_cvtepu8_epi32(_mm_cvtsi32_si128(bytes)));
}

// Values j to j + 4 G - 1 of a run (ExposeRunAvx2), as G groups of 4 lanes: each step for
// every group in turn, so that the out-of-order core overlaps the groups' long chains (hash,
// table loads, square root). The same double operations as ExposeValue in the same order (no
// FMA): the same bits. Lanes that take a rare path (mean electrons below kExactPoissonMean, 0
// included, or not finite; a Gaussian's outer bin) are redone by ExposeValue.
template <int G, typename Input>
__attribute__((target("avx2"), always_inline)) inline void ExposeGroupsAvx2(
    const FrameTerms& t, const Input& in, std::size_t first, std::size_t j, uint16_t* raw,
    uint8_t* out8) {
  const __m256d zero = _mm256_setzero_pd(), half = _mm256_set1_pd(0.5);
  __m256i h[G], rare[G];
  __m256d lambda[G], e[G];
#pragma GCC unroll 8
  for (int k = 0; k < G; ++k) {
    const uint64_t i = first + j + 4 * k;
    h[k] = SensorMix4(_mm256_add_epi64(_mm256_set1_epi64x(static_cast<int64_t>(t.key + i)),
                                       _mm256_setr_epi64x(0, 1, 2, 3)));
    lambda[k] =
        _mm256_mul_pd(EtaPhotons4(in, j + 4 * k), _mm256_cvtps_pd(_mm_loadu_ps(t.prnu + i)));
    rare[k] = _mm256_castpd_si256(
        _mm256_or_pd(_mm256_cmp_pd(lambda[k], _mm256_set1_pd(kExactPoissonMean), _CMP_NGE_UQ),
                     _mm256_cmp_pd(lambda[k], _mm256_set1_pd(0x1p1000), _CMP_NLT_UQ)));
  }
#pragma GCC unroll 8
  for (int k = 0; k < G; ++k) {
    const __m256d shot = SensorGaussian4(t.pairs, _mm256_srli_epi64(h[k], 32), &rare[k]);
    e[k] = _mm256_add_pd(lambda[k], _mm256_mul_pd(_mm256_sqrt_pd(lambda[k]), shot));
  }
  const __m256d shift = _mm256_set1_pd(0x1.8p52);  // RoundWhole
#pragma GCC unroll 8
  for (int k = 0; k < G; ++k) {
    e[k] = _mm256_and_pd(_mm256_cmp_pd(e[k], zero, _CMP_GT_OQ),  // e > 0 ? RoundWhole(e) : 0
                         _mm256_sub_pd(_mm256_add_pd(e[k], shift), shift));
    const __m256i low = _mm256_and_si256(h[k], _mm256_set1_epi64x(0xffff'ffffLL));
    const __m256d dark = SensorGaussian4(t.pairs, low, &rare[k]);
    const __m256d dsnu = _mm256_cvtps_pd(_mm_loadu_ps(t.dsnu + first + j + 4 * k));
    e[k] = _mm256_add_pd(e[k], _mm256_add_pd(_mm256_mul_pd(_mm256_set1_pd(t.sigma_d), dark), dsnu));
  }
#pragma GCC unroll 8
  for (int k = 0; k < G; ++k) {
    const __m256d full = _mm256_min_pd(_mm256_set1_pd(t.sat), e[k]);  // std::min(e, sat)
    // std::clamp(K e + offset, 0, max_dn) of a finite value; rounded half up.
    const __m256d dn =
        _mm256_add_pd(_mm256_mul_pd(_mm256_set1_pd(t.K), full), _mm256_set1_pd(t.offset));
    const __m256d clamped = _mm256_max_pd(zero, _mm256_min_pd(_mm256_set1_pd(t.max_dn), dn));
    const __m128i words = _mm256_cvttpd_epi32(_mm256_add_pd(clamped, half));
    _mm_storel_epi64(reinterpret_cast<__m128i*>(raw + j + 4 * k), _mm_packus_epi32(words, words));
    if (out8 != nullptr) {  // To8
      const __m256d scaled = _mm256_mul_pd(_mm256_cvtepi32_pd(words), _mm256_set1_pd(t.to8));
      const __m128i bytes = _mm256_cvttpd_epi32(_mm256_add_pd(scaled, half));
      const int32_t four =
          _mm_cvtsi128_si32(_mm_packus_epi16(_mm_packus_epi32(bytes, bytes), bytes));
      std::memcpy(out8 + j + 4 * k, &four, sizeof(four));
    }
  }
#pragma GCC unroll 8
  for (int k = 0; k < G; ++k) {
    const int redo = _mm256_movemask_pd(_mm256_castsi256_pd(rare[k]));
    if (redo != 0) [[unlikely]] {
      alignas(32) double lambdas[4];
      _mm256_store_pd(lambdas, lambda[k]);
      RedoLanes(t, first, j + 4 * k, lambdas, 4, static_cast<unsigned>(redo), raw, out8);
    }
  }
}

// ExposeRunPortable with AVX2: kAvx2Groups x 4 values at a time, then 4, then one by one.
template <typename Input>
__attribute__((target("avx2"))) void ExposeRunAvx2(const FrameTerms& t, const Input& in,
                                                   std::size_t first, std::size_t n, uint16_t* raw,
                                                   uint8_t* out8) {
  std::size_t j = 0;
  for (; j + 4 * kAvx2Groups <= n; j += 4 * kAvx2Groups) {
    ExposeGroupsAvx2<kAvx2Groups>(t, in, first, j, raw, out8);
  }
  for (; j + 4 <= n; j += 4) ExposeGroupsAvx2<1>(t, in, first, j, raw, out8);
  ExposeRunPortable(t, in, first, n, raw, out8, j);
}

// GCC 12's AVX-512 intrinsics start from an undefined register (_mm512_undefined_*), which
// -Wmaybe-uninitialized takes for a read of an uninitialised value.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
// The same with AVX-512: 8 lanes a vector, the hash's 64-bit products by vpmullq, each lane's
// quantile and slope by two gathers, the rare lanes in a mask. The same double operations in
// the same order (sensor_model.cc is built without fp contraction: AVX-512 has FMA).
constexpr int kAvx512Groups = 2;
#define SACCADE_AVX512 __attribute__((target("avx512f,avx512dq,avx512bw,avx512vl"), always_inline))

// SensorMix of 8 lanes.
SACCADE_AVX512 inline __m512i SensorMix8(__m512i z) {
  z = _mm512_add_epi64(z, _mm512_set1_epi64(static_cast<int64_t>(0x9e3779b97f4a7c15ULL)));
  z = _mm512_mullo_epi64(_mm512_xor_si512(z, _mm512_srli_epi64(z, 30)),
                         _mm512_set1_epi64(static_cast<int64_t>(0xbf58476d1ce4e5b9ULL)));
  z = _mm512_mullo_epi64(_mm512_xor_si512(z, _mm512_srli_epi64(z, 27)),
                         _mm512_set1_epi64(static_cast<int64_t>(0x94d049bb133111ebULL)));
  return _mm512_xor_si512(z, _mm512_srli_epi64(z, 31));
}

// SensorGaussian of 8 lanes' 32 bits (each 64-bit lane's low half) from GaussianPairs; ORs the
// lanes whose bin is an outer one into `*outer`.
SACCADE_AVX512 inline __m512d SensorGaussian8(const double* pairs, __m512i bits, __mmask8* outer) {
  constexpr int kLowBits = 32 - kGaussianBinBits;
  const __m512i bin = _mm512_srli_epi64(bits, kLowBits);
  *outer |= _mm512_cmpeq_epi64_mask(bin, _mm512_setzero_si512()) |
            _mm512_cmpeq_epi64_mask(bin, _mm512_set1_epi64(kGaussianBins - 1));
  const __m512i at = _mm512_slli_epi64(bin, 1);
  const __m512d t0 = _mm512_i64gather_pd(at, pairs, 8);         // t[bin]
  const __m512d slope = _mm512_i64gather_pd(at, pairs + 1, 8);  // t[bin + 1] - t[bin]
  const __m512i low = _mm512_and_si512(bits, _mm512_set1_epi64((1 << kLowBits) - 1));
  const __m512d bias = _mm512_castsi512_pd(
      _mm512_or_si512(low, _mm512_set1_epi64(static_cast<int64_t>(0x4330'0000'0000'0000ULL))));
  const __m512d frac =
      _mm512_mul_pd(_mm512_add_pd(_mm512_sub_pd(bias, _mm512_set1_pd(0x1p52)), _mm512_set1_pd(0.5)),
                    _mm512_set1_pd(1.0 / (1u << kLowBits)));
  return _mm512_add_pd(t0, _mm512_mul_pd(frac, slope));
}

// EtaPhotons of values j to j + 7.
SACCADE_AVX512 inline __m512d EtaPhotons8(const PhotonInput& in, std::size_t j) {
  const __m256 photons = _mm256_max_ps(_mm256_loadu_ps(in.photons + j), _mm256_setzero_ps());
  return _mm512_mul_pd(_mm512_set1_pd(in.eta), _mm512_cvtps_pd(photons));
}
SACCADE_AVX512 inline __m512d EtaPhotons8(const RenderedInput& in, std::size_t j) {
  const __m128i bytes = _mm_loadl_epi64(reinterpret_cast<const __m128i*>(in.values + j));
  return _mm512_i32gather_pd(_mm256_cvtepu8_epi32(bytes), in.eta_photons, 8);
}

// Values j to j + 8 G - 1 of a run, as G groups of 8 lanes, each step for every group in turn
// (ExposeGroupsAvx2's order of operations).
template <int G, typename Input>
SACCADE_AVX512 inline void ExposeGroupsAvx512(const FrameTerms& t, const Input& in,
                                              std::size_t first, std::size_t j, uint16_t* raw,
                                              uint8_t* out8) {
  const __m512d zero = _mm512_setzero_pd(), half = _mm512_set1_pd(0.5);
  __m512i h[G];
  __mmask8 rare[G];
  __m512d lambda[G], e[G];
  for (int k = 0; k < G; ++k) {
    const uint64_t i = first + j + 8 * k;
    h[k] = SensorMix8(_mm512_add_epi64(_mm512_set1_epi64(static_cast<int64_t>(t.key + i)),
                                       _mm512_setr_epi64(0, 1, 2, 3, 4, 5, 6, 7)));
    lambda[k] =
        _mm512_mul_pd(EtaPhotons8(in, j + 8 * k), _mm512_cvtps_pd(_mm256_loadu_ps(t.prnu + i)));
    rare[k] = _mm512_cmp_pd_mask(lambda[k], _mm512_set1_pd(kExactPoissonMean), _CMP_NGE_UQ) |
              _mm512_cmp_pd_mask(lambda[k], _mm512_set1_pd(0x1p1000), _CMP_NLT_UQ);
  }
  for (int k = 0; k < G; ++k) {
    const __m512d shot = SensorGaussian8(t.pairs, _mm512_srli_epi64(h[k], 32), &rare[k]);
    e[k] = _mm512_add_pd(lambda[k], _mm512_mul_pd(_mm512_sqrt_pd(lambda[k]), shot));
  }
  const __m512d shift = _mm512_set1_pd(0x1.8p52);  // RoundWhole
  for (int k = 0; k < G; ++k) {
    e[k] = _mm512_maskz_mov_pd(_mm512_cmp_pd_mask(e[k], zero, _CMP_GT_OQ),  // e > 0 ? .. : 0
                               _mm512_sub_pd(_mm512_add_pd(e[k], shift), shift));
    const __m512i low = _mm512_and_si512(h[k], _mm512_set1_epi64(0xffff'ffffLL));
    const __m512d dark = SensorGaussian8(t.pairs, low, &rare[k]);
    const __m512d dsnu = _mm512_cvtps_pd(_mm256_loadu_ps(t.dsnu + first + j + 8 * k));
    e[k] = _mm512_add_pd(e[k], _mm512_add_pd(_mm512_mul_pd(_mm512_set1_pd(t.sigma_d), dark), dsnu));
  }
  for (int k = 0; k < G; ++k) {
    const __m512d full = _mm512_min_pd(_mm512_set1_pd(t.sat), e[k]);  // std::min(e, sat)
    const __m512d dn =
        _mm512_add_pd(_mm512_mul_pd(_mm512_set1_pd(t.K), full), _mm512_set1_pd(t.offset));
    const __m512d clamped = _mm512_max_pd(zero, _mm512_min_pd(_mm512_set1_pd(t.max_dn), dn));
    const __m256i words = _mm512_cvttpd_epi32(_mm512_add_pd(clamped, half));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(raw + j + 8 * k), _mm256_cvtepi32_epi16(words));
    if (out8 != nullptr) {  // To8
      const __m512d scaled = _mm512_mul_pd(_mm512_cvtepi32_pd(words), _mm512_set1_pd(t.to8));
      const __m256i bytes = _mm512_cvttpd_epi32(_mm512_add_pd(scaled, half));
      _mm_storel_epi64(reinterpret_cast<__m128i*>(out8 + j + 8 * k), _mm256_cvtepi32_epi8(bytes));
    }
  }
  for (int k = 0; k < G; ++k) {
    if (rare[k] != 0) [[unlikely]] {
      alignas(64) double lambdas[8];
      _mm512_store_pd(lambdas, lambda[k]);
      RedoLanes(t, first, j + 8 * k, lambdas, 8, rare[k], raw, out8);
    }
  }
}
#undef SACCADE_AVX512

// ExposeRunPortable with AVX-512: kAvx512Groups x 8 values at a time, then 8, then one by one.
template <typename Input>
__attribute__((target("avx512f,avx512dq,avx512bw,avx512vl"))) void ExposeRunAvx512(
    const FrameTerms& t, const Input& in, std::size_t first, std::size_t n, uint16_t* raw,
    uint8_t* out8) {
  std::size_t j = 0;
  for (; j + 8 * kAvx512Groups <= n; j += 8 * kAvx512Groups) {
    ExposeGroupsAvx512<kAvx512Groups>(t, in, first, j, raw, out8);
  }
  for (; j + 8 <= n; j += 8) ExposeGroupsAvx512<1>(t, in, first, j, raw, out8);
  ExposeRunPortable(t, in, first, n, raw, out8, j);
}
#pragma GCC diagnostic pop
#endif

// ExposeRunPortable, or the widest vector kernel of at most `lanes` the CPU has: ExposeRunAvx512
// (8), ExposeRunAvx2 (4); the same bits.
template <typename Input>
void ExposeRun(const FrameTerms& t, const Input& in, std::size_t first, std::size_t n,
               uint16_t* raw, uint8_t* out8, int lanes) {
#if defined(__x86_64__)
  static const bool avx2 = __builtin_cpu_supports("avx2");  // asked once
  static const bool avx512 =
      __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
      __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512vl");
  if (avx512 && lanes >= 8) {
    ExposeRunAvx512(t, in, first, n, raw, out8);
    return;
  }
  if (avx2 && lanes >= 4) {
    ExposeRunAvx2(t, in, first, n, raw, out8);
    return;
  }
#else
  static_cast<void>(lanes);
#endif
  ExposeRunPortable(t, in, first, n, raw, out8);
}

// Whether an image of `format` holds a sensor's values of `channels`: kRgb8 for 3; kGray8 or
// an 8-bit Bayer mosaic (one photosite a pixel) for 1.
bool Fits(PixelFormat format, int channels) {
  if (channels == 3) return format == PixelFormat::kRgb8;
  return format == PixelFormat::kGray8 || (IsBayer(format) && BytesPerPixel(format) == 1);
}

// part(first, end) over [0, n) in chunks of kSensorChunkValues on every core (ForEachChunk);
// in one piece on one core.
template <typename Part>
void ForParts(std::size_t n, const Part& part) {
  internal::ForEachChunk(n, kSensorChunkValues,
                         [&part](int, std::size_t first, std::size_t end) { part(first, end); });
}

// ForParts over the values of `height` rows of `row_values` each: row(y, x0, x1) for the
// values [x0, x1) of row y that a part holds.
template <typename Row>
void ForRowParts(int height, std::size_t row_values, const Row& row) {
  ForParts(static_cast<std::size_t>(height) * row_values, [&](std::size_t first, std::size_t end) {
    for (std::size_t y = first / row_values; y * row_values < end; ++y) {
      row(static_cast<int>(y), std::max(first, y * row_values) - y * row_values,
          std::min(end, (y + 1) * row_values) - y * row_values);
    }
  });
}

// The terms of frame `frame_index` of a sensor of `params`, `stream` and fixed pattern.
FrameTerms MakeTerms(const scene::EmvaSensor& params, uint64_t stream, int64_t frame_index,
                     double gain, const float* prnu, const float* dsnu) {
  FrameTerms t;
  t.key = SensorMix(stream ^ SensorMix(kFrameStream + static_cast<uint64_t>(frame_index)));
  t.K = params.gain_dn_per_e * gain;  // the camera's gain amplifies K
  t.sigma_d = params.dark_noise_e;
  t.sat = params.saturation_e;
  t.offset = params.black_level_dn;
  t.max_dn = params.MaxDn();
  t.to8 = 255.0 / params.MaxDn();
  t.table = GaussianTable().data();
  t.pairs = GaussianPairs().data();
  t.prnu = prnu;
  t.dsnu = dsnu;
  return t;
}

// Throws InvalidArgument unless an image of `width` x `height` and `format` holds `sensor`'s
// values (Fits); `what`: the function that asks.
void CheckImage(const char* what, const SensorModel& sensor, int width, int height,
                PixelFormat format) {
  if (width != sensor.width() || height != sensor.height() || !Fits(format, sensor.channels())) {
    const PixelFormat expected = sensor.channels() == 3 ? PixelFormat::kRgb8 : PixelFormat::kGray8;
    throw InvalidArgument(fmt::format("{}: expected a {} x {} {} image, got {} x {} {}", what,
                                      sensor.width(), sensor.height(), ToString(expected), width,
                                      height, ToString(format)));
  }
}

uint64_t HashName(uint64_t seed, const std::string& name) {
  uint64_t h = 1469598103934665603ULL;  // FNV-1a
  for (const char c : name) h = (h ^ static_cast<unsigned char>(c)) * 1099511628211ULL;
  return SensorMix(seed ^ SensorMix(h));
}

}  // namespace

SensorModel::SensorModel(const scene::EmvaSensor& params, uint64_t seed, const std::string& camera,
                         int width, int height, int channels)
    : params_(params),
      stream_(HashName(seed, camera)),
      width_(width),
      height_(height),
      channels_(channels) {
  params_.Validate();
  if (width <= 0 || height <= 0 || (channels != 1 && channels != 3) ||
      int64_t{width} * height * channels > kMaxSensorValues) {
    throw InvalidArgument(fmt::format(
        "SensorModel: expected a positive size of 1 or 3 channels and at most {} values, got "
        "{} x {} x {}",
        kMaxSensorValues, width, height, channels));
  }
  const std::size_t n = static_cast<std::size_t>(width) * height * channels;
  prnu_.resize(n);
  dsnu_.resize(n);
  const double prnu = params_.prnu_percent / 100.0;
  const uint64_t prnu_key = SensorMix(stream_ ^ kPrnuStream);
  const uint64_t dsnu_key = SensorMix(stream_ ^ kDsnuStream);
  const double* const table = GaussianTable().data();
  for (std::size_t i = 0; i < n; ++i) {
    const auto prnu_bits = static_cast<uint32_t>(SensorMix(prnu_key + i));
    const double gain = 1.0 + prnu * SensorGaussian(table, prnu_bits);
    prnu_[i] = static_cast<float>(std::max(0.0, gain));
    const auto dsnu_bits = static_cast<uint32_t>(SensorMix(dsnu_key + i));
    dsnu_[i] = static_cast<float>(params_.dsnu_e * SensorGaussian(table, dsnu_bits));
  }
}

void UseSensorLanes(SensorModel& sensor, int max_lanes) { sensor.lanes_ = max_lanes; }

void SensorModel::Expose(const float* photons, int64_t frame_index, uint16_t* raw,
                         double gain) const {
  const FrameTerms t = MakeTerms(params_, stream_, frame_index, gain, prnu_.data(), dsnu_.data());
  const PhotonInput in{photons, params_.quantum_efficiency};
  // Each value depends on its index alone: parts give the same bits as one loop.
  ForParts(values(), [&](std::size_t first, std::size_t end) {
    ExposeRun(t, PhotonInput{in.photons + first, in.eta}, first, end - first, raw + first, nullptr,
              lanes_);
  });
}

std::vector<uint16_t> SensorModel::ExposeUniform(double mean_photons, int64_t frame_index) const {
  const std::vector<float> photons(values(), static_cast<float>(mean_photons));
  std::vector<uint16_t> raw(values());
  Expose(photons.data(), frame_index, raw.data());
  return raw;
}

std::vector<uint16_t> SensorModel::ExposeRendered(const ImageView& rendered, double exposure_s,
                                                  int64_t frame_index, Image* image8,
                                                  double gain) const {
  std::vector<uint16_t> raw(values());
  ExposeRenderedInto(rendered, exposure_s, frame_index, raw.data(), image8, gain);
  return raw;
}

void SensorModel::ExposeRendered8(const ImageView& rendered, double exposure_s, int64_t frame_index,
                                  Image* image8, double gain) const {
  if (image8 == nullptr) throw InvalidArgument("SensorModel::ExposeRendered8: no image to write");
  ExposeRenderedInto(rendered, exposure_s, frame_index, nullptr, image8, gain);
}

void SensorModel::ExposeRenderedInto(const ImageView& rendered, double exposure_s,
                                     int64_t frame_index, uint16_t* raw, Image* image8,
                                     double gain) const {
  CheckImage("SensorModel::ExposeRendered", *this, rendered.width(), rendered.height(),
             rendered.format());
  if (image8 != nullptr) {
    CheckImage("SensorModel::To8Bit", *this, image8->width(), image8->height(), image8->format());
  }
  const double scale = params_.photons_per_second * exposure_s / 255.0;
  // Each 8-bit value's eta mu_p: its photons as the product per value gave them, times eta.
  double eta_photons[256];
  for (int v = 0; v < 256; ++v) {
    const auto photons = static_cast<float>(v * scale);
    eta_photons[v] = params_.quantum_efficiency * std::max(0.0f, photons);
  }
  const FrameTerms t = MakeTerms(params_, stream_, frame_index, gain, prnu_.data(), dsnu_.data());
  const std::size_t row_values = static_cast<std::size_t>(width_) * channels_;
  // One pass: each value read, exposed and, with `image8`, written back in 8 bits. Without
  // `raw`, a run's DN go to a buffer of the thread's, read back while still in its cache.
  ForRowParts(height_, row_values, [&](int y, std::size_t x0, std::size_t x1) {
    const std::size_t first = y * row_values + x0;
    thread_local std::vector<uint16_t> run;
    if (raw == nullptr && run.size() < x1 - x0) run.resize(x1 - x0);
    ExposeRun(t, RenderedInput{rendered.row(y) + x0, eta_photons}, first, x1 - x0,
              raw != nullptr ? raw + first : run.data(),
              image8 != nullptr ? image8->row(y) + x0 : nullptr, lanes_);
  });
}

void SensorModel::To8Bit(const uint16_t* raw, Image* image8) const {
  CheckImage("SensorModel::To8Bit", *this, image8->width(), image8->height(), image8->format());
  const double scale = 255.0 / params_.MaxDn();
  // Each raw value's 8-bit value, as the product per value gave it.
  std::vector<uint8_t> to8(static_cast<std::size_t>(params_.MaxDn()) + 1);
  for (std::size_t v = 0; v < to8.size(); ++v) {
    to8[v] = static_cast<uint8_t>(RoundNonNegative(static_cast<double>(v) * scale));
  }
  const std::size_t row_values = static_cast<std::size_t>(width_) * channels_;
  ForRowParts(height_, row_values, [&](int y, std::size_t x0, std::size_t x1) {
    uint8_t* row = image8->row(y);
    for (std::size_t x = x0; x < x1; ++x) row[x] = to8[raw[y * row_values + x]];
  });
}

}  // namespace saccade::render
