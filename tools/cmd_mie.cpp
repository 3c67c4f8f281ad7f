// weft mie: Mie efficiencies, g and amplitudes of a sphere (or a lognormal ensemble).
// weft medium: per-band scattering and absorption of a fiber spec or preset.
// Both bind their requests (fiber/mie_request.h, fiber/medium.h), run their plans and print.
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>

#include "commands.h"
#include "weft/core/error.h"
#include "weft/fiber/medium.h"
#include "weft/fiber/mie_request.h"

namespace weft::cli {
namespace {

// Options arrive as text so that malformed and non-finite values are reported with the option's
// name, like every other input error. Ranges are the library's to check (mie.h): its errors name
// the field (m, x, particle_n, host_n, radius_um, wavelength_nm, size.sigma).
struct MieOptions {
  std::string m_re, m_im, x;
  std::string particle_n, particle_k, host_n, radius_um, wavelength_nm, sigma;
  std::string angles_deg;
  bool json = false;
};

std::optional<double> number(const std::string& text, const std::string& option) {
  if (text.empty()) return std::nullopt;
  if (const auto v = finite_number(text)) return v;
  throw Error("", option, "'" + text + "' is not a finite number");
}

// The options' texts as numbers, each refusal naming its option; the rest is the library's.
MieRequest mie_request(const MieOptions& o) {
  MieRequest q;
  q.m_re = number(o.m_re, "--m-re"), q.m_im = number(o.m_im, "--m-im");
  q.x = number(o.x, "--x");
  q.particle_n = number(o.particle_n, "--particle-n");
  q.particle_k = number(o.particle_k, "--particle-k");
  q.host_n = number(o.host_n, "--host-n"), q.radius_um = number(o.radius_um, "--radius-um");
  q.wavelength_nm = number(o.wavelength_nm, "--wavelength-nm");
  q.lognormal_sigma = number(o.sigma, "--lognormal-sigma");
  if (!o.angles_deg.empty()) q.angles_deg = parse_range(o.angles_deg, "--angles-deg");
  return q;
}

int run_mie_command(const MieOptions& o) {
  const MiePlan plan = plan_mie(mie_request(o));
  const nlohmann::json j = run_mie(plan);
  if (o.json) {
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  std::printf("x = %.10g  m = %.10g + %.10gi\n", j["x"].get<double>(), j["m_re"].get<double>(),
              j["m_im"].get<double>());
  std::printf("Q_ext = %.10g\nQ_sca = %.10g\nQ_abs = %.10g\nQ_back = %.10g\ng = %.10g\n",
              j["qext"].get<double>(), j["qsca"].get<double>(), j["qabs"].get<double>(),
              j["qback"].get<double>(), j["g"].get<double>());
  if (j.contains("csca_um2"))
    std::printf("C_ext = %.10g um^2\nC_sca = %.10g um^2\nC_abs = %.10g um^2\n",
                j["cext_um2"].get<double>(), j["csca_um2"].get<double>(),
                j["cabs_um2"].get<double>());
  if (j.contains("phase_function_per_sr")) {
    std::printf("%10s %16s\n", "angle_deg", "p (1/sr)");
    const auto& angles = plan.request.angles_deg;
    for (size_t i = 0; i < angles.size(); ++i)
      std::printf("%10.4g %16.8g\n", angles[i], j["phase_function_per_sr"][i].get<double>());
  }
  return 0;
}

struct MediumCliOptions {
  MediumRequest request;
  std::string wavelengths;
  bool json = false, quiet = false;
};

int run_medium_command(const MediumCliOptions& o, const RunLimits& limits) {
  MediumRequest r = o.request;
  if (!o.wavelengths.empty()) r.wavelengths_nm = parse_range(o.wavelengths, "--wavelengths-nm");
  const MediumPlan plan = plan_medium(r);
  const nlohmann::json j = run_medium(plan, progress_bar(limits, o.quiet));
  if (o.json) {
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  std::printf("%s (hash %s), fiber radius %g um\n", j["name"].get<std::string>().c_str(),
              j["hash"].get<std::string>().c_str(), j["fiber_radius_um"].get<double>());
  std::printf("%6s %8s %12s %12s %8s %8s\n", "nm", "n_host", "mu_s/um", "mu_a/um", "albedo", "g");
  for (const auto& b : j["bands"])
    std::printf("%6.0f %8.4f %12.6g %12.6g %8.5f %8.5f\n", b["wavelength_nm"].get<double>(),
                b["host_n"].get<double>(), b["mu_s_per_um"].get<double>(),
                b["mu_a_per_um"].get<double>(), b["albedo"].get<double>(), b["g"].get<double>());
  return 0;
}

}  // namespace

void add_mie_command(CLI::App& app, Commands& commands) {
  auto o = std::make_shared<MieOptions>();
  auto* sub = app.add_subcommand(
      "mie", "Mie efficiencies, g, amplitudes and phase function of a sphere (m = n + ik, k >= 0)");
  sub->add_option("--m-re", o->m_re, "real part of the relative index m");
  sub->add_option("--m-im", o->m_im, "imaginary part of m (>= 0 absorbing; default 0)");
  sub->add_option("--x", o->x, "size parameter 2 pi n_host r / lambda");
  sub->add_option("--particle-n", o->particle_n, "particle refractive index (real part)");
  sub->add_option("--particle-k", o->particle_k, "particle extinction coefficient k (default 0)");
  sub->add_option("--host-n", o->host_n, "host refractive index (real)");
  sub->add_option("--radius-um", o->radius_um, "sphere radius (lognormal: median radius), um");
  sub->add_option("--wavelength-nm", o->wavelength_nm, "vacuum wavelength, nm");
  sub->add_option("--lognormal-sigma", o->sigma,
                  "average over a lognormal size distribution with this sigma of ln r");
  sub->add_option("--angles-deg", o->angles_deg,
                  "scattering angles a:b:step or a,b,c (degrees) for S1, S2 and p(theta)");
  sub->add_flag("--json", o->json, "print JSON");
  commands.push_back({sub, [o](const RunLimits&) { return run_mie_command(*o); }});
}

void add_medium_command(CLI::App& app, Commands& commands) {
  auto o = std::make_shared<MediumCliOptions>();
  auto* sub = app.add_subcommand(
      "medium", "Per-band mu_s, mu_a, albedo and g of a fiber spec file or preset");
  sub->add_option("spec", o->request.spec, "spec file, or a preset (docs/presets.md)")->required();
  sub->add_option("--wavelengths-nm", o->wavelengths,
                  "band centres a:b:step or a,b,c (default all)");
  sub->add_option("--threads", o->request.threads, "threads (0 = all cores)");
  sub->add_flag("--json", o->json, "print JSON");
  sub->add_flag("--quiet", o->quiet, "no progress bar");
  commands.push_back({sub, [o](const RunLimits& l) { return run_medium_command(*o, l); }});
}

}  // namespace weft::cli
