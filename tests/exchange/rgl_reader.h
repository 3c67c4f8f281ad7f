#pragma once
// An independent reader of RGL .bsdf files for the tests, written from the format as Mitsuba 3
// (src/core/tensor.cpp, src/bsdfs/measured.cpp) and pbrt-v4 (MeasuredBxDF) read it, sharing no
// code with the writer: its own byte parsing of the tensor file, and the renderers' evaluation
// f cos theta_o = spectra(R^-1(u_m)) D(u_m) / (4 sigma(u_wi)), where R^-1 inverts the VNDF's
// continuous piecewise-bilinear warp (marginal CDF in y, conditional in x; each theta_i slice
// normalized, then slices blended linearly in theta_i). Checked against the format authors'
// reader (powitacq.h, rgl-epfl/brdf-loader): it blends the normalized vndf slices and their CDFs
// with the same linear weights in theta_i (clamped, the interval whose lower node is <= theta_i),
// inverts the warp the same way, interpolates the values bilinearly without normalizing them,
// and divides by 4 sigma(u_i) and multiplies by D(u_m) on the same two-row (u, phi) grids.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include "weft/core/math.h"
#include "weft/core/vec.h"

namespace weft::testing {

struct RglField {
  int dtype = 0;
  std::vector<uint64_t> shape;
  uint64_t offset = 0;
  std::vector<float> f;  // float32 fields
  std::string bytes;     // uint8 fields
};

inline std::map<std::string, RglField> read_rgl(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  const std::string d{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  size_t at = 0;
  auto take = [&](size_t n) {
    if (at + n > d.size()) throw std::runtime_error("truncated");
    const char* p = d.data() + at;
    at += n;
    return p;
  };
  auto u = [&](size_t n) {
    uint64_t v = 0;
    const auto* p = reinterpret_cast<const unsigned char*>(take(n));
    for (size_t k = 0; k < n; ++k) v |= static_cast<uint64_t>(p[k]) << (8 * k);
    return v;
  };
  if (std::string(take(12), 12) != std::string("tensor_file\0", 12))
    throw std::runtime_error("magic");
  if (u(1) != 1 || u(1) != 0) throw std::runtime_error("version");
  const uint64_t n = u(4);
  std::map<std::string, RglField> fields;
  for (uint64_t k = 0; k < n; ++k) {
    const uint64_t length = u(2);
    const std::string nm(take(length), length);
    RglField f;
    const uint64_t rank = u(2);
    f.dtype = static_cast<int>(u(1));
    f.offset = u(8);
    for (uint64_t r = 0; r < rank; ++r) f.shape.push_back(u(8));
    fields[nm] = f;
  }
  for (auto& [name, f] : fields) {
    uint64_t count = 1;
    for (uint64_t s : f.shape) count *= s;
    const size_t size = f.dtype == 10 ? 4 : 1;
    if (f.offset + count * size > d.size()) throw std::runtime_error("data past the end");
    if (f.dtype == 10) {
      f.f.resize(count);
      std::memcpy(f.f.data(), d.data() + f.offset, count * 4);
    } else {
      f.bytes = d.substr(f.offset, count);
    }
  }
  return fields;
}

class RglEvaluator {
 public:
  explicit RglEvaluator(std::map<std::string, RglField> f) : f_(std::move(f)) {
    values_ = f_.count("spectra") ? &f_.at("spectra") : &f_.at("rgb");
    const auto& v = f_.at("vndf");
    h_ = static_cast<int>(v.shape[2]);
    w_ = static_cast<int>(v.shape[3]);
    for (size_t k = 0; k < v.shape[1]; ++k) slices_.push_back(normalized_slice(k));
  }
  // f cos theta_light for view 'wv' and light 'wl' (both unit, local frame), channel c.
  double eval(Vec3 wv, Vec3 wl, int c) const {
    if (wv.z <= 0 || wl.z <= 0) return 0;
    const Vec3 m = normalize(wv + wl);
    const double th_i = std::acos(std::min(1.0, wv.z)), ph_i = std::atan2(wv.y, wv.x);
    const double th_m = std::acos(std::min(1.0, m.z)), ph_m = std::atan2(m.y, m.x);
    double um_y = (ph_m - ph_i + kPi) / (2 * kPi);
    um_y -= std::floor(um_y);
    const double um_x = std::sqrt(th_m * 2 / kPi), ui_x = std::sqrt(th_i * 2 / kPi);
    const auto& ti = f_.at("theta_i").f;
    size_t k = 0;
    while (k + 2 < ti.size() && ti[k + 1] < th_i) ++k;
    const double w1 = std::clamp((th_i - ti[k]) / (ti[k + 1] - ti[k]), 0.0, 1.0);
    const auto [sx, sy] = invert(k, w1, um_x, um_y);
    const int ns = static_cast<int>(values_->shape[3]), nc = static_cast<int>(values_->shape[2]);
    auto value = [&](size_t slice) {
      const size_t base = (slice * static_cast<size_t>(nc) + static_cast<size_t>(c)) * ns * ns;
      return bilinear(values_->f.data() + base, ns, ns, sx, sy);
    };
    const double spec = (1 - w1) * value(k) + w1 * value(k + 1);
    const auto& ndf = f_.at("ndf");
    const auto& sigma = f_.at("sigma");
    const int nn = static_cast<int>(ndf.shape[1]);
    const double d = bilinear(ndf.f.data(), nn, 2, um_x, um_y);
    const double s = bilinear(sigma.f.data(), nn, 2, ui_x, (ph_i + kPi) / (2 * kPi));
    return spec * d / (4 * s);
  }

 private:
  struct Slice {
    std::vector<double> v, cond, marg;  // density, per-row CDF in x (w per row), CDF in y
  };
  Slice normalized_slice(size_t k) const {
    const auto& vndf = f_.at("vndf").f;
    Slice s;
    s.v.assign(vndf.begin() + static_cast<long>(k * w_ * h_),
               vndf.begin() + static_cast<long>((k + 1) * w_ * h_));
    const double dx = 1.0 / (w_ - 1), dy = 1.0 / (h_ - 1);
    s.cond.assign(s.v.size(), 0);
    for (int y = 0; y < h_; ++y)
      for (int x = 1; x < w_; ++x)
        s.cond[y * w_ + x] =
            s.cond[y * w_ + x - 1] + dx * 0.5 * (s.v[y * w_ + x - 1] + s.v[y * w_ + x]);
    s.marg.assign(static_cast<size_t>(h_), 0);
    for (int y = 1; y < h_; ++y)
      s.marg[y] =
          s.marg[y - 1] + dy * 0.5 * (s.cond[(y - 1) * w_ + w_ - 1] + s.cond[y * w_ + w_ - 1]);
    const double total = s.marg.back();
    for (auto* a : {&s.v, &s.cond, &s.marg})
      for (double& x : *a) x /= total;
    return s;
  }
  // The sample-space point of u_m: the CDFs of the blended slices at u_m.
  std::pair<double, double> invert(size_t k, double w1, double ux, double uy) const {
    const Slice &a = slices_[k], &b = slices_[k + 1];
    auto V = [&](int x, int y) { return (1 - w1) * a.v[y * w_ + x] + w1 * b.v[y * w_ + x]; };
    auto C = [&](int x, int y) { return (1 - w1) * a.cond[y * w_ + x] + w1 * b.cond[y * w_ + x]; };
    auto M = [&](int y) { return (1 - w1) * a.marg[y] + w1 * b.marg[y]; };
    const double px = std::clamp(ux, 0.0, 1.0) * (w_ - 1), py = std::clamp(uy, 0.0, 1.0) * (h_ - 1);
    const int cx = std::min(static_cast<int>(px), w_ - 2),
              cy = std::min(static_cast<int>(py), h_ - 2);
    const double fx = px - cx, fy = py - cy, dx = 1.0 / (w_ - 1), dy = 1.0 / (h_ - 1);
    const double c0 = V(cx, cy) + (V(cx, cy + 1) - V(cx, cy)) * fy;
    const double c1 = V(cx + 1, cy) + (V(cx + 1, cy + 1) - V(cx + 1, cy)) * fy;
    const double row_cdf = C(cx, cy) + (C(cx, cy + 1) - C(cx, cy)) * fy;
    const double row_total = C(w_ - 1, cy) + (C(w_ - 1, cy + 1) - C(w_ - 1, cy)) * fy;
    const double x = (row_cdf + dx * (c0 * fx + 0.5 * (c1 - c0) * fx * fx)) / row_total;
    const double r0 = C(w_ - 1, cy), r1 = C(w_ - 1, cy + 1);
    const double y = M(cy) + dy * (r0 * fy + 0.5 * (r1 - r0) * fy * fy);
    return {x, y / M(h_ - 1)};
  }
  static double bilinear(const float* g, int w, int h, double x, double y) {
    const double px = std::clamp(x, 0.0, 1.0) * (w - 1), py = std::clamp(y, 0.0, 1.0) * (h - 1);
    const int cx = std::min(static_cast<int>(px), w - 2),
              cy = std::min(static_cast<int>(py), h - 2);
    const double fx = px - cx, fy = py - cy;
    return (1 - fy) * ((1 - fx) * g[cy * w + cx] + fx * g[cy * w + cx + 1]) +
           fy * ((1 - fx) * g[(cy + 1) * w + cx] + fx * g[(cy + 1) * w + cx + 1]);
  }
  std::map<std::string, RglField> f_;
  const RglField* values_;
  int w_ = 0, h_ = 0;
  std::vector<Slice> slices_;
};

}  // namespace weft::testing
