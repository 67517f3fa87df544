#pragma once
// GLSL 330 core sources of the effect passes (internal_effects.h): the lens remap, sensor
// noise and quantisation in one pass; the motion-blur accumulation; the ground-truth scene
// program and its remap.
//
// Every full-screen pass draws one triangle from gl_VertexID (no attributes) covering the
// viewport, and addresses pixels by gl_FragCoord: framebuffer row y is image row y
// everywhere (the scene passes flip rows through their projection), so no pass flips.

namespace saccade::render::gl {

/// One triangle covering the viewport: (-1, -1), (3, -1), (-1, 3).
inline constexpr const char* kFullscreenVertexSource = R"(#version 330 core
void main() {
  vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
  gl_Position = vec4(2.0 * p - 1.0, 0.0, 1.0);
}
)";

/// The lens remap's cells (internal_effects.h, LensMesh): rectangles of the camera's pixels,
/// given in NDC, with the source position (x, y, view) at their corners, which the rasterizer
/// interpolates linearly to every pixel centre (for the cells drawn through the map, unused).
inline constexpr const char* kLensMeshVertexSource = R"(#version 330 core
layout(location = 0) in vec2 a_position;
layout(location = 1) in vec3 a_source;
out vec3 v_source;
void main() {
  v_source = a_source;
  gl_Position = vec4(a_position, 0.0, 1.0);
}
)";

/// Motion blur: adds one sub-frame's layer, times its weight, into the accumulation layer
/// (additive blending into RGBA32F).
inline constexpr const char* kAccumulateFragmentSource = R"(#version 330 core
uniform sampler2DArray u_source;
uniform int u_layer;
uniform float u_weight;
out vec4 o_color;
void main() {
  o_color = u_weight * texelFetch(u_source, ivec3(ivec2(gl_FragCoord.xy), u_layer), 0);
}
)";

/// Motion blur of a camera that turns over the exposure: one instant is drawn and each
/// sub-frame k of its stretch of the exposure is that view seen through the homography of the
/// turn, u_h[k] (maps a pixel of sub-frame k, image coordinates with pixel centres at integers,
/// to the drawn view's), so the pixel gets u_weight times the sum of u_count bilinear fetches
/// along its path. Writes (or, blending, adds to) the accumulation layer (RGBA32F); outside the
/// drawn view the fetch clamps to its edge.
inline constexpr int kMaxTurnBlurSamples = 64;
inline constexpr const char* kTurnBlurFragmentSource = R"(#version 330 core
uniform sampler2DArray u_source;
uniform int u_layer;
uniform int u_count;
uniform float u_weight;
uniform mat3 u_h[64];
out vec4 o_color;
void main() {
  vec2 inverse_size = 1.0 / vec2(textureSize(u_source, 0).xy);
  vec3 p = vec3(gl_FragCoord.xy - 0.5, 1.0);
  vec4 sum = vec4(0.0);
  for (int k = 0; k < u_count; ++k) {
    vec3 q = u_h[k] * p;
    sum += texture(u_source, vec3((q.xy / q.z + 0.5) * inverse_size, float(u_layer)));
  }
  o_color = u_weight * sum;
}
)";

