#pragma once
// Linear RGB images and their files: OpenEXR (float, through OpenImageIO) and an sRGB PNG preview,
// each written atomically (whole or not at all).
#include <filesystem>
#include <vector>

#include "weft/core/spectrum.h"

namespace weft {

struct Image {
  int width = 0, height = 0;
  std::vector<float> rgb;  // row-major, top row first, 3 floats per pixel

  Image() = default;
  Image(int w, int h) : width(w), height(h), rgb(size_t(3) * w * h, 0.0f) {}
  Rgb at(int x, int y) const {
    const size_t i = 3 * (size_t(y) * width + x);
    return {rgb[i], rgb[i + 1], rgb[i + 2]};
  }
};

// Linear float RGB OpenEXR.
void write_exr(const std::filesystem::path& path, const Image& image);
// 8-bit sRGB PNG: linear values times 'exposure', clipped to [0, 1] (a preview, not data).
void write_png_preview(const std::filesystem::path& path, const Image& image,
                       double exposure = 1.0);
// Single-channel float OpenEXR (channel "Y") with one value per pixel.
void write_mask_exr(const std::filesystem::path& path, int width, int height,
                    const std::vector<float>& values);
// Reads an RGB(A) image as linear floats (for tests and tools).
Image read_image(const std::filesystem::path& path);

}  // namespace weft
