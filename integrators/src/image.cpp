#include "weft/integrators/image.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>

#include "weft/core/atomic_file.h"
#include "weft/core/error.h"

namespace weft {
namespace {

void write_oiio(const std::filesystem::path& path, const std::string& expected_ext,
                const OIIO::ImageSpec& spec, const void* data) {
  if (path.extension() != expected_ext)
    throw Error(path.string(), "", "output must end in " + expected_ext);
  write_atomically(path, [&](const std::filesystem::path& tmp) {
    auto out = OIIO::ImageOutput::create(tmp.string());
    if (!out) throw Error(path.string(), "", "no image writer: " + OIIO::geterror());
    if (!out->open(tmp.string(), spec))
      throw Error(path.string(), "", "cannot open: " + out->geterror());
    if (!out->write_image(spec.format, data))
      throw Error(path.string(), "", "write failed: " + out->geterror());
    if (!out->close()) throw Error(path.string(), "", "close failed: " + out->geterror());
  });
}

}  // namespace

void write_exr(const std::filesystem::path& path, const Image& image) {
  OIIO::ImageSpec spec(image.width, image.height, 3, OIIO::TypeDesc::FLOAT);
  spec.attribute("compression", "zip");
  spec.attribute("weft:content", "linear RGB radiance");
  write_oiio(path, ".exr", spec, image.rgb.data());
}

void write_png_preview(const std::filesystem::path& path, const Image& image, double exposure) {
  std::vector<uint8_t> px(image.rgb.size());
  for (size_t i = 0; i < px.size(); ++i) {
    const double v =
        std::clamp(linear_to_srgb_gamma(std::max(0.0, image.rgb[i] * exposure)), 0.0, 1.0);
    px[i] = static_cast<uint8_t>(std::lround(v * 255.0));
  }
  OIIO::ImageSpec spec(image.width, image.height, 3, OIIO::TypeDesc::UINT8);
  write_oiio(path, ".png", spec, px.data());
}

void write_mask_exr(const std::filesystem::path& path, int width, int height,
                    const std::vector<float>& values) {
  if (values.size() != size_t(width) * height) throw Error(path.string(), "", "mask size mismatch");
  OIIO::ImageSpec spec(width, height, 1, OIIO::TypeDesc::FLOAT);
  spec.channelnames = {"Y"};
  spec.attribute("compression", "zip");
  write_oiio(path, ".exr", spec, values.data());
}

Image read_image(const std::filesystem::path& path) {
  auto in = OIIO::ImageInput::open(path.string());
  if (!in) throw Error(path.string(), "", "cannot read image: " + OIIO::geterror());
  const auto& spec = in->spec();
  if (spec.nchannels < 3) throw Error(path.string(), "", "needs at least 3 channels");
  std::vector<float> all(size_t(spec.width) * spec.height * spec.nchannels);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, all.data()))
    throw Error(path.string(), "", "read failed: " + in->geterror());
  Image img(spec.width, spec.height);
  for (size_t p = 0; p < size_t(spec.width) * spec.height; ++p)
    for (int c = 0; c < 3; ++c) img.rgb[3 * p + c] = all[p * spec.nchannels + c];
  return img;
}

}  // namespace weft
