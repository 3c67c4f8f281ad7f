#include "weft/materials/classic_fiber.h"

#include <algorithm>
#include <cmath>

#include "weft/core/math.h"

namespace weft {
namespace {

// Quadrature points per dimension for E(mu): a midpoint grid over the sampler's [0,1)^2, i.e.
// importance-sampled deterministic quadrature of int f cos dwi. 64^2 keeps |E - E_exact| ~ 1e-4.
constexpr int kQuadrature = 64;
// The horizon itself has no defined sampling frame; E(0) is taken at this cosine.
constexpr double kHorizonMu = 1e-4;

}  // namespace

SpecularAlbedoTable SpecularAlbedoTable::compute(const CookTorranceBsdf& surface) {
  SpecularAlbedoTable t;
  for (int k = 0; k < kNodes; ++k) {
    const double mu = std::max(kHorizonMu, static_cast<double>(k) / (kNodes - 1));
    const Vec3 wo{safe_sqrt(1 - mu * mu), 0, mu};
    double sum = 0;
    for (int i = 0; i < kQuadrature; ++i) {
      for (int j = 0; j < kQuadrature; ++j) {
        const Vec2 u{(i + 0.5) / kQuadrature, (j + 0.5) / kQuadrature};
        const Vec3 h = surface.distribution.sample_normal(wo, u);
        const Vec3 wi = normalize(reflect(wo, h));
        const double pdf = surface.pdf_upper(wo, wi);
        if (wi.z <= 0 || !(pdf > 0)) continue;
        sum += surface.eval_upper(wo, wi) * wi.z / pdf;
      }
    }
    t.albedo[k] = sum / (kQuadrature * kQuadrature);
  }
  // 2 int E mu dmu of the piecewise-linear interpolant, exactly (Simpson is exact per segment).
  double avg = 0;
  for (int k = 0; k + 1 < kNodes; ++k) {
    const double a = static_cast<double>(k) / (kNodes - 1),
                 b = static_cast<double>(k + 1) / (kNodes - 1);
    avg += (b - a) * (t.albedo[k] * (2 * a + b) + t.albedo[k + 1] * (a + 2 * b)) / 6;
  }
  t.average = 2 * avg;
  return t;
}

double SpecularAlbedoTable::operator()(double mu) const {
  const double x = std::clamp(mu, 0.0, 1.0) * (kNodes - 1);
  const int k = std::min(static_cast<int>(x), kNodes - 2);
  const double t = x - k;
  return (1 - t) * albedo[k] + t * albedo[k + 1];
}

ClassicFiberBsdf ClassicFiberBsdf::create(Rgb reflectance, MicrofacetDistribution distribution,
                                          double ior) {
  ClassicFiberBsdf b;
  b.reflectance = reflectance;
  b.surface = CookTorranceBsdf{distribution, ior, Rgb(1.0)};
  b.surface_albedo =
      std::make_shared<const SpecularAlbedoTable>(SpecularAlbedoTable::compute(b.surface));
  return b;
}

double ClassicFiberBsdf::surface_lobe_probability(const Vec3& wo_upper) const {
  const double e = (*surface_albedo)(wo_upper.z);
  const double total = e + reflectance.average() * (1 - e);
  return total > 0 ? e / total : 1.0;
}

Rgb ClassicFiberBsdf::eval(const Vec3& wo, const Vec3& wi) const {
  if (!surface_albedo || wo.z * wi.z <= 0) return Rgb(0.0);  // default-constructed: black
  const double s = wo.z < 0 ? -1 : 1;
  const Vec3 o{wo.x, wo.y, s * wo.z}, i{wi.x, wi.y, s * wi.z};
  const SpecularAlbedoTable& e = *surface_albedo;
  const double volume = (1 - e(o.z)) * (1 - e(i.z)) / (kPi * (1 - e.average));
  return Rgb(surface.eval_upper(o, i)) + reflectance * volume;
}

double ClassicFiberBsdf::pdf(const Vec3& wo, const Vec3& wi) const {
  if (!surface_albedo || wo.z * wi.z <= 0) return 0;
  const double s = wo.z < 0 ? -1 : 1;
  const Vec3 o{wo.x, wo.y, s * wo.z}, i{wi.x, wi.y, s * wi.z};
  const double p = surface_lobe_probability(o);
  return p * surface.pdf_upper(o, i) + (1 - p) * i.z * kInvPi;
}

std::optional<BsdfSample> ClassicFiberBsdf::sample(const Vec3& wo, Vec2 u, double u_lobe) const {
  if (!surface_albedo || wo.z == 0) return std::nullopt;
  const double s = wo.z < 0 ? -1 : 1;
  const Vec3 o{wo.x, wo.y, s * wo.z};
  Vec3 wi;
  if (u_lobe < surface_lobe_probability(o)) {
    wi = normalize(reflect(o, surface.distribution.sample_normal(o, u)));
  } else {
    wi = sample_cosine_hemisphere(u);
  }
  if (wi.z <= 0) return std::nullopt;
  wi.z *= s;
  const double p = pdf(wo, wi);
  if (!(p > 0)) return std::nullopt;
  return BsdfSample{wi, eval(wo, wi) * (std::abs(wi.z) / p), p, false};
}

TabulatedBsdfTable classic_fiber_table(const Rgb& diffuse, const MicrofacetDistribution& d,
                                       double ior, int resolution, int samples, uint64_t seed,
                                       int threads, const ProgressCallback& progress) {
  const ClassicFiberBsdf classic = ClassicFiberBsdf::create(diffuse, d, ior);
  // Outside the fiber only: the ray trace lights the far crossing point from inside, where an
  // opaque classic fiber reflects nothing.
  TabulatedBsdfTable t = TabulatedBsdfTable::from_function(
      resolution, 3,
      [&](const Vec3& wo, const Vec3& wi, std::span<double> v) {
        const Rgb f = wo.z > 0 && wi.z > 0 ? classic.eval(wo, wi) : Rgb();
        v[0] = f.r;
        v[1] = f.g;
        v[2] = f.b;
      },
      samples, seed, threads, progress);
  t.kind = "fiber";
  return t;
}

}  // namespace weft
