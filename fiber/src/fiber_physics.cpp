#include "weft/fiber/fiber_physics.h"

#include <algorithm>
#include <cmath>

#include "weft/core/error.h"
#include "weft/core/frame.h"
#include "weft/core/math.h"
#include "weft/materials/cook_torrance.h"
#include "weft/materials/fresnel.h"

namespace weft {

FiberInterior FiberInterior::transport(std::shared_ptr<const CylinderTransport> transport) {
  FiberInterior in;
  in.geometry = transport->geometry();
  in.n_inside = transport->medium().n;
  in.trace = [transport](const Vec3& p, const Vec3& d, double w, Rng& rng, const ExitSink& sink) {
    struct Forward {
      const ExitSink* sink;
      void on_exit(const ExitEvent& e) { (*sink)(e); }
    } recorder{&sink};
    PhotonTally tally;
    // The entry point sits on the wall; nudge it inside so rounding cannot put it outside.
    transport->launch_internal(p * (1 - 1e-12), d, w, rng, recorder, tally);
    return tally;
  };
  return in;
}

void FiberBandPhysics::validate() const {
  if (!(interior.n_inside >= 1) || !std::isfinite(interior.n_inside))
    throw Error("", "n_inside", "fiber refractive index must be finite and >= 1");
  if (!(interior.geometry.n_outside(CylinderGeometry::kSurface) >= 1))
    throw Error("", "n_outside", "outside refractive index must be >= 1");
  if (!boundary && !surface.albedo) throw Error("", "surface", "the surface model needs an albedo");
  if (!interior.trace) throw Error("", "trace", "the interior needs a tracer");
}

FiberBandPhysics smooth_fiber_physics(const TransportMedium& medium, double radius,
                                      double n_outside, TransportOptions options) {
  FiberBandPhysics ph;
  const double n_in = medium.n;
  ph.surface.sample = [n_outside, n_in](const Vec3& w, Vec2, double, Vec3* w_out, double* weight) {
    *w_out = Vec3{-w.x, -w.y, w.z};  // the mirror direction, weight R (a delta lobe)
    *weight = n_outside == n_in ? 0.0 : fresnel_dielectric(w.z, n_outside, n_in);
    return *weight > 0;
  };
  ph.surface.albedo = [n_outside, n_in](double c) {
    return n_outside == n_in ? 0.0 : fresnel_dielectric(c, n_outside, n_in);
  };
  options.exit_reflectance = nullptr;
  ph.interior = FiberInterior::transport(std::make_shared<const CylinderTransport>(
      CylinderGeometry(radius, n_outside), medium, options));
  return ph;
}

TransportMedium fiber_band_medium(const MediumBand& mb) {
  return TransportMedium{mb.mu_a_per_um, mb.mu_s_per_um, mb.host_n, mb.phase};
}

const char* fiber_exit_estimator_name(FiberExitEstimator e) {
  return name_of(kFiberExitEstimators, e);
}

FiberExitEstimator parse_fiber_exit_estimator(const std::string& name, const std::string& field) {
  return value_of(kFiberExitEstimators, name, "", field);
}

TransportOptions fiber_band_transport_options(const FiberBandPhysics& fiber,
                                              uint64_t max_events_per_photon, WeightMode mode,
                                              FiberExitEstimator estimator) {
  TransportOptions topt;
  topt.max_events = max_events_per_photon;
  topt.mode = mode;
  topt.expected_exits = estimator == FiberExitEstimator::kNextEvent;
  if (const auto boundary = fiber.boundary) {
    topt.boundary_scatter = [boundary](const Vec3& d, Rng& rng) {
      const RoughDielectricScatter s = boundary->scatter(d, rng);
      return BoundaryScatter{s.direction, s.lost};
    };
    return topt;
  }
  if (!fiber.surface.albedo) throw Error("", "surface", "the surface model needs an albedo");
  topt.exit_reflectance = fiber.surface.albedo;
  return topt;
}

FiberBandPhysics fiber_band_physics(const FiberSpec& spec, const MediumBand& mb,
                                    uint64_t max_events_per_photon,
                                    std::shared_ptr<const SurfaceAlbedoTable> albedo,
                                    WeightMode mode, FiberExitEstimator estimator) {
  FiberBandPhysics ph;
  if (spec.boundary == FiberBoundary::kRoughDielectric) {
    ph.boundary = std::make_shared<const RoughDielectricInterface>(
        spec.roughness_distribution, spec.roughness_alpha, 1.0, mb.host_n);
  } else {
    auto ct = std::make_shared<const CookTorranceBsdf>(
        CookTorranceBsdf{{spec.roughness_distribution, spec.roughness_alpha}, mb.host_n, Rgb(1.0)});
    if (!albedo)
      albedo = std::make_shared<const SurfaceAlbedoTable>(spec.roughness_distribution,
                                                          spec.roughness_alpha, mb.host_n);
    ph.surface.sample = [ct](const Vec3& w_light, Vec2 u, double u_lobe, Vec3* w_out,
                             double* weight) {
      // Cook-Torrance is reciprocal: sampling the view direction given the light one uses the
      // same routine with the roles swapped; the weight is f cos(out) / pdf.
      const auto smp = ct->sample(w_light, u, u_lobe);
      if (!smp || !(smp->wi.z > 0)) return false;
      *w_out = smp->wi;
      *weight = smp->weight.r;
      return true;
    };
    ph.surface.albedo = [albedo](double c) { return (*albedo)(c); };
  }
  ph.interior = FiberInterior::transport(std::make_shared<const CylinderTransport>(
      CylinderGeometry(spec.fiber_radius_um, 1.0), fiber_band_medium(mb),
      fiber_band_transport_options(ph, max_events_per_photon, mode, estimator)));
  return ph;
}

void enter_fiber(const FiberBandPhysics& fiber, double phi, const Vec3& omega, double w0, Rng& rng,
                 const ExitSink& surface_exits, const ExitSink& interior_exits, PhotonTally& books,
                 std::span<const double> lobe_uniforms) {
  // Light that enters must leave somewhere: an unset sink would drop it (or call an empty
  // std::function) deep inside the transport.
  if (!interior_exits) throw Error("enter_fiber: no sink for the interior's exits (internal)");
  const FiberInterior& in = fiber.interior;
  const Frame frame = CylinderGeometry::cylinder_frame(phi);
  const Vec3 point = in.geometry.radius() * frame.n;
  books.photons += 1;
  books.launched += w0;
  const Vec3 omega_local = frame.to_local(omega);
  const double cos_a = omega_local.z;
  if (!(cos_a > 0)) {  // a grazing edge ray (measure zero): book it, never drop it
    books.lost += w0;
    return;
  }
  const auto trace_inside = [&](const Vec3& d, double w) {
    const PhotonTally inside = in.trace(point, normalize(d), w, rng, interior_exits);
    books.exited += inside.exited;
    books.expected_exit_excess += inside.expected_exit_excess;
    books.absorbed += inside.absorbed;
    books.roulette_gain += inside.roulette_gain;
    books.roulette_loss += inside.roulette_loss;
    books.lost += inside.lost;
    books.scatterings += inside.scatterings;
    books.reflections += inside.reflections;
  };
  if (fiber.boundary) {
    // One rough interface: its walk reflects the photon (the surface part) or refracts it in.
    const RoughDielectricScatter s = fiber.boundary->scatter(-omega_local, rng);
    if (s.lost) {
      books.lost += w0;
    } else if (s.outside) {
      books.specular += w0;
      if (surface_exits)
        surface_exits(
            ExitEvent{point, frame.to_world(s.direction), w0, CylinderGeometry::kSurface, 0});
    } else {
      trace_inside(frame.to_world(s.direction), w0);
    }
    return;
  }
  double sampled_surface = 0;
  // Surface lobe: sampled reflected directions with weight f cos / pdf (expectation = albedo).
  const int samples = std::max(1, fiber.surface.samples);
  if (!lobe_uniforms.empty() && lobe_uniforms.size() != 3 * static_cast<size_t>(samples))
    throw Error("enter_fiber: lobe uniforms do not match the surface samples (internal)");
  for (int k = 0; k < samples; ++k) {
    Vec3 w_out;
    double weight = 0;
    const double* given = lobe_uniforms.empty() ? nullptr : &lobe_uniforms[3 * k];
    const Vec2 u = given ? Vec2{given[0], given[1]} : Vec2{rng.uniform(), rng.uniform()};
    const double u_lobe = given ? given[2] : rng.uniform();
    if (fiber.surface.sample && fiber.surface.sample(omega_local, u, u_lobe, &w_out, &weight) &&
        weight > 0) {
      const double w = w0 * weight / samples;
      sampled_surface += w;
      books.specular += w;
      if (surface_exits)
        surface_exits(ExitEvent{point, frame.to_world(w_out), w, CylinderGeometry::kSurface, 0});
    }
  }
  // The rest enters, refracted at the macroscopic (smooth) normal.
  const double albedo = fiber.surface.albedo(cos_a);
  books.specular_excess += sampled_surface - w0 * albedo;
  const double w_in = w0 * (1 - albedo);
  if (!(w_in > 0)) return;
  Vec3 d;
  const double n_out = in.geometry.n_outside(CylinderGeometry::kSurface);
  if (!refract(-omega, frame.n, n_out, in.n_inside, &d)) {  // impossible from outside
    books.lost += w_in;
    return;
  }
  trace_inside(d, w_in);
}

}  // namespace weft
