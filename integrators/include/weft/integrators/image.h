#pragma once
// Linear RGB images and their files: OpenEXR (float, through OpenImageIO) and an sRGB PNG preview,
// each written atomically (whole or not at all).
#include <array>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "weft/core/spectrum.h"
#include "weft/scenes/camera.h"

namespace weft {

struct Image {
  int width = 0, height = 0;
  std::vector<float> rgb;  // row-major, top row first, 3 floats per pixel
  // Where these pixels lie on the whole film (OpenEXR's data window inside its display window):
  // a crop window's image starts at (x0, y0) of a film_width x film_height film; 0 = this image.
  int x0 = 0, y0 = 0, film_width = 0, film_height = 0;

  Image() = default;
  Image(int w, int h) : width(w), height(h), rgb(size_t(3) * w * h, 0.0f) {}
  Rgb at(int x, int y) const {
    const size_t i = 3 * (size_t(y) * width + x);
    return {rgb[i], rgb[i + 1], rgb[i + 2]};
  }
};

// What a render's EXR says about how it was made (header attributes; every run of the same inputs
// writes the same bytes: no date, no host, no path above the scene's file name).
struct RenderMetadata {
  std::string scene;             // "weft:scene": the description's file name
  std::string camera_name;       // "weft:camera": as --camera chose it ("" = the description's)
  uint64_t seed = 0;             // "weft:seed" (decimal string: OpenEXR has no 64-bit integer)
  int spp = 0;                   // "weft:spp": samples per pixel in the image
  int spp_requested = 0;         // "weft:spp_requested": less than spp only when time-limited
  double time_limit_s = 0;       // "weft:time_limit_s" (0: none, and not written)
  std::optional<Camera> camera;  // "worldToCamera", "worldToNDC" (OpenEXR standard attributes)
  std::string pass;              // "weft:content": "linear RGB radiance", "albedo", "normal"
};

// OpenEXR's standard matrices (row vectors, p' = p M, Imath's convention) of a camera on a
// film_width x film_height film. worldToCamera: x right, y up, z the viewing direction, origin
// at the camera. worldToNDC: NDC (0, 0) is the film's upper-left corner and (1, 1) its
// lower-right after the divide by w, as Camera::generate_ray's (fx, fy).
std::array<float, 16> world_to_camera_matrix(const Camera& camera);
std::array<float, 16> world_to_ndc_matrix(const Camera& camera, int film_width, int film_height);

// Linear float RGB OpenEXR (zip), deterministic bytes. Always: "chromaticities" (sRGB/Rec. 709
// primaries, D65 white: the RGB of core/spectrum.h) and "weft:version"; the render's metadata
// when given. A crop window's image is the data window inside the film's display window.
void write_exr(const std::filesystem::path& path, const Image& image,
               const RenderMetadata* metadata = nullptr);
// 8-bit sRGB PNG: linear values times 'exposure', clipped to [0, 1], then the sRGB transfer
// curve (IEC 61966-2-1); no other tone mapping (a preview, not data).
void write_png_preview(const std::filesystem::path& path, const Image& image,
                       double exposure = 1.0);
// Single-channel float OpenEXR (channel "Y") with one value per pixel.
void write_mask_exr(const std::filesystem::path& path, int width, int height,
                    const std::vector<float>& values);
// Reads an RGB(A) image as linear floats (for tests and tools).
Image read_image(const std::filesystem::path& path);
// An image file's header attributes: strings as strings, numbers, and numeric arrays (matrices
// row by row) as lists of numbers (for tests and tools).
nlohmann::json read_image_metadata(const std::filesystem::path& path);

}  // namespace weft
