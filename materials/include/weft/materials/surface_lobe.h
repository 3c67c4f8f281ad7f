#pragma once
// The analytic part of a table: the Cook-Torrance reflection off the surface at the table's point
// (a fiber's first-surface reflection, the paper's f_surf: docs/fiber-bsdf.md), which a table may
// name beside its cells so that a reader can evaluate and sample it exactly rather than as the
// cells' blur. On a smooth filament (GGX alpha 0.1) the lobe is a few degrees wide, narrower than
// the bins of an R 8 table (about 11 degrees): binned, it is averaged away.
//
// The cells of a table with a lobe still hold the cosine-weighted cell averages of the WHOLE f,
// lobe included, so a reader that ignores the lobe reads the same table as before. A reader that
// uses it takes f = (cells - lobe cells) interpolated + lobe, where the lobe cells are
// cell_averages() below: one deterministic function, so that the baker who added them and the
// reader who takes them out use the same numbers, and what is left is the rest of f alone.
//
// The lobe is lit-side only: f_lobe(wo, wi) = F(wo.h; ior_c) D(h) G2(wo, wi) / (4 cos_o cos_i)
// for wi.z > 0 and wo.z > 0 (CookTorranceBsdf::eval_upper), zero otherwise; one index of
// refraction per channel of the table (Fresnel is all that depends on the channel).
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "weft/core/direction_grid.h"
#include "weft/core/vec.h"
#include "weft/materials/microfacet.h"

namespace weft {

struct SurfaceLobe {
  MicrofacetDistribution distribution;
  std::vector<double> ior;  // per channel of the table, outside index 1

  int channels() const { return static_cast<int>(ior.size()); }
  // The channels' distinct indices (in order of first use), and which of them each channel has:
  // Fresnel is all that differs between channels, so readers compute per distinct index.
  struct DistinctIndices {
    std::vector<double> ior;
    std::vector<int> of_channel;
  };
  DistinctIndices distinct_indices() const;
  // f of one channel (1/sr).
  double eval(const Vec3& wo, const Vec3& wi, int channel) const;
  // f of every channel into 'out' (channels() values).
  void eval(const Vec3& wo, const Vec3& wi, std::span<double> out) const;
  // An exit direction for light from wi (wi.z > 0) drawn from the distribution's visible normals
  // (independent of the channel), and its solid-angle density; nothing when the draw leaves the
  // lit side.
  std::optional<Vec3> sample(const Vec3& wi, Vec2 u, double* pdf) const;
  double pdf(const Vec3& wi, const Vec3& wo) const;  // the density of sample()

  // The lobe's cosine-weighted cell averages on 'grid', [wi bin][wo bin][channel] like a table's
  // values (zero off the upper-upper quarter). A deterministic quadrature: per wi bin, 16 x 16
  // stratified directions (weight |cos theta_i|), each with 24 x 24 lattice draws of sample()
  // booked into their wo bins with weight f |cos theta_o| / pdf; channels of equal index share
  // the draws. The same inputs give the same bits at any thread count.
  std::vector<double> cell_averages(const DirectionGrid& grid, int threads = 0) const;

  // Header attributes of a table file (bsdf_table.h), and the lobe back from them: "surface_lobe"
  // = "cook-torrance", "surface_lobe_distribution" = "ggx" | "beckmann", "surface_lobe_alpha",
  // "surface_lobe_ior" (one number per channel, comma-separated, 17 significant digits).
  static constexpr const char* kKindAttribute = "surface_lobe";
  static bool is_attribute(const std::string& name);
  std::map<std::string, std::string> attributes() const;
  // Nothing when the header names no lobe; weft::Error naming the file and attribute when it is
  // malformed or has another channel count.
  static std::optional<SurfaceLobe> from_attributes(const std::map<std::string, std::string>& a,
                                                    int channels, const std::string& file);
  // Throws weft::Error(file, "surface_lobe...", ...) unless alpha lies in [1e-3, 2], every
  // index in [1, 4] and there are 'channels' of them.
  void validate(int channels, const std::string& file) const;
};

}  // namespace weft
