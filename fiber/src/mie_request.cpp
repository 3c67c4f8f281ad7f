#include "weft/fiber/mie_request.h"

#include <cmath>
#include <complex>
#include <string>

#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/fiber/mie.h"

namespace weft {

namespace {

double required_mie_value(const std::optional<double>& v, const std::string& option) {
  if (!v) throw Error("", option, "is required here");
  return *v;
}

nlohmann::json mie_complex_parts(const std::vector<std::complex<double>>& s, bool imag) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& v : s) a.push_back(imag ? v.imag() : v.real());
  return a;
}

// Efficiencies and g, of one sphere (MieResult) or of an ensemble (MieEnsemble).
template <class Result>
void add_mie_efficiencies(nlohmann::json& j, const Result& r) {
  j["qext"] = r.qext;
  j["qsca"] = r.qsca;
  j["qabs"] = r.qabs;
  j["qback"] = r.qback;
  j["g"] = r.g;
}

// One sphere's efficiencies, g, and (at the requested angles) amplitudes and phase function.
void add_mie_sphere(nlohmann::json& j, const MieResult& res,
                    const std::vector<double>& angles_deg) {
  add_mie_efficiencies(j, res);
  j["terms"] = res.terms;
  if (angles_deg.empty()) return;
  j["angles_deg"] = angles_deg;
  j["s1_re"] = mie_complex_parts(res.s1, false);
  j["s1_im"] = mie_complex_parts(res.s1, true);
  j["s2_re"] = mie_complex_parts(res.s2, false);
  j["s2_im"] = mie_complex_parts(res.s2, true);
  j["phase_function_per_sr"] = mie_phase_function(res);
}

nlohmann::json run_physical_mie(const MieRequest& q, const std::vector<double>& mu) {
  const double n = required_mie_value(q.particle_n, "--particle-n"), k = q.particle_k.value_or(0.0);
  const double h = required_mie_value(q.host_n, "--host-n");
  const double radius = required_mie_value(q.radius_um, "--radius-um");
  const double lambda = required_mie_value(q.wavelength_nm, "--wavelength-nm");
  const double xv = mie_size_parameter(h, radius, lambda);
  nlohmann::json j = {{"particle_n", n},         {"particle_k", k}, {"host_n", h},
                      {"radius_um", radius},     {"x", xv},         {"m_re", n / h},
                      {"wavelength_nm", lambda}, {"m_im", k / h}};
  if (q.lognormal_sigma) {
    const MieEnsemble e =
        mie_ensemble(n, k, h, SizeDistribution::lognormal(radius, *q.lognormal_sigma), lambda, mu);
    j["distribution"] = "lognormal";
    j["sigma"] = *q.lognormal_sigma;
    add_mie_efficiencies(j, e);
    j["cext_um2"] = e.mean_cext_um2;
    j["csca_um2"] = e.mean_csca_um2;
    j["cabs_um2"] = e.mean_cabs_um2;
    j["mean_volume_um3"] = e.mean_volume_um3;
    if (!mu.empty()) {
      j["angles_deg"] = q.angles_deg;
      j["phase_function_per_sr"] = e.phase;
    }
    return j;
  }
  const MieResult res = mie_sphere_physical(n, k, h, radius, lambda, mu);
  const double area = kPi * radius * radius;
  j["distribution"] = "monodisperse";
  add_mie_sphere(j, res, q.angles_deg);
  j["cext_um2"] = res.qext * area;
  j["csca_um2"] = res.qsca * area;
  j["cabs_um2"] = res.qabs * area;
  return j;
}

}  // namespace

MiePlan plan_mie(const MieRequest& q) {
  MiePlan p;
  p.request = q;
  const bool relative = q.m_re || q.m_im || q.x;
  const bool physical = q.particle_n || q.particle_k || q.host_n || q.radius_um ||
                        q.wavelength_nm || q.lognormal_sigma;
  if (relative && physical) {
    const std::string first = q.m_re ? "--m-re" : q.m_im ? "--m-im" : "--x";
    const std::string second = q.particle_n      ? "--particle-n"
                               : q.particle_k    ? "--particle-k"
                               : q.host_n        ? "--host-n"
                               : q.radius_um     ? "--radius-um"
                               : q.wavelength_nm ? "--wavelength-nm"
                                                 : "--lognormal-sigma";
    throw Error("", second,
                "cannot be combined with " + first +
                    " (give m and x, or the particle, host, radius and wavelength)");
  }
  if (!relative && !physical)
    throw Error("", "--m-re",
                "give --m-re/--m-im/--x, or --particle-n/--host-n/--radius-um/--wavelength-nm");
  p.relative = relative;
  // Scattering angles are the request's: the library's Mie functions see only their cosines.
  for (double a : q.angles_deg) {
    if (a < 0 || a > 180) throw Error("", "--angles-deg", "angles must lie in [0, 180] degrees");
    p.mu.push_back(std::cos(deg_to_rad(a)));
  }
  return p;
}

nlohmann::json run_mie(const MiePlan& p) {
  const MieRequest& q = p.request;
  if (!p.relative) return run_physical_mie(q, p.mu);
  const std::complex<double> m(required_mie_value(q.m_re, "--m-re"), q.m_im.value_or(0.0));
  const MieResult res = mie_sphere(m, required_mie_value(q.x, "--x"), p.mu);
  nlohmann::json j = {{"x", res.x}, {"m_re", m.real()}, {"m_im", m.imag()}};
  add_mie_sphere(j, res, q.angles_deg);
  return j;
}

}  // namespace weft
