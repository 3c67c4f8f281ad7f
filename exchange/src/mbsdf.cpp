#include "weft/exchange/mbsdf.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/core/frame.h"
#include "weft/core/math.h"
#include "weft/exchange/table_view.h"

namespace weft {
namespace {

void put_u32(std::string& out, uint32_t v) {
  char b[4];
  std::memcpy(b, &v, 4);
  out.append(b, 4);
}

// One part's RGB values, index ((theta_in nt + theta_out) np + phi) 3 + channel.
struct MbsdfGrid {
  int nt = 0, np = 0;
  std::vector<double> v;
  size_t index(int ti, int to, int p, int c) const {
    return static_cast<size_t>(((ti * nt + to) * np + p) * 3 + c);
  }
  double& at(int ti, int to, int p, int c) { return v[index(ti, to, p, c)]; }
  double at(int ti, int to, int p, int c) const { return v[index(ti, to, p, c)]; }
};

// f in linear sRGB over the grid, light at theta_in on the side 'light_z' (+1 upper, -1 lower),
// view at (theta_out, phi) on the side 'view_z'.
MbsdfGrid sample_mbsdf_part(const TableView& view, const MbsdfOptions& o, double light_z,
                            double view_z, GamutClip& clip) {
  MbsdfGrid g{o.theta_resolution, o.phi_resolution, {}};
  g.v.resize(static_cast<size_t>(g.nt * g.nt * g.np * 3));
  std::vector<double> f(static_cast<size_t>(view.channels()));
  for (int ti = 0; ti < g.nt; ++ti)
    for (int to = 0; to < g.nt; ++to)
      for (int p = 0; p < g.np; ++p) {
        Vec3 wi = spherical_direction((ti + 0.5) * (kPi / 2) / g.nt, 0);
        Vec3 wo = spherical_direction((to + 0.5) * (kPi / 2) / g.nt, (p + 0.5) * kPi / g.np);
        wi.z *= light_z;
        wo.z *= view_z;
        view.isotropic(wo, wi, f);
        const Rgb c = view.rgb(f, &clip);
        for (int k = 0; k < 3; ++k) g.at(ti, to, p, k) = std::max(0.0, c[k]);
      }
  return g;
}

// The hemispherical albedo per theta_in and channel: f cos theta_out over the cells (exact
// cos sin weights, phi over [0, pi] counted twice).
std::vector<double> mbsdf_part_albedos(const MbsdfGrid& g) {
  std::vector<double> a(static_cast<size_t>(g.nt * 3), 0.0);
  const double dt = kPi / 2 / g.nt, dp = kPi / g.np;
  for (int ti = 0; ti < g.nt; ++ti)
    for (int to = 0; to < g.nt; ++to) {
      const double w = (sqr(std::sin((to + 1) * dt)) - sqr(std::sin(to * dt))) / 2 * dp * 2;
      for (int p = 0; p < g.np; ++p)
        for (int c = 0; c < 3; ++c) a[static_cast<size_t>(ti * 3 + c)] += g.at(ti, to, p, c) * w;
    }
  return a;
}

// The largest difference per incidence and channel of the file's albedo from either direction's,
// relative to the larger of the two directions (where that is not negligible, 1e-6 of its peak):
// 0 for a reciprocal table, 1/2 for one that transmits one way only.
double mbsdf_direction_error(const std::vector<double>& file, const std::vector<double>& down,
                             const std::vector<double>& up) {
  double peak = 0;
  for (size_t k = 0; k < file.size(); ++k) peak = std::max({peak, down[k], up[k]});
  double worst = 0;
  for (size_t k = 0; k < file.size(); ++k) {
    const double larger = std::max(down[k], up[k]);
    if (larger > 1e-6 * peak)
      worst = std::max(
          {worst, std::abs(file[k] - down[k]) / larger, std::abs(file[k] - up[k]) / larger});
  }
  return worst;
}

// The transmission part: the MDL SDK's renderers orient the normal towards the viewer and look
// up one table for both sides, averaged with its transpose (f(in, out) + f(out, in)) / 2. So the
// file holds the mean of the table's two directions (light from above to a view below, light
// from below to a view above), made reciprocal: what those renderers show, exactly.
MbsdfGrid mbsdf_transmission_part(const TableView& view, const MbsdfOptions& o, GamutClip& clip,
                                  ExportReport& r) {
  MbsdfGrid down = sample_mbsdf_part(view, o, 1, -1, clip),
            up = sample_mbsdf_part(view, o, -1, 1, clip);
  MbsdfGrid t{down.nt, down.np, std::vector<double>(down.v.size())};
  for (int ti = 0; ti < t.nt; ++ti)
    for (int to = 0; to < t.nt; ++to)
      for (int p = 0; p < t.np; ++p)
        for (int c = 0; c < 3; ++c)
          t.at(ti, to, p, c) = (down.at(ti, to, p, c) + up.at(ti, to, p, c) +
                                down.at(to, ti, p, c) + up.at(to, ti, p, c)) /
                               4;
  const auto a_down = mbsdf_part_albedos(down), a_up = mbsdf_part_albedos(up),
             a_file = mbsdf_part_albedos(t);
  const auto mean = [](const std::vector<double>& a) {
    double s = 0;
    for (double x : a) s += x;
    return s / static_cast<double>(a.size());
  };
  r.figures.push_back({"transmittance light from above (table)", mean(a_down)});
  r.figures.push_back({"transmittance light from below (table)", mean(a_up)});
  r.figures.push_back({"transmittance either way (file)", mean(a_file)});
  const double error = mbsdf_direction_error(a_file, a_down, a_up);
  r.figures.push_back({"transmission direction error (max relative)", error});
  if (error > 0.01)
    r.notes.push_back(
        "the table transmits differently from above and from below; MDL's measured BSDF holds "
        "one transmission for both, so the file carries their mean (largest albedo error per "
        "incidence in the figures)");
  return t;
}

void append_mbsdf_part(const MbsdfGrid& g, bool transmission, std::string& out) {
  out += transmission ? "MBSDF_DATA_TRANSMISSION=\n" : "MBSDF_DATA_REFLECTION=\n";
  put_u32(out, 1);  // RGB
  put_u32(out, static_cast<uint32_t>(g.nt));
  put_u32(out, static_cast<uint32_t>(g.np));
  for (double x : g.v) {
    const float v = static_cast<float>(x);
    out.append(reinterpret_cast<const char*>(&v), 4);
  }
}

}  // namespace

void MbsdfOptions::validate() const {
  if (theta_resolution < 1 || theta_resolution > 360)
    throw Error("", "theta_resolution", "must be 1..360");
  if (phi_resolution < 1 || phi_resolution > 720)
    throw Error("", "phi_resolution", "must be 1..720");
  if (azimuths < 1) throw Error("", "azimuths", "must be at least 1");
}

ExportReport write_mbsdf(const TabulatedBsdfTable& table, const std::filesystem::path& path,
                         const MbsdfOptions& o) {
  o.validate();
  const TableView view(table, o.azimuths);
  ExportReport r{"MDL .mbsdf", {}, {}, {}};
  GamutClip clip;
  const MbsdfGrid reflection = sample_mbsdf_part(view, o, 1, 1, clip);
  const MbsdfGrid transmission = mbsdf_transmission_part(view, o, clip, r);
  std::string bytes = "NVIDIA ARC MBSDF V1\n";
  append_mbsdf_part(reflection, false, bytes);
  append_mbsdf_part(transmission, true, bytes);
  write_text_atomically(path, bytes);
  r.dropped = {
      "reflection of light arriving from below (the file's reflection is the upper side's; MDL "
      "shows it on both sides)",
      "anisotropy (averaged over " + std::to_string(o.azimuths) + " rotations about the normal)"};
  if (view.spectral()) {
    r.dropped.push_back("the spectrum (written as linear sRGB under D65)");
    r.figures.push_back({"components out of gamut set to 0", static_cast<double>(clip.components)});
  }
  r.figures.push_back({"theta samples", o.theta_resolution});
  r.figures.push_back({"phi samples", o.phi_resolution});
  return r;
}

}  // namespace weft