/// The camera's image: lens remap, sensor noise, quantisation to 8 bits.
/// IDENTITY 1: the source is the image itself (no distortion), one layer at the image's size.
/// MESH 1: the pixel's source position (x, y, view) comes interpolated from the lens mesh's
/// cell corners (v_source; LensMesh: within kLensMeshTolerancePx, half a source pixel, of the
/// map, one sample), plus the pixel's residual (u_residual, two signed bytes in units of
/// RESIDUAL_SCALE / 127: what the map departs from the interpolation), so within 0.003 px of
/// the map, with no fetch of the map itself: on llvmpipe the map's RGBA32F fetch was what made
/// the lens cost (10 ms of the pass an eye on the bench scene), and each triangle of a mesh
/// held to 0.01 px without residuals (8,100 cells an eye instead of 192) cost about 0.3 us of
/// setup on the calling thread; the residual's coherent 2-byte fetch costs less than either.
/// Otherwise u_map holds, per pixel, (x, y, view, taps) (internal_effects.h, RemapTable):
/// (x, y) in source view `view` (geometry/lens_map.h; view < 0: no ray, black), and the pixel
/// is the mean of the source over its footprint, a box as a sensor's pixel integrates: taps =
/// nu + 16 nv samples on a grid over the parallelogram spanned by u_footprint's (du, dv), the
/// map's steps to the neighbouring pixels. Each sample is one bilinear fetch of the texture
/// unit (the source is filtered linearly, clamped to its edge: llvmpipe and GPUs weigh with
/// 8 fractional bits, a position within 1/512 pixel, far below the lens's 0.02-0.03 px RMS
/// against OpenCV; by hand, four fetches and the weights in float cost three times as much on
/// llvmpipe). Most pixels of most lenses take one sample; where a lens compresses the source
/// (a fisheye's rim, a cube face seen obliquely: several source pixels a pixel step) one would
/// alias, and a corner or an edge would move by tenths of a pixel from one frame to the next.
/// TURN n (n > 0): motion blur of a turning camera folded into this pass. The n sub-frames of
/// the exposure fall into stretches, each drawn once at its middle into its own layer of
/// u_source; sub-frame k is layer u_turn_layer[k] seen through the homography of the turn,
/// u_turn_h[k] (a source pixel of sub-frame k, pixel centres at integers, to the drawn one's).
/// Wherever the pass would sample the source at x, it takes the mean of the n bilinear fetches
/// at u_turn_h[k] x instead: no accumulation image is written or read (on llvmpipe a
/// full-screen RGBA32F pass cost 6 ms an eye at 1024 x 768, as much as 2 fetches a pixel), and
/// the loop's bound is a constant, unrolled (a uniform bound cost a third more).
/// NOISE 1: signal S in DN (0..255), plus Gaussian noise of variance
///   u_read_sigma^2 + u_gain * S   (read noise; EMVA 1288 shot noise, gain K in DN/e-),
/// three standard normal deviates from one entry of u_gauss (GaussianTable: 2^16 entries, each
/// channel the quantiles of the normal distribution in its own order, packed into one 32-bit
/// integer as three 10-bit codes, PackGaussianTable), the entry chosen by a 32-bit integer
/// hash (lowbias32, C. Wellons) of the pixel and u_key (the camera's seed, name and frame
/// index, mixed on the CPU): the same key gives the same noise on the same device, and no
/// state is carried between frames. One fetch instead of Box-Muller's log, sqrt, sin and cos
/// per pixel; on llvmpipe the table's fetch, at a random place in it, is what the noise costs:
/// as three floats (768 KiB) 2.2 ms an eye at 1024 x 768, as one integer (256 KiB) less.
inline constexpr const char* kFinalFragmentSource = R"(
uniform sampler2DArray u_source;
#if MESH
in vec3 v_source;
uniform sampler2D u_residual;
#elif !IDENTITY
uniform sampler2D u_map;
uniform sampler2D u_footprint;
#endif
#if NOISE
uniform float u_read_sigma;
uniform float u_gain;
uniform uint u_key;
uniform usampler2D u_gauss;
#endif
#if TURN > 0
uniform mat3 u_turn_h[TURN];
uniform float u_turn_layer[TURN];
#endif
out vec4 o_color;

#if TURN > 0
vec3 Bilinear(vec2 x, float layer, vec2 inverse_size) {
  vec3 p = vec3(x, 1.0);
  vec3 sum = vec3(0.0);
  for (int k = 0; k < TURN; ++k) {
    vec3 q = u_turn_h[k] * p;
    sum += texture(u_source, vec3((q.xy / q.z + 0.5) * inverse_size, u_turn_layer[k])).rgb;
  }
  return sum * (1.0 / float(TURN));
}
#else
vec3 Bilinear(vec2 x, float layer, vec2 inverse_size) {
  return texture(u_source, vec3((x + 0.5) * inverse_size, layer)).rgb;
}
#endif

#if NOISE
uint Hash(uint x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}
#endif

void main() {
  ivec2 pixel = ivec2(gl_FragCoord.xy);
  vec3 c;
#if IDENTITY && TURN > 0
  c = Bilinear(vec2(pixel), 0.0, 1.0 / vec2(textureSize(u_source, 0).xy));
#elif IDENTITY
  c = texelFetch(u_source, ivec3(pixel, 0), 0).rgb;
#elif MESH
  vec2 s = v_source.xy + RESIDUAL_SCALE * texelFetch(u_residual, pixel, 0).xy;
  c = Bilinear(s, v_source.z, 1.0 / vec2(textureSize(u_source, 0).xy));
#else
  vec4 m = texelFetch(u_map, pixel, 0);
  if (m.z < 0.0) {
    c = vec3(0.0);
  } else {
    vec2 inverse_size = 1.0 / vec2(textureSize(u_source, 0).xy);
    int taps = int(m.w + 0.5);
    if (taps == 17) {  // nu = nv = 1
      c = Bilinear(m.xy, m.z, inverse_size);
    } else {
      int nu = taps & 15, nv = taps >> 4;
      vec4 footprint = texelFetch(u_footprint, pixel, 0);
      vec3 sum = vec3(0.0);
      for (int j = 0; j < nv; ++j) {
        for (int i = 0; i < nu; ++i) {
          vec2 o = (vec2(i, j) + 0.5) / vec2(nu, nv) - 0.5;
          sum += Bilinear(m.xy + o.x * footprint.xy + o.y * footprint.zw, m.z, inverse_size);
        }
      }
      c = sum / float(nu * nv);
    }
  }
#endif
  vec3 dn = 255.0 * c;
#if NOISE
  uint h = Hash(uint(pixel.x) ^ Hash(uint(pixel.y) ^ u_key));
  uint g = texelFetch(u_gauss, ivec2(int(h & 255u), int((h >> 8) & 255u)), 0).r;
  vec3 z = vec3(uvec3(g, g >> 10, g >> 20) & 1023u) * GAUSS_STEP - GAUSS_RANGE;
  vec3 sigma = sqrt(u_read_sigma * u_read_sigma + u_gain * max(dn, vec3(0.0)));
  dn += sigma * z;
#endif
  o_color = vec4(clamp(floor(dn + 0.5), 0.0, 255.0) * (1.0 / 255.0), 1.0);
}
)";

