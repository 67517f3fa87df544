#pragma once
// Reading and writing image files. PNG (8 and 16 bit) through libpng; JPEG, BMP, TGA and the
// rest stb_image reads, for textures.

#include <cstdint>
#include <filesystem>

#include "saccade/core/image.h"

namespace saccade {

/// The largest image ReadImage decodes: 16384 px a side (GL_MAX_TEXTURE_SIZE of llvmpipe and
/// most GPUs, so any image read can become a texture) and 256 Mpx (1 GiB as RGBA). Larger
/// images are refused from their header, before anything is allocated.
inline constexpr int64_t kMaxImageSide = 16384;
inline constexpr int64_t kMaxImagePixels = kMaxImageSide * kMaxImageSide;

/// Reads an image file: 8-bit gray, RGB or RGBA as they are stored (gray+alpha becomes RGBA),
/// 16-bit gray PNG as kGray16. Throws FileError (file and reason) when the file is missing,
/// unreadable, not an image, or larger than kMaxImageSide / kMaxImagePixels.
Image ReadImage(const std::filesystem::path& path);

/// Writes a PNG (kGray8, kRgb8, kRgba8, kGray16). Writes a temporary file in the same
/// directory and renames it, so a failed or interrupted write leaves no partial file.
/// Throws FileError on failure, InvalidArgument on a format PNG cannot hold.
void WritePng(const ImageView& image, const std::filesystem::path& path);

}  // namespace saccade
