#pragma once
// A table as a glTF 2.0 material: the core metallicRoughness model (metallic 0, the dielectric of
// the specification's Appendix B: Lambert base weighted by 1 - F, GGX specular with the separable
// Smith visibility, Schlick F with F0 = 0.04) under KHR_materials_sheen (Charlie distribution and
// visibility, alpha = sheenRoughness, the base scaled by the albedo-scaling term
// min(1 - max(sheenColor) E(n.v), 1 - max(sheenColor) E(n.l)), E the sheen's directional albedo,
// here integrated numerically), and, where the fabric transmits notably, its transmission:
// KHR_materials_diffuse_transmission when the table transmits diffusely (a Lambertian BTDF with
// its own colour, for thin translucent surfaces: base = mix(diffuse_brdf(baseColor),
// diffuse_btdf(diffuseTransmissionColor), diffuseTransmission) under the same Fresnel mix), else
// KHR_materials_transmission (a rough specular BTDF tinted by the base colour); either way the
// diffuse reflection is weighted by 1 - the factor. The reflection parameters are fitted to the
// table by the project's optimizer (core/optimize.h, Levenberg-Marquardt) on the RMS of
// log((f_model + eps) / (f_table + eps)) over the table's grid: view and light at the centres of
// the upper hemisphere's bins (a grid of resolution min(R, 8)), RGB channels (spectral tables in
// linear sRGB under D65), eps = 0.01 / sr so that near-black cells do not dominate.
#include <filesystem>
#include <string>
#include <vector>

#include "weft/core/spectrum.h"
#include "weft/core/vec.h"
#include "weft/exchange/export_report.h"
#include "weft/materials/bsdf_table.h"

namespace weft {

struct GltfMaterial {
  Rgb base_color{0.5};
  double roughness = 0.7;
  Rgb sheen_color{0.0};
  double sheen_roughness = 0.5;
  double transmission = 0;          // 0: no KHR_materials_transmission
  double diffuse_transmission = 0;  // 0: no KHR_materials_diffuse_transmission
  Rgb diffuse_transmission_color{1.0};
};

// The sheen's directional albedo E(cos theta) for one sheen roughness (colour 1), tabulated at
// 32 cosines and interpolated linearly.
class SheenAlbedo {
 public:
  explicit SheenAlbedo(double sheen_roughness);
  double operator()(double cos_theta) const;

 private:
  std::vector<double> e_;
};
// The Charlie sheen lobe (colour 1): D * V, V including 1 / (4 n.l n.v).
double charlie_sheen(double sheen_roughness, const Vec3& wo, const Vec3& wi);

// f in 1/sr of the material for view wo and light wi (local frame, z the normal); 0 unless both
// are above the surface. 'e' is SheenAlbedo(m.sheen_roughness).
Rgb gltf_brdf(const GltfMaterial& m, const SheenAlbedo& e, const Vec3& wo, const Vec3& wi);
// f in 1/sr of the diffuse transmission for a view wo above and light wi below (0 otherwise):
// (1 - F) diffuseTransmission diffuseTransmissionColor / pi, F Schlick's at |v.h| with h the half
// vector of wo and wi mirrored to the view's side, times the sheen's albedo scaling at |n.l|.
Rgb gltf_btdf(const GltfMaterial& m, const SheenAlbedo& e, const Vec3& wo, const Vec3& wi);

struct GltfFit {
  GltfMaterial material;
  double rms_log = 0;        // the fit's error (see above)
  double rms_log_start = 0;  // at the start point
  int points = 0;            // direction pairs compared
  int evaluations = 0;
  double transmittance = 0;  // the table's mean hemispherical transmittance (view from above)
  // The diffuse transmission's fit: the material's transmitted albedo against the table's
  // (linear sRGB) over the upper view bins and RGB, relative: RMS and largest.
  double transmission_rms_rel = 0, transmission_max_rel = 0;
  double transmission_peak = 0;  // the table's straight-through f against a Lambertian BTDF's
};
struct GltfFitOptions {
  int max_resolution = 8;  // the comparison grid: min(R, this)
  // The targets: the table averaged over this many rotations about the normal (TableView), as
  // the other exports hold it; 1 is the table's own value at each pair, which an isotropic
  // material cannot follow. Against the mean over 256 rotations (RMS log), an anisotropic woven
  // table's fit to 1 rotation was 0.266 off, to 64 0.263 (GltfMaterial.
  // FitsTheTablesMeanOverRotations; docs/exchange.md: the baked tables move as little).
  int azimuths = 64;
  int max_evaluations = 400;
  double epsilon_per_sr = 0.01;          // eps of the log error
  double transmission_threshold = 0.05;  // mean transmittance above which transmission is written
  // Diffuse transmission unless the straight-through f exceeds this many times a Lambertian
  // BTDF's of the same albedo (mean over the upper view bins).
  double diffuse_peak_max = 10;
};
GltfFit fit_gltf_material(const TabulatedBsdfTable& table, const GltfFitOptions& options = {});

// Writes a glTF 2.0 asset (.gltf, buffer embedded as a data URI, or .glb by the extension): one
// 1 m x 1 m double-sided quad carrying the fitted material, the fit's error and source in the
// material's extras. Atomic.
ExportReport write_gltf_material(const TabulatedBsdfTable& table, const std::filesystem::path& path,
                                 const std::string& name, const GltfFitOptions& options = {});

}  // namespace weft
