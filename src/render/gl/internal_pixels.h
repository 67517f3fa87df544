#pragma once
// Pixel conversion of the readback.
#include <cstddef>
#include <cstdint>

namespace saccade::render::gl {

/// RGBA rows to tightly packed RGB (alpha dropped); SSSE3 where the CPU has it.
void RgbaToRgb(const uint8_t* rgba, uint8_t* rgb, std::size_t pixels);

}  // namespace saccade::render::gl
