#include "weft/integrators/image.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "image_hdr.h"
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

std::array<float, 16> world_to_camera_matrix(const Camera& c) {
  // Columns are the camera axes; the last row moves the camera to the origin.
  const Vec3 axes[3] = {c.right, c.up, c.forward};
  std::array<float, 16> m{};
  for (int j = 0; j < 3; ++j) {
    m[0 * 4 + j] = static_cast<float>(axes[j].x);
    m[1 * 4 + j] = static_cast<float>(axes[j].y);
    m[2 * 4 + j] = static_cast<float>(axes[j].z);
    m[3 * 4 + j] = static_cast<float>(-dot(c.position, axes[j]));
  }
  m[15] = 1;
  return m;
}

std::array<float, 16> world_to_ndc_matrix(const Camera& c, int film_width, int film_height) {
  // Camera space to NDC, inverting Camera::generate_ray: perspective x / z = (2 fx - 1) tan(fov/2)
  // aspect and y / z = (1 - 2 fy) tan(fov/2), with w = z (and z' = 1, so z'/w is 1/depth);
  // orthographic x = (2 fx - 1) half_width, y = (1 - 2 fy) half_height, w = 1.
  double p[4][4] = {};
  if (c.type == Camera::Type::perspective) {
    const double th = std::tan(0.5 * c.yfov_rad), aspect = double(film_width) / film_height;
    p[0][0] = 0.5 / (th * aspect);
    p[1][1] = -0.5 / th;
    p[2][0] = 0.5, p[2][1] = 0.5, p[2][3] = 1;
    p[3][2] = 1;
  } else {
    p[0][0] = 0.5 / c.half_width;
    p[1][1] = -0.5 / c.half_height;
    p[2][2] = 1;
    p[3][0] = 0.5, p[3][1] = 0.5, p[3][3] = 1;
  }
  const std::array<float, 16> v = world_to_camera_matrix(c);
  std::array<float, 16> m{};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      double sum = 0;
      for (int k = 0; k < 4; ++k) sum += double(v[i * 4 + k]) * p[k][j];
      m[i * 4 + j] = static_cast<float>(sum);
    }
  return m;
}

void write_exr(const std::filesystem::path& path, const Image& image, const RenderMetadata* meta) {
  OIIO::ImageSpec spec(image.width, image.height, 3, OIIO::TypeDesc::FLOAT);
  if (image.film_width > 0) {
    spec.x = image.x0, spec.y = image.y0;
    spec.full_x = 0, spec.full_y = 0;
    spec.full_width = image.film_width, spec.full_height = image.film_height;
  }
  spec.attribute("compression", "zip");
  // OpenImageIO adds the time of writing unless DateTime is set; empty, it writes none, so that
  // the same render gives the same bytes.
  spec.attribute("DateTime", "");
  // sRGB / Rec. 709 primaries and the D65 white point (IEC 61966-2-1), x and y of R, G, B, white.
  const float chromaticities[8] = {0.64f, 0.33f, 0.30f, 0.60f, 0.15f, 0.06f, 0.3127f, 0.3290f};
  spec.attribute("chromaticities", OIIO::TypeDesc(OIIO::TypeDesc::FLOAT, 8), chromaticities);
  spec.attribute("weft:version", WEFT_VERSION);
  spec.attribute("weft:content", meta && !meta->pass.empty() ? meta->pass : "linear RGB radiance");
  if (meta) {
    spec.attribute("weft:scene", meta->scene);
    if (!meta->camera_name.empty()) spec.attribute("weft:camera", meta->camera_name);
    spec.attribute("weft:seed", std::to_string(meta->seed));
    spec.attribute("weft:spp", meta->spp);
    spec.attribute("weft:spp_requested", meta->spp_requested);
    if (meta->time_limit_s > 0) spec.attribute("weft:time_limit_s", float(meta->time_limit_s));
    if (meta->camera) {
      const int fw = image.film_width > 0 ? image.film_width : image.width;
      const int fh = image.film_height > 0 ? image.film_height : image.height;
      const auto w2c = world_to_camera_matrix(*meta->camera);
      const auto w2n = world_to_ndc_matrix(*meta->camera, fw, fh);
      spec.attribute("worldToCamera", OIIO::TypeMatrix44, w2c.data());
      spec.attribute("worldToNDC", OIIO::TypeMatrix44, w2n.data());
    }
  }
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

void write_hdr(const std::filesystem::path& path, const Image& image) {
  std::vector<float> px(image.rgb.size());
  for (size_t i = 0; i < px.size(); ++i) px[i] = std::max(0.0f, image.rgb[i]);
  OIIO::ImageSpec spec(image.width, image.height, 3, OIIO::TypeDesc::FLOAT);
  write_oiio(path, ".hdr", spec, px.data());
}

void write_mask_exr(const std::filesystem::path& path, int width, int height,
                    const std::vector<float>& values) {
  if (values.size() != size_t(width) * height) throw Error(path.string(), "", "mask size mismatch");
  OIIO::ImageSpec spec(width, height, 1, OIIO::TypeDesc::FLOAT);
  spec.channelnames = {"Y"};
  spec.attribute("compression", "zip");
  write_oiio(path, ".exr", spec, values.data());
}

nlohmann::json read_image_metadata(const std::filesystem::path& path) {
  auto in = OIIO::ImageInput::open(path.string());
  if (!in) throw Error(path.string(), "", "cannot read image: " + OIIO::geterror());
  nlohmann::json j = nlohmann::json::object();
  for (const auto& a : in->spec().extra_attribs) {
    const OIIO::TypeDesc t = a.type();
    if (t == OIIO::TypeString) {
      j[a.name().string()] = std::string(a.get_string());
    } else if (t.basetype == OIIO::TypeDesc::FLOAT || t.basetype == OIIO::TypeDesc::INT ||
               t.basetype == OIIO::TypeDesc::DOUBLE || t.basetype == OIIO::TypeDesc::UINT) {
      const int n = static_cast<int>(t.numelements() * t.aggregate);
      // The raw values: ParamValue's converting getters do not index into matrices.
      auto element = [&](int i) -> nlohmann::json {
        switch (t.basetype) {
          case OIIO::TypeDesc::INT:
            return static_cast<const int32_t*>(a.data())[i];
          case OIIO::TypeDesc::UINT:
            return static_cast<const uint32_t*>(a.data())[i];
          case OIIO::TypeDesc::DOUBLE:
            return static_cast<const double*>(a.data())[i];
          default:
            return static_cast<const float*>(a.data())[i];
        }
      };
      if (n == 1) {
        j[a.name().string()] = element(0);
      } else {
        nlohmann::json arr = nlohmann::json::array();
        for (int i = 0; i < n; ++i) arr.push_back(element(i));
        j[a.name().string()] = arr;
      }
    }
  }
  return j;
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
  if (spec.x != 0 || spec.y != 0 || spec.full_width != spec.width ||
      spec.full_height != spec.height)
    img.x0 = spec.x, img.y0 = spec.y, img.film_width = spec.full_width,
    img.film_height = spec.full_height;
  for (size_t p = 0; p < size_t(spec.width) * spec.height; ++p)
    for (int c = 0; c < 3; ++c) img.rgb[3 * p + c] = all[p * spec.nchannels + c];
  return img;
}

}  // namespace weft
