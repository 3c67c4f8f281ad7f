#include "weft/exchange/rgl_bsdf.h"

#include <algorithm>
#include <cmath>

#include "marginal_warp.h"
#include "tensor_file.h"
#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/core/frame.h"
#include "weft/core/math.h"
#include "weft/exchange/table_view.h"

namespace weft {
namespace {

// The format's square: u_theta = sqrt(2 theta / pi), u_phi = (phi + pi) / (2 pi).
double u_to_theta(double u) {
  return u * u * (kPi / 2);
}
double u_to_phi(double u) {
  return (2 * u - 1) * kPi;
}

// A function of theta_m given at the nodes u_j = j / (n - 1), linear in u between them: how the
// renderers interpolate the ndf and sigma grids (bilinear, two identical phi rows).
struct UGrid {
  std::vector<double> v;
  double at(double u) const {
    const double x = std::clamp(u, 0.0, 1.0) * static_cast<double>(v.size() - 1);
    const size_t j = std::min(static_cast<size_t>(x), v.size() - 2);
    return v[j] + (v[j + 1] - v[j]) * (x - static_cast<double>(j));
  }
};

// int over the upper hemisphere of g(theta_m, m), by the midpoint rule in (u_theta, phi).
template <class G>
double hemisphere_integral(G&& g) {
  constexpr int kU = 96, kPhi = 96;
  double sum = 0;
  for (int a = 0; a < kU; ++a) {
    const double u = (a + 0.5) / kU, theta = u_to_theta(u);
    const double jac = kPi * u * std::sin(theta);  // d theta = pi u du, d omega = sin d theta d phi
    for (int b = 0; b < kPhi; ++b) {
      const double phi = 2 * kPi * (b + 0.5) / kPhi;
      sum += g(theta, spherical_direction(theta, phi)) * jac;
    }
  }
  return sum * (1.0 / kU) * (2 * kPi / kPhi);
}

UGrid projected_area(const UGrid& ndf) {
  UGrid sigma{std::vector<double>(ndf.v.size())};
  for (size_t j = 0; j < ndf.v.size(); ++j) {
    const Vec3 w = spherical_direction(u_to_theta(static_cast<double>(j) / (ndf.v.size() - 1)), 0);
    sigma.v[j] = hemisphere_integral([&](double theta, const Vec3& m) {
      return ndf.at(std::sqrt(theta * 2 / kPi)) * std::max(0.0, dot(m, w));
    });
  }
  return sigma;
}

// The paper's retro-reflection estimate of the NDF (see rgl_bsdf.h), on 'nodes' u nodes.
UGrid estimate_ndf(const TableView& view, int nodes) {
  std::vector<double> retro(static_cast<size_t>(nodes)),
      values(static_cast<size_t>(view.channels()));
  for (int j = 0; j < nodes; ++j) {
    const Vec3 w = spherical_direction(u_to_theta(static_cast<double>(j) / (nodes - 1)), 0);
    view.isotropic(w, w, values);
    retro[static_cast<size_t>(j)] = std::max(0.0, view.luminance(values));
  }
  UGrid ndf{std::vector<double>(static_cast<size_t>(nodes))};
  UGrid sigma{std::vector<double>(static_cast<size_t>(nodes))};
  for (int j = 0; j < nodes; ++j)
    sigma.v[static_cast<size_t>(j)] = std::cos(u_to_theta(static_cast<double>(j) / (nodes - 1)));
  for (int iteration = 0; iteration < 6; ++iteration) {
    for (int j = 0; j < nodes; ++j) {
      const double theta = u_to_theta(static_cast<double>(j) / (nodes - 1));
      ndf.v[static_cast<size_t>(j)] =
          4 * sigma.v[static_cast<size_t>(j)] * std::cos(theta) * retro[static_cast<size_t>(j)];
    }
    // A floor keeps every normal possible (the value tensors divide by D).
    const double peak = *std::max_element(ndf.v.begin(), ndf.v.end());
    if (!(peak > 0)) throw Error("", "ndf", "the table reflects nothing back towards the light");
    for (double& d : ndf.v) d = std::max(d, 1e-3 * peak);
    const double norm = hemisphere_integral([&](double theta, const Vec3&) {
      return ndf.at(std::sqrt(theta * 2 / kPi)) * std::cos(theta);
    });
    for (double& d : ndf.v) d /= norm;
    sigma = projected_area(ndf);
  }
  return ndf;
}

// The incidence angles: theta_k = k / (count - 1) * 90 deg, and 'grazing' more between the last
// two, at theta_{n-2} + (90 deg - theta_{n-2}) (1 - (1 - t)^2), t = j / (grazing + 1). Evenly
// spaced rather than the paper's (k / (count - 1))^2, which is dense at normal incidence where a
// cloth's values hardly change and 10 deg apart at 70 deg, where the renderers' linear blend of
// the neighbouring incidences missed a baked fabric's curvature by up to 18 %.
std::vector<double> incidence_angles(int count, int grazing) {
  std::vector<double> theta;
  for (int k = 0; k + 1 < count; ++k) theta.push_back(kPi / 2 * k / (count - 1));
  const double last = theta.back();
  for (int j = 1; j <= grazing; ++j) {
    const double t = static_cast<double>(j) / (grazing + 1);
    theta.push_back(last + (kPi / 2 - last) * (1 - sqr(1 - t)));
  }
  theta.push_back(kPi / 2);
  return theta;
}

// Solves M x = b in place for the 1-D mass matrix of the hat functions on n unit-spaced nodes
// (2/3 on the diagonal, 1/3 at the two ends, 1/6 beside it), b read with stride 'stride'.
void solve_mass(double* b, int n, int stride) {
  std::vector<double> c(static_cast<size_t>(n));  // Thomas algorithm: the reduced upper row
  auto diag = [n](int j) { return j == 0 || j == n - 1 ? 1.0 / 3 : 2.0 / 3; };
  double d = diag(0);
  c[0] = (1.0 / 6) / d;
  b[0] /= d;
  for (int j = 1; j < n; ++j) {
    d = diag(j) - (1.0 / 6) * c[static_cast<size_t>(j - 1)];
    c[static_cast<size_t>(j)] = (1.0 / 6) / d;
    b[j * stride] = (b[j * stride] - (1.0 / 6) * b[(j - 1) * stride]) / d;
  }
  for (int j = n - 2; j >= 0; --j) b[j * stride] -= c[static_cast<size_t>(j)] * b[(j + 1) * stride];
}

// The n x n node values whose bilinear interpolant is the L2 projection of a function given on
// the finer grid of s (n - 1) + 1 points a side that holds the nodes: its integrals against the
// nodes' hat functions (trapezoid rule on the fine grid) solved through the mass matrix in x,
// then in y. The integral over the square, the albedo here, is kept (the hats sum to 1); point
// values lose the function's curvature between the nodes (the interpolant of a peak lies below
// it), which took 3.6 % of a baked fabric's albedo at 85 deg.
std::vector<double> project_bilinear(const std::vector<double>& fine, int n, int s) {
  const int nf = s * (n - 1) + 1;
  auto weight = [&](int j, int t) {  // node j's hat at fine offset t, times the trapezoid's weight
    const int k = j * s + t;
    if (k < 0 || k >= nf) return 0.0;
    return (1 - std::abs(t) / static_cast<double>(s)) / s * (k == 0 || k == nf - 1 ? 0.5 : 1.0);
  };
  const auto at = [](int row, int col, int width) {
    return static_cast<size_t>(row * width + col);
  };
  std::vector<double> rows(static_cast<size_t>(nf * n), 0.0), out(static_cast<size_t>(n * n), 0.0);
  for (int y = 0; y < nf; ++y)
    for (int j = 0; j < n; ++j)
      for (int t = -s; t <= s; ++t)
        if (const double w = weight(j, t); w != 0)
          rows[at(y, j, n)] += w * fine[at(y, j * s + t, nf)];
  for (int i = 0; i < n; ++i)
    for (int t = -s; t <= s; ++t)
      if (const double w = weight(i, t); w != 0)
        for (int x = 0; x < n; ++x) out[at(i, x, n)] += w * rows[at(i * s + t, x, n)];
  for (int i = 0; i < n; ++i) solve_mass(out.data() + i * n, n, 1);
  for (int x = 0; x < n; ++x) solve_mass(out.data() + x, n, n);
  return out;
}

// The stored value f(w_i, w_o) cos theta_o 4 sigma / D(m) per channel, [channel][y][x], on the
// warp's sample space at 'side' x 'side' points.
std::vector<std::vector<double>> sample_values(const TableView& view, const rgl::MarginalWarp& warp,
                                               const UGrid& ndf, double sigma, const Vec3& wi,
                                               int side) {
  const auto nc = static_cast<size_t>(view.channels());
  std::vector<std::vector<double>> out(nc, std::vector<double>(static_cast<size_t>(side * side)));
  std::vector<double> f(nc);
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x) {
      const Vec2 um =
          warp.sample({static_cast<double>(x) / (side - 1), static_cast<double>(y) / (side - 1)});
      const Vec3 m = spherical_direction(u_to_theta(um.x), u_to_phi(um.y));
      const Vec3 wo = reflect(wi, m);
      std::fill(f.begin(), f.end(), 0.0);
      if (wo.z > 0 && dot(wi, m) > 0) {
        view.isotropic(wi, wo, f);  // Weft's f(view, light): wi here is the view
        const double scale = wo.z * 4 * sigma / ndf.at(um.x);
        for (double& v : f) v = std::max(0.0, v) * scale;
      }
      for (size_t c = 0; c < nc; ++c) out[c][static_cast<size_t>(y * side + x)] = f[c];
    }
  return out;
}

struct Slices {
  std::vector<float> vndf, luminance, values;  // [theta_i][...]
};

// One theta_i's vndf, luminance and value tensors, appended to 'out'.
void add_slice(const TableView& view, const RglOptions& o, const UGrid& ndf, double sigma,
               double theta_i, Slices& out) {
  const int nv = o.vndf_resolution, ns = o.sample_resolution;
  const Vec3 wi = spherical_direction(theta_i, 0);
  std::vector<double> density(static_cast<size_t>(nv * nv));
  for (int y = 0; y < nv; ++y)
    for (int x = 0; x < nv; ++x) {
      const double ux = static_cast<double>(x) / (nv - 1), theta_m = u_to_theta(ux);
      const Vec3 m = spherical_direction(theta_m, u_to_phi(static_cast<double>(y) / (nv - 1)));
      const double d =
          ndf.at(ux) * std::max(0.0, dot(m, wi)) / sigma * (2 * kPi * kPi * ux * std::sin(theta_m));
      density[static_cast<size_t>(y * nv + x)] = d;
      out.vndf.push_back(static_cast<float>(d));
    }
  const rgl::MarginalWarp warp(std::move(density), nv, nv);
  const int fine = o.sample_supersampling * (ns - 1) + 1;
  std::vector<std::vector<double>> values = sample_values(view, warp, ndf, sigma, wi, fine);
  for (auto& v : values) {
    if (o.sample_supersampling > 1) v = project_bilinear(v, ns, o.sample_supersampling);
    for (double& x : v) x = std::max(0.0, x);  // the projection rings below a steep edge
    out.values.insert(out.values.end(), v.begin(), v.end());
  }
  std::vector<double> f(values.size());
  for (size_t k = 0; k < static_cast<size_t>(ns * ns); ++k) {
    for (size_t c = 0; c < f.size(); ++c) f[c] = values[c][k];
    out.luminance.push_back(static_cast<float>(view.luminance(f)));
  }
  // The luminance only steers sampling; an incidence that reflects nothing is sampled uniformly
  // (an all-zero slice cannot be normalized by the renderers).
  const auto first = out.luminance.end() - ns * ns;
  if (std::all_of(first, out.luminance.end(), [](float v) { return v == 0; }))
    std::fill(first, out.luminance.end(), 1.0f);
}

}  // namespace

