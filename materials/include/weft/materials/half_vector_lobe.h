#pragma once
// A fabric table's sheen held sharp: the light its fibers reflect off their first surface and that
// leaves the cloth at once, tabulated per light bin over the half vector h = (wi + wo) / |wi + wo|
// on a fine grid about the pole, beside the table's cells.
//
// Why the half vector: a mirror-like reflection off fibers sends light from wi along wo with h
// near the fibers' surface normals, which do not move with wi. Over a light bin (about 18 degrees
// across at R 8) the peak in wo moves twice as far as wi, and the cells average it away; over h it
// stays put, so a fine h grid per coarse light bin holds a peak a few degrees wide (docs/fabric-
// bsdf.md, "Sharp sheen").
//
// The grid: DirectionGrid at h_resolution (R_h), of which only the window of W x W bins about the
// pole of the upper square is kept (at R_h 64 and W 16, 2.2 degrees a bin, a cap of about 20
// degrees). Half vectors outside it are the cells' alone. Light from below (wi.z < 0) reflects
// off the lower face: its h is mirrored through z = 0 into the window. With R_h and W even the
// pole is the corner of the window's four middle bins; with both odd, the centre of its middle
// bin.
//
// What is stored: Q[light bin][window bin][channel] with f(wi, wo) = Q(wi, h) / (4 |cos_i| |cos_o|)
// for wi, wo on the same side (zero otherwise): the microfacet form F D G, so that the value varies
// slowly with wi; Q(wi, h) is bilinear over the light bins (DirectionGrid::bilinear) and constant
// over a window bin (no second blur). The light bins are those of DirectionGrid{light_resolution},
// the table's R or a multiple m = 2 or 4 of it: the m x m light bins nested in one table bin (the
// equal-area chart splits it evenly) follow it in the values, so each image row of a file holds
// its table bin's m^2 windows. Why finer light bins: how much of a satin is lit and seen, and so
// Q, changes with the light faster than an 18 degree bin resolves (docs/fabric-bsdf.md).
// With a Fresnel index (fresnel_ior > 0, since table format 6) the values are Q / F(wi . h), F
// the fibers' surface reflectance at that index, and eval multiplies F back: the fibers' Fresnel
// rises about fourfold from a 55 to a 75 degree light, so Q itself is not slow across the grazing
// light bins (18 degrees at R 8): on a sheen that is Fresnel alone, blending it put a 60 degree
// light's mirror f 87 % too high (docs/fabric-bsdf.md, "Sharp sheen"). A booking of Q (the fabric
// ray trace) divides the light of each (light bin, window bin) by the mean (wi . h) over them
// (mean_projections), so that the cell averages carry the light booked there.
// The cells of the table include the lobe (like a surface lobe, surface_lobe.h): a reader that
// ignores it reads the whole f as before, one that uses it takes the cells less cell_averages(),
// interpolated, plus eval().
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "weft/core/direction_grid.h"
#include "weft/core/vec.h"

namespace weft {

struct HalfVectorLobe {
  int resolution = 0;        // R of the table's grid
  int light_resolution = 0;  // R_l of the light bins' grid: R, 2 R or 4 R
  int h_resolution = 0;      // R_h of the half vectors' DirectionGrid
  int window = 0;            // W: bins per side of the window about the pole (<= R_h, R_h - W even)
  int channels = 3;
  double fresnel_ior = 0;     // > 1: values hold Q / F(wi . h) at this index; 0: Q
  std::vector<float> values;  // [slot of light bin][window bin][channel]: Q, or Q / F

  static constexpr double kMaxFresnelIor = 4;

  static constexpr int kMaxHResolution = 256;
  static constexpr int kMaxLightFactor = 4;  // R_l / R: 1, 2 or 4

