// Textures from image files (saccade::ReadImage) and from memory (embedded in model files:
// stb_image, whose implementation libstb provides; core compiles its own static copy).

#include <fmt/format.h>
#include <stb/stb_image.h>

#include <cstring>
#include <limits>
#include <utility>

#include "internal_assets.h"
#include "saccade/core/error.h"
#include "saccade/core/image_io.h"

namespace saccade::scene::internal {

Image ToTextureImage(Image image) {
  if (image.format() == PixelFormat::kRgb8 || image.format() == PixelFormat::kRgba8) return image;
  Image rgb(image.width(), image.height(), PixelFormat::kRgb8);
  for (int y = 0; y < image.height(); ++y) {
    const uint8_t* in = image.row(y);
    uint8_t* out = rgb.row(y);
    for (int x = 0; x < image.width(); ++x) {
      uint8_t gray = 0;
      switch (image.format()) {
        case PixelFormat::kGray8:
          gray = in[x];
          break;
        case PixelFormat::kGray16: {
          uint16_t value = 0;
          std::memcpy(&value, in + 2 * x, sizeof(value));
          gray = static_cast<uint8_t>(value >> 8);
          break;
        }
        default:
          throw InvalidArgument(fmt::format("ToTextureImage: cannot use a {} image as a texture",
                                            ToString(image.format())));
      }
      out[3 * x] = out[3 * x + 1] = out[3 * x + 2] = gray;
    }
  }
  return rgb;
}

std::shared_ptr<const Texture> LoadTexture(const std::filesystem::path& canonical_path,
                                           AssetCache& cache) {
  const std::string key = canonical_path.string();
  if (const auto it = cache.textures.find(key); it != cache.textures.end()) return it->second;
  Image image = ReadImage(canonical_path);  // FileError naming the file
  if (image.empty()) throw FileError(key, 0, "", "the image has no pixels");
  auto texture = std::make_shared<const Texture>(Texture{key, ToTextureImage(std::move(image))});
  cache.textures.emplace(key, texture);
  return texture;
}

std::shared_ptr<const Texture> DecodeTexture(const uint8_t* data, std::size_t size,
                                             const std::string& source) {
  if (data == nullptr || size == 0 ||
      size > static_cast<std::size_t>(std::numeric_limits<int>::max())) {
    throw FileError(source, 0, "", fmt::format("not a readable image ({} bytes)", size));
  }
  const int length = static_cast<int>(size);
  int width = 0, height = 0, channels = 0;
  if (!stbi_info_from_memory(data, length, &width, &height, &channels)) {
    throw FileError(source, 0, "", fmt::format("not a readable image: {}", stbi_failure_reason()));
  }
  if (width > kMaxImageSide || height > kMaxImageSide ||
      int64_t{width} * height > kMaxImagePixels) {
    throw FileError(source, 0, "",
                    fmt::format("the embedded image is {}x{} px, larger than saccade reads ({} px "
                                "a side; core/image_io.h)",
                                width, height, kMaxImageSide));
  }
  const int wanted = (channels == 2 || channels == 4) ? 4 : 3;
  std::unique_ptr<stbi_uc, void (*)(void*)> pixels(
      stbi_load_from_memory(data, length, &width, &height, &channels, wanted), stbi_image_free);
  if (!pixels || width <= 0 || height <= 0) {
    throw FileError(source, 0, "", fmt::format("not a readable image: {}", stbi_failure_reason()));
  }
  Image image(width, height, wanted == 4 ? PixelFormat::kRgba8 : PixelFormat::kRgb8);
  std::memcpy(image.data(), pixels.get(), image.size_bytes());
  return std::make_shared<const Texture>(Texture{source, std::move(image)});
}

}  // namespace saccade::scene::internal