void RglOptions::validate() const {
  if (theta_i_count < 2 || theta_i_count > 90) throw Error("", "theta_i_count", "must be 2..90");
  if (grazing_theta_i < 0 || grazing_theta_i > 90)
    throw Error("", "grazing_theta_i", "must be 0..90");
  if (!(ndf_uniform_share >= 0 && ndf_uniform_share <= 1))
    throw Error("", "ndf_uniform_share", "must be in [0, 1]");
  if (ndf_resolution < 2 || ndf_resolution > 4096)
    throw Error("", "ndf_resolution", "must be 2..4096");
  if (vndf_resolution < 2 || vndf_resolution > 512)
    throw Error("", "vndf_resolution", "must be 2..512");
  if (sample_resolution < 2 || sample_resolution > 256)
    throw Error("", "sample_resolution", "must be 2..256");
  if (sample_supersampling < 1 || sample_supersampling > 8)
    throw Error("", "sample_supersampling", "must be 1..8");
  if (azimuths < 1) throw Error("", "azimuths", "must be at least 1");
}

ExportReport write_rgl_bsdf(const TabulatedBsdfTable& table, const std::filesystem::path& path,
                            const RglOptions& o) {
  o.validate();
  const TableView view(table, o.azimuths);
  UGrid ndf = estimate_ndf(view, o.ndf_resolution);
  for (double& d : ndf.v) d = (1 - o.ndf_uniform_share) * d + o.ndf_uniform_share / kPi;
  const UGrid sigma = projected_area(ndf);
  const std::vector<double> angles = incidence_angles(o.theta_i_count, o.grazing_theta_i);
  const int nt = static_cast<int>(angles.size());
  Slices s;
  std::vector<float> theta_i;
  for (double theta : angles) {
    // In double: pi/2 rounded to float lies below the horizon. sigma as the renderers
    // interpolate it, which they divide by.
    theta_i.push_back(static_cast<float>(theta));
    add_slice(view, o, ndf, sigma.at(std::sqrt(theta * 2 / kPi)), theta, s);
  }
  const auto u64 = [](int v) { return static_cast<uint64_t>(v); };
  const uint64_t ns = u64(o.sample_resolution), nv = u64(o.vndf_resolution);
  const uint64_t nc = u64(view.channels()), nn = u64(o.ndf_resolution);
  std::vector<float> ndf_rows, sigma_rows;
  for (int row = 0; row < 2; ++row)
    for (size_t j = 0; j < ndf.v.size(); ++j) {
      ndf_rows.push_back(static_cast<float>(ndf.v[j]));
      sigma_rows.push_back(static_cast<float>(sigma.v[j]));
    }
  std::vector<rgl::TensorField> fields{
      rgl::byte_field("description", o.description),
      rgl::byte_field("jacobian", std::string(1, '\1')),
      rgl::float_field("theta_i", {u64(nt)}, theta_i),
      rgl::float_field("phi_i", {1}, {0.0f}),
      rgl::float_field("ndf", {2, nn}, ndf_rows),
      rgl::float_field("sigma", {2, nn}, sigma_rows),
      rgl::float_field("vndf", {1, u64(nt), nv, nv}, s.vndf),
      rgl::float_field("luminance", {1, u64(nt), ns, ns}, s.luminance)};
  if (view.spectral()) {
    std::vector<float> wavelengths;
    for (int b = 0; b < kNumBands; ++b)
      wavelengths.push_back(static_cast<float>(band_wavelength_nm(b)));
    fields.push_back(rgl::float_field("wavelengths", {nc}, wavelengths));
    fields.push_back(rgl::float_field("spectra", {1, u64(nt), nc, ns, ns}, s.values));
  } else {
    fields.push_back(rgl::float_field("rgb", {1, u64(nt), nc, ns, ns}, s.values));
  }
  const std::vector<uint8_t> bytes = rgl::encode_tensor_file(fields);
  write_bytes_atomically(path, bytes);
  ExportReport r{"RGL .bsdf", {}, {}, {}};
  r.dropped = {
      "transmission (light and viewer on opposite sides of the cloth)",
      "the back side (a view from below: the format is one-sided)",
      "anisotropy (averaged over " + std::to_string(o.azimuths) + " rotations about the normal)"};
  if (!view.spectral())
    r.notes.push_back(
        "RGB file ('rgb' field): Mitsuba 3 RGB variants read it; pbrt-v4 reads only "
        "spectral files, export a spectral table for it");
  r.figures = {{"theta_i", nt},
               {"samples per side", o.sample_resolution},
               {"bytes", static_cast<double>(bytes.size())}};
  return r;
}

}  // namespace weft
