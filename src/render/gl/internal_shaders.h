#pragma once
// GLSL 330 core sources of the render/gl backend.
//
// Shading model (kept simple, documented once here): colours are used as they are, linear
// values in [0, 1] written to the 8-bit image without sRGB encoding; textures are sampled as
// stored (no sRGB decoding). A surface's colour is
//   albedo * (ambient + sum_i c_i max(n.l_i, 0)) + specular * sum_i c_i (n.h_i)^shininess
// (Lambert diffuse, Blinn-Phong specular, h = normalize(l + v), the highlight only where
// n.l_i > 0), with albedo = base colour x texture, c_i = colour x intensity of light i, times
// 1 / (1 + attenuation d^2) for point lights. Everything is opaque (alpha is ignored). Open
// meshes are two-sided (lit on the side seen); lighting is computed in OpenGL's eye frame.
//
// Programs are specialised by #defines at the top of both stages (SourcePrefix): the number
// of directional and point lights of the scene (loops unroll, absent lights cost nothing),
// and per program variant:
//   TEXTURED    the material has a texture (uv varying, one sample);
//   SHINY       the material has specular > 0;
//   PER_VERTEX  lighting evaluated per vertex (Gouraud) and interpolated, rather than per
//               fragment. The renderer chooses it where the two agree: exactly on flat faces
//               (one normal per triangle) without point lights or specular, where the lighting
//               is constant over each triangle; to well under one 8-bit step on smooth meshes
//               whose triangles are at most 2 px across on screen (internal_gl_renderer.cc).
//               On llvmpipe, which shades whole 4 x 4 pixel blocks per triangle, this keeps
//               finely tessellated models from paying a lighting evaluation per tiny triangle.
//   TWO_SIDED   (PER_VERTEX only) the mesh is open: both sides are lit per vertex.
//
// Texture orientation: textures are uploaded with the image's row 0 (its top) first, which
// OpenGL puts at t = 0; scene uv (0, 0) is the image's bottom-left (scene.h), so the vertex
// shader samples at t = 1 - v.

#include <string>

namespace saccade::render::gl {

/// Directional and point lights a scene may have (ambient lights are summed into one term).
inline constexpr int kMaxLights = 8;

/// Lighting shared by all programs. In the eye frame: u_directional_direction[i] is the unit
/// direction towards light i; u_point_position[i] a point light's position; colours are
/// colour x intensity, u_point_color[i].a the attenuation. Light() returns the diffuse
/// irradiance (to multiply the albedo by) and the specular highlight (to add).
inline constexpr const char* kLightingSource = R"(
#ifndef SHINY
#define SHINY 0
#endif
uniform vec3 u_ambient;
#if NUM_DIRECTIONAL > 0
uniform vec3 u_directional_direction[NUM_DIRECTIONAL];
uniform vec3 u_directional_color[NUM_DIRECTIONAL];
#endif
#if NUM_POINT > 0
uniform vec3 u_point_position[NUM_POINT];
uniform vec4 u_point_color[NUM_POINT];
#endif

void Light(vec3 n, vec3 p_eye, float shininess, out vec3 diffuse, out vec3 highlight) {
  diffuse = u_ambient;
  highlight = vec3(0.0);
#if SHINY
  vec3 v = normalize(-p_eye);
#endif
#if NUM_DIRECTIONAL > 0
  for (int i = 0; i < NUM_DIRECTIONAL; ++i) {
    vec3 l = u_directional_direction[i];
    float ndl = dot(n, l);
    if (ndl > 0.0) {
      diffuse += u_directional_color[i] * ndl;
#if SHINY
      highlight += u_directional_color[i] * pow(max(dot(n, normalize(l + v)), 0.0), shininess);
#endif
    }
  }
#endif
#if NUM_POINT > 0
  for (int i = 0; i < NUM_POINT; ++i) {
    vec3 l = u_point_position[i] - p_eye;
    float d2 = dot(l, l);
    l *= inversesqrt(d2);
    float ndl = dot(n, l);
    if (ndl > 0.0) {
      vec3 c = u_point_color[i].rgb / (1.0 + u_point_color[i].a * d2);
      diffuse += c * ndl;
#if SHINY
      highlight += c * pow(max(dot(n, normalize(l + v)), 0.0), shininess);
#endif
    }
  }
#endif
}
)";

/// Meshes: attributes 0 position, 1 normal, 2 uv (model frame).
inline constexpr const char* kMeshVertexSource = R"(
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_uv;
uniform mat4 u_mvp;     // clip <- model: P * OpticalToGlEye * X_CW * X_WO * scale
uniform mat4 u_mv;      // eye <- model
uniform mat3 u_normal;  // inverse transpose of u_mv's 3x3
#if TEXTURED
out vec2 v_uv;
#endif
#if PER_VERTEX
uniform vec4 u_base_color;
uniform float u_specular;
uniform float u_shininess;
out vec3 v_diffuse;  // base colour x irradiance, front side
#if SHINY
out vec3 v_highlight;
#endif
#if TWO_SIDED
out vec3 v_diffuse_back;
#if SHINY
out vec3 v_highlight_back;
#endif
#endif
#else
#if NUM_POINT > 0 || SHINY
#define NEEDS_POSITION 1
out vec3 v_position;
#endif
out vec3 v_normal;
#endif

