#pragma once
// What a scene may ask of the machine, checked when the scene is loaded, before anything is
// allocated for it: a scene beyond these gets a FileError naming the file, line and key, never
// an out-of-memory abort in the renderer.
#include <cstdint>

namespace saccade::scene {

/// The longest image side a camera may have, pixels: GL_MAX_TEXTURE_SIZE of Mesa's llvmpipe and
/// of most GPUs (the renderer also checks the context's own limits when it starts).
inline constexpr int kMaxImageSide = 16384;
/// Pixels per camera: 8192 x 8192. A camera's render targets take up to about 64 bytes a pixel
/// (colour, depth, readback buffers, ground truth, the lens's remap tables, the motion-blur
/// accumulator in float), so this bounds one camera near 4 GiB.
inline constexpr int64_t kMaxImagePixels = int64_t{8192} * 8192;
/// Pixels of all cameras of a scene together (four cameras at the largest size).
inline constexpr int64_t kMaxScenePixels = 4 * kMaxImagePixels;
/// Cameras of a scene, the robot's eyes included.
inline constexpr int kMaxCameras = 64;
/// Objects of a scene (each is drawn every frame; instance ids stay below 2^24).
inline constexpr int kMaxObjects = 100000;

/// Triangles and vertices of one model file. A model is drawn at every frame of every camera
/// (levels of detail simplify it, but its full mesh stays in memory: ~40 bytes a vertex).
inline constexpr int64_t kMaxModelTriangles = 10'000'000;
inline constexpr int64_t kMaxModelVertices = 30'000'000;

}  // namespace saccade::scene