  int window_bins() const { return window * window; }
  int light_factor() const { return light_resolution / resolution; }
  DirectionGrid light_grid() const { return DirectionGrid{light_resolution}; }
  // The light bins per table bin, m^2: a file's image row holds this many windows.
  int light_bins_per_cell() const { return light_factor() * light_factor(); }
  // Where light bin b of light_grid() is kept: its table bin's m^2 places, then its own among them
  // (row-major in the chart); b itself when R_l = R.
  size_t slot(int light_bin) const;
  // The light bin kept at slot s (the inverse of slot).
  int light_bin_at(size_t s) const;
  size_t index(int light_bin, int window_bin, int channel) const {
    return (slot(light_bin) * static_cast<size_t>(window_bins()) +
            static_cast<size_t>(window_bin)) *
               static_cast<size_t>(channels) +
           static_cast<size_t>(channel);
  }
  // An empty lobe (every Q zero) of the given shape; light_resolution 0: the table's.
  static HalfVectorLobe zeros(int resolution, int h_resolution, int window, int channels,
                              int light_resolution = 0);
  // The window bin of h, mirrored into the upper hemisphere when h.z < 0; -1 outside the window.
  int window_bin_of(const Vec3& h) const;
  // The solid angle of each window bin (DirectionGrid{h_resolution}.bin_solid_angle()).
  double window_bin_solid_angle() const;
  // The direction at offsets (fx, fy) in [0, 1] across window bin k (upper hemisphere).
  Vec3 window_point(int k, double fx, double fy) const;

  // f of every channel into 'out' (channels values, 1/sr).
  void eval(const Vec3& wo, const Vec3& wi, std::span<double> out) const;

  // The lobe's cosine-weighted cell averages on the table's grid, [wi bin][wo bin][channel] like a
  // table's values: a deterministic quadrature (per table bin 16 x 16 wi, per window bin 3 x 3 half
  // vectors), the same bits at any thread count.
  std::vector<double> cell_averages(int threads = 0) const;

  // The factor eval multiplies the values by at wi . h: F(wi . h) with a Fresnel index, else 1.
  double value_scale(double wi_dot_h) const;

  // What a booking of the lobe's light needs (the fabric ray trace): per light bin a (by slot) and
  // window bin k the mean of (wi . h) value_scale(wi . h) over wi in a and h in k where wo =
  // reflect(wi, h) lies on wi's side, zero elsewhere, by the quadrature of cell_averages (the same
  // wi points, a light bin's share of them); [slot][window bin], like the values. A particle from a
  // that leaves with weight w and half vector in k estimates the cell's light, so the value (sum of
  // w) / (particles x solid angle of k x this mean) gives the cell's cell averages that light
  // exactly (with the value constant over the light bin).
  std::vector<double> mean_projections(int threads = 0) const;

  // Header attributes of a table file: "sheen" = "half-vector window", "sheen_h_resolution",
  // "sheen_window", with a Fresnel index "sheen_fresnel_ior" (format 6 on) and with light bins
  // finer than the table's "sheen_light_resolution" (format 7 on; absent: the table's R); the
  // values are the image's columns past the cells (bsdf_table.h).
  static constexpr const char* kKindAttribute = "sheen";
  static bool is_attribute(const std::string& name);
  std::map<std::string, std::string> attributes() const;
  // The shape from the header (values empty, to be read), nothing when it names no sheen;
  // weft::Error naming the file and attribute when malformed. 'format_version': the file's (0: the
  // newest); an attribute newer than it (the Fresnel index before 6, the light resolution before
  // 7) is another program's and is ignored.
  static std::optional<HalfVectorLobe> from_attributes(const std::map<std::string, std::string>& a,
                                                       int resolution, int channels,
                                                       const std::string& file,
                                                       int format_version = 0);
  // Throws weft::Error(file, "sheen...", ...) unless the shape is valid for a table of
  // 'resolution' and 'channels' (the light resolution R, 2 R or 4 R), the Fresnel index is 0 or in
  // (1, kMaxFresnelIor], and every value is finite and >= 0.
  void validate(int resolution, int channels, const std::string& file) const;
  // Throws weft::Error(file, h_field or window_field, ...) unless R_h lies in [1, kMaxHResolution]
  // and the window in [1, R_h], centred on the pole (R_h - W even). With R_h and W odd the pole is
  // the centre of the middle bin, so a peak about it is not split four ways.
  static void check_shape(int h_resolution, int window, const std::string& file,
                          const std::string& h_field, const std::string& window_field);
  // Throws weft::Error(file, field, ...) unless light_resolution is R, 2 R or 4 R (nested bins).
  static void check_light_resolution(int resolution, int light_resolution, const std::string& file,
                                     const std::string& field);
};

}  // namespace weft