void main() {
  gl_Position = u_mvp * vec4(a_position, 1.0);
#if TEXTURED
  v_uv = vec2(a_uv.x, 1.0 - a_uv.y);
#endif
#if PER_VERTEX
  vec3 p = (u_mv * vec4(a_position, 1.0)).xyz;
  vec3 n = normalize(u_normal * a_normal);
  vec3 diffuse, highlight;
  Light(n, p, u_shininess, diffuse, highlight);
  v_diffuse = u_base_color.rgb * diffuse;
#if SHINY
  v_highlight = u_specular * highlight;
#endif
#if TWO_SIDED
  Light(-n, p, u_shininess, diffuse, highlight);
  v_diffuse_back = u_base_color.rgb * diffuse;
#if SHINY
  v_highlight_back = u_specular * highlight;
#endif
#endif
#else
#ifdef NEEDS_POSITION
  v_position = (u_mv * vec4(a_position, 1.0)).xyz;
#endif
  v_normal = u_normal * a_normal;
#endif
}
)";

inline constexpr const char* kMeshFragmentSource = R"(
uniform vec4 u_base_color;
uniform float u_specular;
uniform float u_shininess;
#if TEXTURED
uniform sampler2D u_texture;
in vec2 v_uv;
#endif
#if PER_VERTEX
in vec3 v_diffuse;
#if SHINY
in vec3 v_highlight;
#endif
#if TWO_SIDED
in vec3 v_diffuse_back;
#if SHINY
in vec3 v_highlight_back;
#endif
#endif
#else
#if NUM_POINT > 0 || SHINY
#define NEEDS_POSITION 1
in vec3 v_position;
#endif
in vec3 v_normal;
#endif
out vec4 o_color;

void main() {
#if TEXTURED
  vec3 texel = texture(u_texture, v_uv).rgb;
#else
  vec3 texel = vec3(1.0);
#endif
#if PER_VERTEX
#if TWO_SIDED
  bool front = gl_FrontFacing;
  vec3 color = texel * (front ? v_diffuse : v_diffuse_back);
#if SHINY
  color += front ? v_highlight : v_highlight_back;
#endif
#else
  vec3 color = texel * v_diffuse;
#if SHINY
  color += v_highlight;
#endif
#endif
#else
  vec3 n = normalize(gl_FrontFacing ? v_normal : -v_normal);
#ifdef NEEDS_POSITION
  vec3 p = v_position;
#else
  vec3 p = vec3(0.0);
#endif
  vec3 diffuse, highlight;
  Light(n, p, u_shininess, diffuse, highlight);
  vec3 color = texel * u_base_color.rgb * diffuse + u_specular * highlight;
#endif
  o_color = vec4(color, 1.0);
}
)";

/// The ground: a quad in the world plane z = 0 (attribute 0, world coordinates). PATTERN is
/// 0 (plain), 1 (grid) or 2 (checker).
inline constexpr const char* kGroundVertexSource = R"(
layout(location = 0) in vec3 a_position;
uniform mat4 u_mvp;
uniform mat4 u_mv;
uniform float u_cell;
#if NUM_POINT > 0
out vec3 v_position;
#endif
#if PATTERN != 0
out vec2 v_cells;  // world x, y in cells
#endif
void main() {
  gl_Position = u_mvp * vec4(a_position, 1.0);
#if NUM_POINT > 0
  v_position = (u_mv * vec4(a_position, 1.0)).xyz;
#endif
#if PATTERN != 0
  v_cells = a_position.xy / u_cell;
#endif
}
)";

/// The ground's pattern, analytic and box-filtered over the pixel's footprint (fwidth), so
/// that it does not alias far away: checker squares [i, i+1) x [j, j+1) cells take u_color
/// when i + j is even; grid lines of width u_line_fraction cells are centred on whole cells.
inline constexpr const char* kGroundFragmentSource = R"(
uniform float u_line_fraction;
uniform vec3 u_color;
uniform vec3 u_color2;
uniform vec3 u_normal_eye;  // world +z in the eye frame
#if NUM_POINT > 0
in vec3 v_position;
#endif
#if PATTERN != 0
in vec2 v_cells;
#endif
out vec4 o_color;
void main() {
  float t = 0.0;
#if PATTERN != 0
  vec2 w = fwidth(v_cells) + 1e-4;
#if PATTERN == 2
  // Box-filtered square wave of period 2 (+1 on [0, 1), -1 on [1, 2)) in x and in y.
  vec2 i = 2.0 * (abs(fract((v_cells - 0.5 * w) * 0.5) - 0.5) -
                  abs(fract((v_cells + 0.5 * w) * 0.5) - 0.5)) / w;
  t = 0.5 - 0.5 * i.x * i.y;
#else
  // Box-filtered pulse train: lines cover [0, f) of every cell after a shift by f / 2.
  float f = u_line_fraction;
  vec2 a = v_cells + 0.5 * f + 0.5 * w;
  vec2 b = v_cells + 0.5 * f - 0.5 * w;
  vec2 i = (floor(a) + min(fract(a) / f, 1.0) - floor(b) - min(fract(b) / f, 1.0)) * f / w;
  t = 1.0 - (1.0 - i.x) * (1.0 - i.y);
#endif
#endif
  vec3 albedo = mix(u_color, u_color2, t);
  vec3 n = gl_FrontFacing ? u_normal_eye : -u_normal_eye;
#if NUM_POINT > 0
  vec3 p = v_position;
#else
  vec3 p = vec3(0.0);
#endif
  vec3 diffuse, highlight;
  Light(n, p, 1.0, diffuse, highlight);
  o_color = vec4(albedo * diffuse, 1.0);
}
)";

/// The #version line and #defines that specialise a program (both stages get the same).
inline std::string SourcePrefix(int num_directional, int num_point, const std::string& defines) {
  return "#version 330 core\n#define NUM_DIRECTIONAL " + std::to_string(num_directional) +
         "\n#define NUM_POINT " + std::to_string(num_point) + "\n" + defines;
}

}  // namespace saccade::render::gl
