#include "weft/exchange/mbsdf.h"

#include <cstring>
#include <fstream>
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

// One part's block: the magic line, the header and the RGB values.
void add_part(const TableView& view, const MbsdfOptions& o, bool transmission, std::string& out,
              GamutClip& clip) {
  const int nt = o.theta_resolution, np = o.phi_resolution;
  out += transmission ? "MBSDF_DATA_TRANSMISSION=\n" : "MBSDF_DATA_REFLECTION=\n";
  put_u32(out, 1);  // RGB
  put_u32(out, static_cast<uint32_t>(nt));
  put_u32(out, static_cast<uint32_t>(np));
  std::vector<double> f(static_cast<size_t>(view.channels()));
  for (int ti = 0; ti < nt; ++ti)
    for (int to = 0; to < nt; ++to)
      for (int p = 0; p < np; ++p) {
        const double theta_in = (ti + 0.5) * (kPi / 2) / nt;
        const double theta_out = (to + 0.5) * (kPi / 2) / nt;
        const double phi = (p + 0.5) * kPi / np;
        const Vec3 wi = spherical_direction(theta_in, 0);
        Vec3 wo = spherical_direction(theta_out, phi);
        if (transmission) wo.z = -wo.z;
        view.isotropic(wo, wi, f);
        const Rgb c = view.rgb(f, &clip);
        for (int k = 0; k < 3; ++k) {
          const float v = static_cast<float>(std::max(0.0, c[k]));
          out.append(reinterpret_cast<const char*>(&v), 4);
        }
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
  std::string bytes = "NVIDIA ARC MBSDF V1\n";
  GamutClip clip;
  add_part(view, o, false, bytes, clip);
  add_part(view, o, true, bytes, clip);
  write_text_atomically(path, bytes);
  ExportReport r{"MDL .mbsdf", {}, {}, {}};
  r.dropped = {
      "light arriving from below (the parts are for light on the upper side)",
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
