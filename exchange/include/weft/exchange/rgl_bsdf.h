#pragma once
// A table as an RGL material file (.bsdf; Dupuy & Jakob 2018, "An Adaptive Parameterization for
// Efficient Material Acquisition and Rendering"), which Mitsuba 3's `measured` BSDF and pbrt-v4's
// `measured` material read. The format holds one reflection lobe on the upper side, isotropic
// here (phi_i has one value), in the paper's adaptive parameterization:
//  - ndf D(theta_m) and sigma(theta_i) = int D(m) <m . w_i> dm on a grid of u = sqrt(2 theta / pi)
//    (rows: phi in u, two identical rows). D is half the paper's retro-reflection estimate (with
//    G2 ~ G1 = cos theta / sigma, f(w, w) = D(w) / (4 sigma(w) cos theta), solved for D by fixed
//    point iteration from a flat surface (sigma = cos theta), normalized to int D cos = 1) and
//    half a uniform 1 / pi. D only parameterizes the file (the renderers multiply the values
//    back by it), and a cloth's estimate vanishes towards the horizon (D ~ sigma cos theta for a
//    Lambertian): the values, which divide by D, then spike there, and sigma(90 deg) is so small
//    that the renderers' blend of the warps of neighbouring incidences, linear in theta_i,
//    over-weights the grazing one. The uniform half keeps both in bounds.
//  - theta_i: k / (count - 1) 90 deg, every 5 deg by default (the paper's (k / (count - 1))^2 is
//    dense at normal incidence, where a cloth changes least), and more between the last two (85
//    and 90 deg by default), where the warp changes fastest.
//  - vndf: per theta_i, the visible normals' density D(m) <m . w_i> / sigma(w_i) in the
//    (u_theta_m, u_phi_m - phi_i) square (times the square's Jacobian 2 pi^2 u sin theta_m).
//  - luminance and rgb / spectra: per theta_i, on an n x n grid of the VNDF warp's sample space,
//    the value f(w_i, w_o) cos theta_o 4 sigma(w_i) / D(m) (the file's 'jacobian' = 1), with
//    w_o the mirror of w_i about the microfacet normal m the warp maps the grid point to; f is the
//    Weft table as the renderer reads it, its sheen included (TableView::isotropic). The renderers
//    multiply back by D(m) / (4 sigma(w_i)) and interpolate bilinearly, and the albedo towards w_i
//    is the integral of the values over the sample space, so the grid holds the L2 projection onto
//    bilinear functions of the value sampled on a grid 'sample_supersampling' times finer: it keeps
//    the albedo, which point values at the grid points lose where the value is curved. The
//    luminance steers sampling only; an incidence that reflects nothing gets a uniform one.
// Here w_i is the direction the renderer conditions on (towards the viewer, Weft's wo) and w_o
// the other (towards the light, Weft's wi): the renderers gather f cos theta_light.
// Spectral tables write 'spectra' + 'wavelengths' (the 33 band centres, 390..710 nm), which both
// renderers read; RGB tables write 'rgb', which only Mitsuba 3's RGB variants read (pbrt-v4 needs
// a spectral table).
#include <filesystem>
#include <string>

#include "weft/exchange/export_report.h"
#include "weft/materials/bsdf_table.h"

namespace weft {

struct RglOptions {
  int theta_i_count = 19;          // incidence angles, theta_k = k / (count - 1) * 90 deg
  int grazing_theta_i = 4;         // more between the last two of those, denser towards 90 deg
  double ndf_uniform_share = 0.5;  // of the ndf, a uniform one's (int D cos = 1 each)
  int ndf_resolution = 65;         // ndf and sigma nodes in u
  int vndf_resolution = 48;        // vndf: n x n
  int sample_resolution = 48;      // luminance and rgb / spectra: n x n
  int sample_supersampling = 3;    // the table sampled s (n - 1) + 1 a side, projected to n x n
  // Rotations averaged for the isotropic table. The average is a rule of that many points over
  // a table whose interpolation has a kink at every bin centre, and the file holds phi_i = 0
  // alone: with 16, a baked R = 8 fabric's export was 8.7 % off its mean over all rotations at
  // the 95th percentile, with 64 6.5 % (the other settings as they were then).
  int azimuths = 64;
  std::string description;  // the file's 'description' field
  void validate() const;    // weft::Error naming the field
};

// Writes the file atomically; weft::Error naming the file and field on failure.
ExportReport write_rgl_bsdf(const TabulatedBsdfTable& table, const std::filesystem::path& path,
                            const RglOptions& options = {});

}  // namespace weft
