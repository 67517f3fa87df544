#include "saccade/core/image.h"

#include <fmt/format.h>

#include "saccade/core/error.h"

namespace saccade {

int BytesPerPixel(PixelFormat format) {
  switch (format) {
    case PixelFormat::kGray8:
      return 1;
    case PixelFormat::kRgb8:
      return 3;
    case PixelFormat::kRgba8:
      return 4;
    case PixelFormat::kGray16:
      return 2;
    case PixelFormat::kBayerRggb8:
    case PixelFormat::kBayerBggr8:
    case PixelFormat::kBayerGbrg8:
    case PixelFormat::kBayerGrbg8:
      return 1;
    case PixelFormat::kBayerRggb16:
    case PixelFormat::kBayerBggr16:
    case PixelFormat::kBayerGbrg16:
    case PixelFormat::kBayerGrbg16:
      return 2;
    case PixelFormat::kFloat32:
    case PixelFormat::kUint32:
      return 4;
  }
  return 0;
}

const char* ToString(PixelFormat format) {
  switch (format) {
    case PixelFormat::kGray8:
      return "gray8";
    case PixelFormat::kRgb8:
      return "rgb8";
    case PixelFormat::kRgba8:
      return "rgba8";
    case PixelFormat::kGray16:
      return "gray16";
    case PixelFormat::kFloat32:
      return "float32";
    case PixelFormat::kUint32:
      return "uint32";
    case PixelFormat::kBayerRggb8:
      return "bayer_rggb8";
    case PixelFormat::kBayerBggr8:
      return "bayer_bggr8";
    case PixelFormat::kBayerGbrg8:
      return "bayer_gbrg8";
    case PixelFormat::kBayerGrbg8:
      return "bayer_grbg8";
    case PixelFormat::kBayerRggb16:
      return "bayer_rggb16";
    case PixelFormat::kBayerBggr16:
      return "bayer_bggr16";
    case PixelFormat::kBayerGbrg16:
      return "bayer_gbrg16";
    case PixelFormat::kBayerGrbg16:
      return "bayer_grbg16";
  }
  return "unknown";
}

bool IsBayer(PixelFormat format) {
  switch (format) {
    case PixelFormat::kBayerRggb8:
    case PixelFormat::kBayerBggr8:
    case PixelFormat::kBayerGbrg8:
    case PixelFormat::kBayerGrbg8:
    case PixelFormat::kBayerRggb16:
    case PixelFormat::kBayerBggr16:
    case PixelFormat::kBayerGbrg16:
    case PixelFormat::kBayerGrbg16:
      return true;
    default:
      return false;
  }
}

ImageView::ImageView(const uint8_t* data, int width, int height, PixelFormat format,
                     std::size_t stride_bytes, const ImageMetadata* metadata)
    : data_(data),
      width_(width),
      height_(height),
      format_(format),
      stride_(stride_bytes != 0 ? stride_bytes
                                : static_cast<std::size_t>(width) * BytesPerPixel(format)),
      metadata_(metadata) {}

Image::Image(int width, int height, PixelFormat format)
    : width_(width), height_(height), format_(format) {
  if (width < 0 || height < 0) {
    throw InvalidArgument(
        fmt::format("Image: width and height must be >= 0, got {} x {}", width, height));
  }
  pixels_.assign(static_cast<std::size_t>(width) * height * BytesPerPixel(format), 0);
}

Image::Image(int width, int height, PixelFormat format, const uint8_t* pixels, std::size_t stride)
    : width_(width), height_(height), format_(format) {
  if (width < 0 || height < 0) {
    throw InvalidArgument(
        fmt::format("Image: width and height must be >= 0, got {} x {}", width, height));
  }
  const std::size_t row = static_cast<std::size_t>(width) * BytesPerPixel(format);
  if (stride < row) {
    throw InvalidArgument(
        fmt::format("Image: a stride of {} bytes is shorter than a {} x {} {} "
                    "row ({} bytes)",
                    stride, width, height, ToString(format), row));
  }
  if (row * height == 0) return;
  if (stride == row) {
    pixels_.assign(pixels, pixels + row * height);  // one copy, no zero-fill first
    return;
  }
  pixels_.reserve(row * height);
  for (int y = 0; y < height; ++y) {
    const uint8_t* begin = pixels + static_cast<std::size_t>(y) * stride;
    pixels_.insert(pixels_.end(), begin, begin + row);
  }
}

}  // namespace saccade