/// Ground truth of the scene in one source view: instance id; the surface's z in the CAMERA's
/// optical frame (u_depth_axis: the camera's +z in this view's OpenGL eye frame; a linear
/// function of position, so interpolation is exact), and its depth along the VIEW's axis (for
/// the remap's step test: in a cube face far off the camera's axis the camera z of a surface
/// changes by several per cent per pixel, its depth in the view does not). Attribute 0:
/// position.
inline constexpr const char* kTruthVertexSource = R"(#version 330 core
layout(location = 0) in vec3 a_position;
uniform mat4 u_mvp;
uniform mat4 u_mv;
uniform vec3 u_depth_axis;
out vec2 v_z;
void main() {
  gl_Position = u_mvp * vec4(a_position, 1.0);
  vec3 p = (u_mv * vec4(a_position, 1.0)).xyz;
  v_z = vec2(dot(u_depth_axis, p), -p.z);
}
)";

inline constexpr const char* kTruthFragmentSource = R"(#version 330 core
uniform uint u_id;
in vec2 v_z;
layout(location = 0) out uint o_id;
layout(location = 1) out vec2 o_z;
void main() {
  o_id = u_id;
  o_z = v_z;
}
)";

/// The truth's remap: the id of the nearest source pixel; the depth interpolated bilinearly
/// where the four source pixels around the ray see the same id (one surface), the nearest
/// one's otherwise (no depth mixed across an edge or a step). IDENTITY as in the final pass.
inline constexpr const char* kTruthRemapFragmentSource = R"(
uniform usampler2DArray u_ids;
uniform sampler2DArray u_z;
#if !IDENTITY
uniform sampler2D u_map;
#endif
layout(location = 0) out uint o_id;
layout(location = 1) out float o_z;
void main() {
  ivec2 pixel = ivec2(gl_FragCoord.xy);
#if IDENTITY
  o_id = texelFetch(u_ids, ivec3(pixel, 0), 0).r;
  o_z = texelFetch(u_z, ivec3(pixel, 0), 0).r;
#else
  // r: the camera's z, g: the depth along the view's axis (0: no surface).
  vec3 m = texelFetch(u_map, pixel, 0).xyz;
  if (m.z < 0.0) {
    o_id = 0u;
    o_z = 0.0;
    return;
  }
  int layer = int(m.z + 0.5);
  ivec2 last = textureSize(u_ids, 0).xy - 1;
  ivec2 n = clamp(ivec2(floor(m.xy + 0.5)), ivec2(0), last);
  o_id = texelFetch(u_ids, ivec3(n, layer), 0).r;
  vec2 f = floor(m.xy);
  vec2 w = m.xy - f;
  ivec2 a = clamp(ivec2(f), ivec2(0), last);
  ivec2 b = clamp(ivec2(f) + 1, ivec2(0), last);
  uint i00 = texelFetch(u_ids, ivec3(a.x, a.y, layer), 0).r;
  uint i10 = texelFetch(u_ids, ivec3(b.x, a.y, layer), 0).r;
  uint i01 = texelFetch(u_ids, ivec3(a.x, b.y, layer), 0).r;
  uint i11 = texelFetch(u_ids, ivec3(b.x, b.y, layer), 0).r;
  vec2 z00 = texelFetch(u_z, ivec3(a.x, a.y, layer), 0).rg;
  vec2 z10 = texelFetch(u_z, ivec3(b.x, a.y, layer), 0).rg;
  vec2 z01 = texelFetch(u_z, ivec3(a.x, b.y, layer), 0).rg;
  vec2 z11 = texelFetch(u_z, ivec3(b.x, b.y, layer), 0).rg;
  float d_min = min(min(z00.g, z10.g), min(z01.g, z11.g));
  float d_max = max(max(z00.g, z10.g), max(z01.g, z11.g));
  // Same id, all surfaces, and no depth step (an object occluding part of itself): 2 % of the
  // depth between neighbours is a surface at 85 degrees' incidence on a 600-pixel focal.
  bool one_surface = i00 == i10 && i00 == i01 && i00 == i11 && d_min > 0.0 &&
                     d_max - d_min <= 0.02 * d_min;
  o_z = one_surface ? mix(mix(z00.r, z10.r, w.x), mix(z01.r, z11.r, w.x), w.y)
                    : texelFetch(u_z, ivec3(n, layer), 0).r;
#endif
}
)";

}  // namespace saccade::render::gl
