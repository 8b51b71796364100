// PNG files through libpng's simplified API (png_image_*), which handles
// every colour type and bit depth on reading and reports errors as messages
// instead of longjmp.
#include <png.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>

#include "client/viewer/rgba_image.h"

namespace meshstream::client {

Status write_png(const std::string& path, const RgbaImage& image) {
  if (image.width <= 0 || image.height <= 0 ||
      image.rgba.size() != static_cast<size_t>(image.width) * image.height * 4) {
    return make_error(ErrorCode::kInvalidArgument,
                      path + ": image buffer does not match its size " +
                          std::to_string(image.width) + "x" + std::to_string(image.height));
  }
  png_image png;
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  png.width = static_cast<png_uint_32>(image.width);
  png.height = static_cast<png_uint_32>(image.height);
  png.format = PNG_FORMAT_RGBA;
  if (!png_image_write_to_file(&png, path.c_str(), 0, image.rgba.data(), 0, nullptr)) {
    std::string message = path + ": cannot write PNG: " + png.message;
    png_image_free(&png);
    return make_error(ErrorCode::kIo, message);
  }
  return {};
}

Result<RgbaImage> read_png(const std::string& path) {
  if (FILE* file = std::fopen(path.c_str(), "rb")) {
    std::fclose(file);
  } else {
    return make_error(ErrorCode::kIo, path + ": cannot open: " + std::strerror(errno));
  }
  png_image png;
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&png, path.c_str())) {
    std::string message = path + ": not a readable PNG: " + png.message;
    png_image_free(&png);
    return make_error(ErrorCode::kParse, message);
  }
  png.format = PNG_FORMAT_RGBA;
  RgbaImage image;
  image.width = static_cast<int>(png.width);
  image.height = static_cast<int>(png.height);
  image.rgba.resize(PNG_IMAGE_SIZE(png));
  if (!png_image_finish_read(&png, nullptr, image.rgba.data(), 0, nullptr)) {
    std::string message = path + ": corrupt PNG: " + png.message;
    png_image_free(&png);
    return make_error(ErrorCode::kParse, message);
  }
  return image;
}

void flip_rows(RgbaImage& image) {
  size_t row = static_cast<size_t>(image.width) * 4;
  for (int top = 0, bottom = image.height - 1; top < bottom; ++top, --bottom) {
    std::swap_ranges(image.rgba.begin() + top * row, image.rgba.begin() + (top + 1) * row,
                     image.rgba.begin() + bottom * row);
  }
}

}  // namespace meshstream::client
