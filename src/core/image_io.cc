#include "saccade/core/image_io.h"

#include <fmt/format.h>
#include <png.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>

#include "saccade/core/error.h"
#include "saccade/core/temporary_file.h"

#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STBI_FAILURE_USERMSG
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wsign-compare"
#include <stb_image.h>
#pragma GCC diagnostic pop

namespace saccade {
namespace {

struct FileCloser {
  void operator()(FILE* f) const {
    if (f != nullptr) std::fclose(f);
  }
};
using File = std::unique_ptr<FILE, FileCloser>;

// libpng reports errors by longjmp back here: nothing in this frame is modified after the
// setjmp, so nothing can be clobbered.
bool EncodePng(png_structp png, png_infop info, FILE* file, const ImageView& image, int bit_depth,
               int color_type) {
  if (setjmp(png_jmpbuf(png)) != 0) return false;
  png_init_io(png, file);
  png_set_compression_level(png, 1);  // fast: frames are written at render rate
  png_set_IHDR(png, info, image.width(), image.height(), bit_depth, color_type, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  if (bit_depth == 16) png_set_swap(png);  // PNG is big-endian; our pixels are host order
  for (int y = 0; y < image.height(); ++y) png_write_row(png, const_cast<png_bytep>(image.row(y)));
  png_write_end(png, nullptr);
  return true;
}

// The image's size as its header states it, against kMaxImageSide and kMaxImagePixels, before
// anything is decoded or allocated. A PNG's IHDR is read here (stb gives up on some lying
// headers with a message that hides the size); other formats through stbi_info.
void CheckImageHeader(FILE* file, const std::string& name) {
  std::array<unsigned char, 24> head{};
  const std::size_t got = std::fread(head.data(), 1, head.size(), file);
  std::fseek(file, 0, SEEK_SET);
  int64_t width = -1, height = -1;
  static constexpr std::array<unsigned char, 8> kPngSignature = {0x89, 'P',  'N',  'G',
                                                                 '\r', '\n', 0x1a, '\n'};
  if (got == head.size() && std::equal(kPngSignature.begin(), kPngSignature.end(), head.begin()) &&
      std::memcmp(head.data() + 12, "IHDR", 4) == 0) {
    const auto be32 = [&](int at) {
      return (int64_t{head[at]} << 24) | (int64_t{head[at + 1]} << 16) |
             (int64_t{head[at + 2]} << 8) | int64_t{head[at + 3]};
    };
    width = be32(16);
    height = be32(20);
  } else {
    int w = 0, h = 0, channels = 0;
    if (stbi_info_from_file(file, &w, &h, &channels)) {
      width = w;
      height = h;
    }
    std::fseek(file, 0, SEEK_SET);
  }
  if (width > kMaxImageSide || height > kMaxImageSide || width * height > kMaxImagePixels) {
    throw FileError(name, 0, "",
                    fmt::format("the image is {}x{} px, larger than saccade reads ({} px a side, "
                                "{} Mpx; core/image_io.h)",
                                width, height, kMaxImageSide, kMaxImagePixels / 1'000'000));
  }
}

}  // namespace

Image ReadImage(const std::filesystem::path& path) {
  const std::string name = path.string();
  File file(std::fopen(name.c_str(), "rb"));
  if (!file) throw FileError(name, 0, "", fmt::format("cannot open: {}", std::strerror(errno)));
  CheckImageHeader(file.get(), name);
  int width = 0, height = 0, channels = 0;
  if (stbi_is_16_bit_from_file(file.get())) {
    std::fseek(file.get(), 0, SEEK_SET);
    std::unique_ptr<stbi_us, void (*)(void*)> pixels(
        stbi_load_from_file_16(file.get(), &width, &height, &channels, 1), stbi_image_free);
    if (!pixels)
      throw FileError(name, 0, "", fmt::format("not a readable image: {}", stbi_failure_reason()));
    Image image(width, height, PixelFormat::kGray16);
    std::memcpy(image.data(), pixels.get(), image.size_bytes());
    return image;
  }
  std::fseek(file.get(), 0, SEEK_SET);
  if (!stbi_info_from_file(file.get(), &width, &height, &channels)) {
    throw FileError(name, 0, "", fmt::format("not a readable image: {}", stbi_failure_reason()));
  }
  // Gray stays gray, RGB stays RGB, anything with alpha becomes RGBA.
  const int wanted = channels == 1 ? 1 : (channels == 3 ? 3 : 4);
  const PixelFormat format =
      wanted == 1 ? PixelFormat::kGray8 : (wanted == 3 ? PixelFormat::kRgb8 : PixelFormat::kRgba8);
  std::unique_ptr<stbi_uc, void (*)(void*)> pixels(
      stbi_load_from_file(file.get(), &width, &height, &channels, wanted), stbi_image_free);
  if (!pixels)
    throw FileError(name, 0, "", fmt::format("not a readable image: {}", stbi_failure_reason()));
  Image image(width, height, format);
  std::memcpy(image.data(), pixels.get(), image.size_bytes());
  return image;
}

void WritePng(const ImageView& image, const std::filesystem::path& path) {
  const std::string name = path.string();
  int color_type = 0, bit_depth = 8;
  switch (image.format()) {
    case PixelFormat::kGray8:
      color_type = PNG_COLOR_TYPE_GRAY;
      break;
    case PixelFormat::kRgb8:
      color_type = PNG_COLOR_TYPE_RGB;
      break;
    case PixelFormat::kRgba8:
      color_type = PNG_COLOR_TYPE_RGBA;
      break;
    case PixelFormat::kGray16:
      color_type = PNG_COLOR_TYPE_GRAY;
      bit_depth = 16;
      break;
    default:
      throw InvalidArgument(
          fmt::format("WritePng: {}: PNG cannot hold {} pixels", name, ToString(image.format())));
  }
  if (image.empty()) throw InvalidArgument(fmt::format("WritePng: {}: empty image", name));

  static std::atomic<unsigned> counter{0};
  const std::filesystem::path temporary = TemporaryPathFor(path, counter++);
  File file(std::fopen(temporary.c_str(), "wb"));
  if (!file) throw FileError(name, 0, "", fmt::format("cannot write: {}", std::strerror(errno)));

  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png != nullptr ? png_create_info_struct(png) : nullptr;
  const bool ok = info != nullptr && EncodePng(png, info, file.get(), image, bit_depth, color_type);
  png_destroy_write_struct(&png, &info);
  // The rename makes the file appear whole or not at all if the process dies; no fsync: frames
  // are written at render rate and power loss is not what this guards against.
  const bool flushed = ok && std::fflush(file.get()) == 0;
  file.reset();
  if (!flushed) {
    std::filesystem::remove(temporary);
    throw FileError(name, 0, "", "cannot write the PNG (disk full or I/O error)");
  }
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) {
    std::filesystem::remove(temporary);
    throw FileError(name, 0, "", fmt::format("cannot rename into place: {}", error.message()));
  }
}

}  // namespace saccade
