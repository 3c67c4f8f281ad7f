#include "weft/scenes/environment_map.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfVersion.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/scenes/lights.h"

namespace weft {

EnvironmentTexels read_environment_exr(const std::filesystem::path& path) {
  const std::string file = path.string();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw Error(file, "", "environment map not found");
  {
    std::ifstream in(path, std::ios::binary);
    char magic[4] = {};
    in.read(magic, 4);
    if (!in || !Imf::isImfMagic(magic)) throw Error(file, "", "not an OpenEXR file");
  }
  EnvironmentTexels t;
  try {
    Imf::InputFile in(file.c_str());
    const Imath::Box2i dw = in.header().dataWindow();
    const int64_t w = int64_t(dw.max.x) - dw.min.x + 1, h = int64_t(dw.max.y) - dw.min.y + 1;
    if (w < 1 || h < 1) throw Error(file, "dataWindow", "is empty");
    // Checked before allocating.
    if (size_t(w) * size_t(h) > kMaxEnvironmentTexels)
      throw Error(file, "dataWindow",
                  std::to_string(w) + " x " + std::to_string(h) + " texels exceed the limit of " +
                      std::to_string(kMaxEnvironmentTexels));
    for (const char* c : {"R", "G", "B"})
      if (!in.header().channels().findChannel(c))
        throw Error(file, c, "channel missing (an RGB OpenEXR environment map is expected)");
    t.width = int(w), t.height = int(h);
    t.rgb.assign(size_t(3) * w * h, 0.0f);
    Imf::FrameBuffer fb;
    const size_t xs = 3 * sizeof(float), ys = xs * size_t(w);
    char* base = reinterpret_cast<char*>(t.rgb.data()) -
                 (int64_t(dw.min.x) * int64_t(xs) + int64_t(dw.min.y) * int64_t(ys));
    fb.insert("R", Imf::Slice(Imf::FLOAT, base, xs, ys));
    fb.insert("G", Imf::Slice(Imf::FLOAT, base + sizeof(float), xs, ys));
    fb.insert("B", Imf::Slice(Imf::FLOAT, base + 2 * sizeof(float), xs, ys));
    in.setFrameBuffer(fb);
    in.readPixels(dw.min.y, dw.max.y);
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw Error(file, "", std::string("cannot read OpenEXR: ") + e.what());
  }
  for (size_t i = 0; i < t.rgb.size(); ++i)
    if (!(std::isfinite(t.rgb[i]) && t.rgb[i] >= 0))
      throw Error(file, "",
                  "texel " + std::to_string(i / 3) +
                      " is negative or not finite; radiance must be finite and >= 0");
  return t;
}

double cie_clear_sky_relative(double zenith, double gamma, double sun_zenith) {
  const double cz = std::cos(zenith);
  if (!(cz > 0)) return 0;
  auto gradation = [](double cos_z) { return 1 - std::exp(-0.32 / cos_z); };
  auto indicatrix = [](double x) {
    const double c = std::cos(x);
    return 1 + 10 * (std::exp(-3 * x) - std::exp(-1.5 * kPi)) + 0.45 * c * c;
  };
  return indicatrix(gamma) * gradation(cz) / (indicatrix(sun_zenith) * gradation(1.0));
}

EnvironmentTexels cie_clear_sky_texels(const Rgb& zenith_radiance, double sun_zenith,
                                       double sun_azimuth, int width, int height) {
  EnvironmentTexels t;
  t.width = width, t.height = height;
  t.rgb.assign(size_t(3) * width * height, 0.0f);
  const Vec3 sun = spherical_direction(sun_zenith, sun_azimuth);
  constexpr int kSub = 4;
  for (int j = 0; j < height; ++j) {
    const double c0 = std::cos(kPi * j / height), c1 = std::cos(kPi * (j + 1) / height);
    for (int i = 0; i < width; ++i) {
      double sum = 0;
      for (int a = 0; a < kSub; ++a)
        for (int b = 0; b < kSub; ++b) {
          const double cz = c0 + (c1 - c0) * (a + 0.5) / kSub;
          const double phi = 2 * kPi * (i + (b + 0.5) / kSub) / width;
          const double z = safe_acos(cz);
          const double gamma = safe_acos(dot(spherical_direction(z, phi), sun));
          sum += cie_clear_sky_relative(z, gamma, sun_zenith);
        }
      const double rel = sum / (kSub * kSub);
      const size_t k = 3 * (size_t(j) * width + i);
      t.rgb[k] = float(rel * zenith_radiance.r);
      t.rgb[k + 1] = float(rel * zenith_radiance.g);
      t.rgb[k + 2] = float(rel * zenith_radiance.b);
    }
  }
  return t;
}

EnvironmentMap::EnvironmentMap(EnvironmentTexels texels, const Frame& frame, const Rgb& scale,
                               const std::string& source) {
  const int w = texels.width, h = texels.height;
  if (w < 1 || h < 1 || texels.rgb.size() != size_t(3) * w * h)
    throw Error(source, "", "environment map has no texels");
  std::vector<double> weights(size_t(w) * h);
  double total = 0;
  for (int j = 0; j < h; ++j) {
    // Solid angle per unit (u, v) area is 2 pi^2 sin(theta); the row's exact share is
    // cos(theta_j) - cos(theta_j+1), which keeps the polar rows' weights exact too.
    const double band = std::cos(kPi * j / h) - std::cos(kPi * (j + 1) / h);
    for (int i = 0; i < w; ++i) {
      const size_t k = size_t(j) * w + i;
      const Rgb L = Rgb(texels.rgb[3 * k], texels.rgb[3 * k + 1], texels.rgb[3 * k + 2]) * scale;
      weights[k] = L.average() * band;
      total += weights[k];
    }
  }
  if (!(total > 0)) throw Error(source, "", "environment map is black (nothing to sample)");
  auto d = std::make_shared<Data>();
  d->texels = std::move(texels);
  d->frame = frame;
  d->scale = scale;
  d->dist = Distribution2D(weights, size_t(w), size_t(h));
  data_ = std::move(d);
}

Vec2 EnvironmentMap::uv_of(const Vec3& dir) const {
  const Vec3 l = data_->frame.to_local(dir);
  double phi = std::atan2(l.y, l.x);
  if (phi < 0) phi += 2 * kPi;
  const double u = std::min(phi / (2 * kPi), std::nextafter(1.0, 0.0));
  const double v = std::min(safe_acos(l.z) / kPi, std::nextafter(1.0, 0.0));
  return {u, v};
}

Rgb EnvironmentMap::radiance(const Vec3& dir) const {
  const EnvironmentTexels& t = data_->texels;
  const Vec2 uv = uv_of(dir);
  const int i = std::min(t.width - 1, int(uv.x * t.width));
  const int j = std::min(t.height - 1, int(uv.y * t.height));
  const size_t k = 3 * (size_t(j) * t.width + i);
  return Rgb(t.rgb[k], t.rgb[k + 1], t.rgb[k + 2]) * data_->scale;
}

double EnvironmentMap::pdf_dir(const Vec3& dir) const {
  const Vec2 uv = uv_of(dir);
  const double sin_theta = std::sin(kPi * uv.y);
  if (!(sin_theta > 0)) return 0;
  // The distribution's texel probability spread over the texel's exact solid angle, so that pdf
  // and the sampled directions agree texel by texel.
  const EnvironmentTexels& t = data_->texels;
  const int j = std::min(t.height - 1, int(uv.y * t.height));
  const double band = std::cos(kPi * j / t.height) - std::cos(kPi * (j + 1) / t.height);
  const double texel_sr = 2 * kPi * band / t.width;
  const double texel_area = 1.0 / (double(t.width) * t.height);
  return data_->dist.pdf(uv) * texel_area / texel_sr;
}

std::optional<LightSample> EnvironmentMap::sample(const Vec3&, Rng& rng) const {
  const Vec2 u{rng.uniform(), rng.uniform()};
  const Distribution2D::Sample s = data_->dist.sample(u);
  const EnvironmentTexels& t = data_->texels;
  // Within the texel, uniform in azimuth and in cos(theta) (uniform in solid angle).
  const int j = std::min(t.height - 1, int(s.p.y * t.height));
  const double fv = s.p.y * t.height - j;
  const double c0 = std::cos(kPi * j / t.height), c1 = std::cos(kPi * (j + 1) / t.height);
  const double cos_theta = c0 + (c1 - c0) * fv;
  const double phi = 2 * kPi * s.p.x;
  const double sin_theta = safe_sqrt(1 - cos_theta * cos_theta);
  const Vec3 local{sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta};
  LightSample out;
  out.wi = normalize(data_->frame.to_world(local));
  const double texel_sr = 2 * kPi * (c0 - c1) / t.width;
  out.pdf = s.pdf / (double(t.width) * t.height) / texel_sr;
  if (!(out.pdf > 0)) return std::nullopt;
  out.L = radiance(out.wi);
  out.at_infinity = true;
  return out;
}

double EnvironmentMap::pdf(const LightHit& hit) const {
  return hit.escaped ? pdf_dir(hit.dir) : 0;
}

Rgb EnvironmentMap::eval(const LightHit& hit) const {
  return hit.escaped ? radiance(hit.dir) : Rgb(0.0);
}

bool EnvironmentMap::is_grey() const {
  const Rgb& s = data_->scale;
  const std::vector<float>& v = data_->texels.rgb;
  bool same = true;
  for (size_t k = 0; same && k + 2 < v.size(); k += 3) {
    same = Rgb(v[k] * s.r, v[k + 1] * s.g, v[k + 2] * s.b).is_grey();
  }
  return same;
}

Rgb EnvironmentMap::integral() const {
  const EnvironmentTexels& t = data_->texels;
  Rgb sum(0.0);
  for (int j = 0; j < t.height; ++j) {
    const double sr =
        2 * kPi * (std::cos(kPi * j / t.height) - std::cos(kPi * (j + 1) / t.height)) / t.width;
    for (int i = 0; i < t.width; ++i) {
      const size_t k = 3 * (size_t(j) * t.width + i);
      sum += Rgb(t.rgb[k], t.rgb[k + 1], t.rgb[k + 2]) * sr;
    }
  }
  return sum * data_->scale;
}

}  // namespace weft
