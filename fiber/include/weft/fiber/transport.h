#pragma once
// Photon transport in a homogeneous scattering medium bounded by a smooth dielectric surface:
// one engine, two geometries (an infinite circular cylinder, the fiber; a plane-parallel slab,
// for validation against MCML and analytic results).
//
// Conventions, stated once:
// * Lengths are in any one unit (the slab CLI uses mm, fibers use um); mu_a and mu_s are in the
//   inverse of that unit. Free paths follow e^(-mu_t l), mu_t = mu_a + mu_s.
// * Slab: the medium fills -thickness <= z <= 0 (thickness may be +infinity). The top face
//   z = 0 (boundary kTop) has outward normal +z and index n_above outside; the bottom face
//   z = -thickness (kBottom) has outward normal -z and index n_below outside.
// * Cylinder: the axis is the x axis, the cross-section is the (y, z) plane and the medium fills
//   y^2 + z^2 <= radius^2 (boundary kSurface, index n_outside outside). At the surface point of
//   angle phi the fiber frame (docs/fiber-bsdf.md) is n = (0, cos phi, sin phi) (outward), t = (1,
//   0, 0) (the axis) and b = n x t = (0, sin phi, -cos phi): cylinder_frame() returns it.
// * Boundaries: unpolarized Fresnel reflectance R at every hit from inside, total internal
//   reflection included. The photon is reflected with probability R and transmitted otherwise
//   (no splitting: every photon keeps one path, which keeps the walk free of recursion and the
//   estimate unbiased). Index-matched faces (n outside == n inside) transmit without a draw.
// * Entry from outside (launch_external) splits deterministically: the Fresnel-reflected part
//   w R goes to PhotonTally::specular (its mirror direction is returned), w (1 - R) is refracted
//   in and traced, as MCML does with its specular reflectance.
// * A rough boundary (TransportOptions::boundary_scatter) replaces both: every hit, from outside
//   or inside, is one draw of the interface's scattering (reflected or transmitted, whole weight).
// * Weights: WeightMode::implicit_capture deposits w mu_a / mu_t into 'absorbed' at each
//   interaction and always scatters; below roulette_threshold the photon survives a Russian
//   roulette with probability roulette_survival and has its weight divided by it (MCML's scheme,
//   unbiased). WeightMode::analog absorbs the whole photon with probability mu_a / mu_t.
//   WeightMode::absorption_weight draws free paths from mu_s alone and multiplies the weight by
//   exp(-mu_a l) over every length l travelled (to the boundary too), without roulette (it would
//   decide on the weight): a photon's path and the random numbers it draws then do not depend on
//   mu_a, so at a fixed seed a change of absorption changes weights, not paths, and an estimate is
//   a smooth function of mu_a (the fit's inner bake, docs/verify.md). Unbiased: exp(-mu_a l) is
//   the analog walk's probability of surviving the length l. Paths are as long as without
//   absorption, so it costs more where mu_a is large.
// * Energy bookkeeping is exact to rounding: per launched weight w,
//     w = specular + exited + absorbed + roulette_loss - roulette_gain + lost,
//   where roulette_loss is the weight of photons killed by roulette, roulette_gain the weight
//   added to survivors (their difference has mean zero), and 'lost' the weight of photons that
//   hit the interaction cap (max_events scatterings + internal reflections) or travel without end
//   (a path that neither interacts nor meets the boundary). Nothing is dropped silently.
// * Exits go to a recorder: any type with `void on_exit(const ExitEvent&)`. NullRecorder does
//   nothing, so a bare walk compiles to the walk alone.
// * TransportOptions::expected_exits (smooth boundary only) records exits by next-event
//   estimation: where a flight starts (the walk's start, each scattering) the flight's specular
//   chain is followed to the boundary and every hit's transmitted weight,
//   w exp(-(mu_a + mu_s) L) (1 - R) times the reflectances before it, is recorded; the chain stops
//   after the hit where its weight falls below expected_exit_cutoff * w (or at
//   kMaxExpectedExitHits). The walk itself is unchanged (same draws, same path), but its own exit
//   is recorded only when it happens after more internal reflections since the flight's start
//   than the chain covered: the two partition the exits, so the estimate is unbiased. Books:
//   'exited' is what the recorder got; expected_exit_excess = recorded expected weight minus the
//   walk's exits it replaced (mean zero), so the books still close exactly.
#include <algorithm>
#include <cmath>
#include <concepts>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <utility>

#include "weft/core/error.h"
#include "weft/core/frame.h"
#include "weft/core/math.h"
#include "weft/core/rng.h"
#include "weft/core/vec.h"
#include "weft/fiber/phase_function.h"
#include "weft/materials/fresnel.h"

namespace weft {

// +infinity, named once: a semi-infinite slab thickness, a ray that never meets the boundary.
inline constexpr double kTransportInfinity = std::numeric_limits<double>::infinity();
// The most boundary hits of one flight's chain that next-event estimation records (a chain of
// total internal reflections in a clear medium never falls below the cutoff).
inline constexpr int kMaxExpectedExitHits = 32;

// The medium inside the boundary.
struct TransportMedium {
  double mu_a = 0;  // absorption coefficient [1/length]
  double mu_s = 0;  // scattering coefficient [1/length]
  double n = 1;     // refractive index inside
  PhaseFunction phase = PhaseFunction::henyey_greenstein(0);

  // Throws weft::Error naming the field (mu_a, mu_s, n) when a value is negative or not finite.
  void validate() const;
};

enum class WeightMode : uint8_t { implicit_capture, analog, absorption_weight };

// What a rough boundary (TransportOptions::boundary_scatter) did with a photon.
struct BoundaryScatter {
  Vec3 direction;     // after the interface, local frame of the boundary point (unit)
  bool lost = false;  // the boundary model gave up on the photon (booked as lost)
};

struct TransportOptions {
  WeightMode mode = WeightMode::implicit_capture;
  double roulette_threshold = 1e-4;  // MCML's default weight threshold
  double roulette_survival = 0.1;    // MCML's "chance" (m = 10)
  // Cap on interactions per photon (scatterings plus internal reflections); the weight of a photon
  // that reaches it goes to PhotonTally::lost.
  uint64_t max_events = 10'000'000;
  // Optional reflectance of the boundary for a photon leaving the medium, as a function of the
  // cosine OUTSIDE (after refraction). Empty: the smooth Fresnel reflectance. The fiber baker sets
  // it to the rough surface's reflectance so that exits and entries see the same boundary
  // transmittance, which keeps the fiber's scattering reciprocal. Total internal reflection is
  // unaffected.
  std::function<double(double cos_outside)> exit_reflectance;
  // Optional: a rough interface in place of the smooth boundary, at entries (launch_external)
  // and exits alike. Given the photon's travelling direction d in the local frame of the
  // boundary point (z = outward normal; d.z < 0 arriving from outside, d.z > 0 from inside), it
  // returns the direction after the interface: z > 0 outside, z < 0 inside. Empty: Fresnel at
  // the smooth normal. Excludes exit_reflectance.
  std::function<BoundaryScatter(const Vec3& d_local, Rng& rng)> boundary_scatter;
  // Next-event estimation of exits (see the conventions above); excludes boundary_scatter.
  bool expected_exits = false;
  double expected_exit_cutoff = 1e-3;  // relative weight below which a chain stops, in (0, 1)

  void validate() const;
};

// One photon leaving the medium.
struct ExitEvent {
  Vec3 position;   // on the boundary
  Vec3 direction;  // outside the medium, after refraction (unit)
  double weight = 0;
  int boundary = 0;          // SlabGeometry::kTop / kBottom, CylinderGeometry::kSurface
  uint64_t scatterings = 0;  // scattering events before the exit (0: unscattered)
};

// The energy books of photon transport: weight and event counts, per photon or accumulated over
// many (operator+=). The project's one energy tally: the slab, the cylinder beam, the BSSRDF and
// the fiber bakers all keep their books in it.
struct PhotonTally {
  uint64_t photons = 0;  // launches
  double launched = 0;   // weight launched
  double specular = 0;   // reflected at entry (external launches; the fiber's surface lobe)
  // Where the reflection at entry is sampled rather than split (the fiber bakers draw one
  // direction of the rough surface lobe, weight f cos / pdf, while 1 - albedo enters), the sampled
  // weight minus its expectation: mean zero, kept so that the books still close exactly.
  double specular_excess = 0;
  double exited = 0;  // passed to the recorder (after entering)
  // With expected exits (TransportOptions::expected_exits): the expected weight recorded minus the
  // walk's own exits it stands for (mean zero), so that the books close exactly.
  double expected_exit_excess = 0;
  double absorbed = 0;
  double roulette_gain = 0;  // weight added to roulette survivors
  double roulette_loss = 0;  // weight of photons killed by roulette
  double lost = 0;           // interaction cap or endless path
  uint64_t scatterings = 0;
  uint64_t reflections = 0;  // internal reflections at the boundary (Fresnel or total)

  PhotonTally& operator+=(const PhotonTally& o) {
    photons += o.photons;
    launched += o.launched;
    specular += o.specular;
    specular_excess += o.specular_excess;
    exited += o.exited;
    expected_exit_excess += o.expected_exit_excess;
    absorbed += o.absorbed;
    roulette_gain += o.roulette_gain;
    roulette_loss += o.roulette_loss;
    lost += o.lost;
    scatterings += o.scatterings;
    reflections += o.reflections;
    return *this;
  }
  // launched - (everything accounted for): zero up to rounding.
  double imbalance() const {
    return launched - (specular - specular_excess + exited - expected_exit_excess + absorbed +
                       roulette_loss - roulette_gain + lost);
  }
};

template <class R>
concept ExitRecorder = requires(R r, const ExitEvent& e) {
  r.on_exit(e);
};

struct NullRecorder {
  void on_exit(const ExitEvent&) {}
};

struct BoundaryHit {
  double distance =
      kTransportInfinity;  // along the unit direction; +inf when the ray never meets it
  int boundary = 0;
};

// Plane-parallel slab (see the conventions above).
class SlabGeometry {
 public:
  static constexpr int kTop = 0, kBottom = 1;

  // thickness > 0 (may be +infinity: a semi-infinite medium), indices >= 1e-6 and finite.
  SlabGeometry(double thickness, double n_above, double n_below);

  double thickness() const { return thickness_; }
  bool semi_infinite() const { return !std::isfinite(thickness_); }
  double n_outside(int boundary) const { return boundary == kTop ? n_above_ : n_below_; }
  bool contains(const Vec3& p) const { return p.z <= 0 && p.z >= -thickness_; }

  BoundaryHit distance_to_boundary(const Vec3& p, const Vec3& d) const {
    // Only the face the direction points to can be hit, so a photon sitting on one face after a
    // reflection never re-hits it at distance ~0.
    if (d.z > 0) return {std::max(0.0, -p.z / d.z), kTop};
    if (d.z < 0 && !semi_infinite()) return {std::max(0.0, (-thickness_ - p.z) / d.z), kBottom};
    return {kTransportInfinity, kTop};
  }
  Vec3 outward_normal(const Vec3&, int boundary) const {
    return boundary == kTop ? Vec3{0, 0, 1} : Vec3{0, 0, -1};
  }
  // Puts a point that reached a face exactly on it.
  Vec3 snap(Vec3 p, int boundary) const {
    p.z = boundary == kTop ? 0.0 : -thickness_;
    return p;
  }
  bool valid_boundary(int boundary) const {
    return boundary == kTop || (boundary == kBottom && !semi_infinite());
  }

 private:
  double thickness_, n_above_, n_below_;
};

// Infinite circular cylinder around the x axis (see the conventions above).
class CylinderGeometry {
 public:
  static constexpr int kSurface = 0;

  // radius > 0 and finite, n_outside >= 1e-6 and finite.
  CylinderGeometry(double radius, double n_outside);

  double radius() const { return radius_; }
  double n_outside(int) const { return n_outside_; }
  bool contains(const Vec3& p) const { return p.y * p.y + p.z * p.z <= radius2_; }

  BoundaryHit distance_to_boundary(const Vec3& p, const Vec3& d) const {
    // |p2 + t d2|^2 = r^2 in the cross-section: a t^2 + 2 b t + c = 0, c <= 0 inside.
    const double a = d.y * d.y + d.z * d.z;
    if (!(a > 0)) return {kTransportInfinity, kSurface};  // along the axis: never meets the wall
    const double b = p.y * d.y + p.z * d.z;
    const double c = p.y * p.y + p.z * p.z - radius2_;
    const double sq = std::sqrt(std::max(0.0, b * b - a * c));
    // Larger root without cancellation: moving outwards (b > 0) use c / (a t_minus), which stays
    // accurate for photons on the wall (c ~ 0); moving inwards the plain form has no cancellation.
    const double t = b > 0 ? -c / (b + sq) : (sq - b) / a;
    return {std::max(0.0, t), kSurface};
  }
  Vec3 outward_normal(const Vec3& p, int) const {
    return Vec3{0, p.y * inv_radius_, p.z * inv_radius_};
  }
  // Projects a point radially onto the wall (the axial coordinate is kept).
  Vec3 snap(Vec3 p, int) const {
    const double r = std::hypot(p.y, p.z);
    if (r > 0) {
      p.y *= radius_ / r;
      p.z *= radius_ / r;
    }
    return p;
  }
  bool valid_boundary(int boundary) const { return boundary == kSurface; }

  // Surface point at angle phi around the axis and axial position x.
  Vec3 surface_point(double phi, double x) const {
    return {x, radius_ * std::cos(phi), radius_ * std::sin(phi)};
  }
  // The fiber frame at angle phi: s = t (axis), t = b, n = outward normal (frame.h's fiber
  // convention: local x = tangent, y = binormal, z = normal).
  static Frame cylinder_frame(double phi) {
    const double c = std::cos(phi), s = std::sin(phi);
    return Frame{Vec3{1, 0, 0}, Vec3{0, s, -c}, Vec3{0, c, s}};
  }

 private:
  double radius_, radius2_, inv_radius_, n_outside_;
};

template <class G>
concept TransportGeometry = requires(const G& g, const Vec3& p, const Vec3& d, int b) {
  { g.distance_to_boundary(p, d) } -> std::same_as<BoundaryHit>;
  { g.outward_normal(p, b) } -> std::same_as<Vec3>;
  { g.snap(p, b) } -> std::same_as<Vec3>;
  { g.n_outside(b) } -> std::convertible_to<double>;
  { g.contains(p) } -> std::same_as<bool>;
  { g.valid_boundary(b) } -> std::same_as<bool>;
};

// What an external launch returns: the Fresnel-reflected part (already added to
// PhotonTally::specular) and its mirror direction.
struct EntryResult {
  double specular_weight = 0;
  Vec3 specular_direction;
};

template <TransportGeometry Geometry>
class PhotonTransport {
 public:
  // Validates the medium and options (weft::Error naming the field).
  PhotonTransport(Geometry geometry, TransportMedium medium, TransportOptions options = {})
      : geometry_(std::move(geometry)), medium_(std::move(medium)), options_(options) {
    medium_.validate();
    options_.validate();
    mu_t_ = medium_.mu_a + medium_.mu_s;
    if (!std::isfinite(mu_t_)) throw Error("", "mu_a", "mu_a + mu_s overflows");
    mu_total_ = mu_t_;
    absorb_fraction_ = mu_t_ > 0 ? medium_.mu_a / mu_t_ : 0.0;
    // mu_t_ is the coefficient free paths are drawn from: mu_s alone when absorption is a weight.
    if (options_.mode == WeightMode::absorption_weight) mu_t_ = medium_.mu_s;
    inv_mu_t_ = mu_t_ > 0 ? 1.0 / mu_t_ : kTransportInfinity;
    inv_survival_ = 1.0 / options_.roulette_survival;
  }

  const Geometry& geometry() const { return geometry_; }
  const TransportMedium& medium() const { return medium_; }
  const TransportOptions& options() const { return options_; }

  // (a) A photon of weight w arriving from outside at 'position' on 'boundary' (the point is
  // projected onto it), travelling along unit 'direction' into the medium.
  template <ExitRecorder Recorder>
  EntryResult launch_external(int boundary, const Vec3& position, const Vec3& direction,
                              double weight, Rng& rng, Recorder& recorder,
                              PhotonTally& tally) const {
    if (!geometry_.valid_boundary(boundary))
      throw Error("", "boundary", "no boundary " + std::to_string(boundary) + " in this geometry");
    if (!(weight >= 0) || !std::isfinite(weight))
      throw Error("", "weight", "must be finite and >= 0");
    const Vec3 p = geometry_.snap(position, boundary);
    const Vec3 n = geometry_.outward_normal(p, boundary);
    // Exactly grazing arrivals (cos_i = 0, e.g. a beam's edge) are allowed: Fresnel reflects all.
    const double cos_i = std::max(0.0, -dot(direction, n));
    if (!is_finite(p) || !(-dot(direction, n) > -1e-9) ||
        !(std::abs(length_squared(direction) - 1) < 1e-9))
      throw Error("", "direction", "must be a unit vector pointing into the medium");
    tally.photons += 1;
    tally.launched += weight;
    if (options_.boundary_scatter) {
      // The rough interface decides: reflected (whole weight, as specular) or refracted in.
      const Frame frame = Frame::from_normal(n);
      const BoundaryScatter b = options_.boundary_scatter(frame.to_local(direction), rng);
      if (b.lost) {
        tally.lost += weight;
        return {};
      }
      const Vec3 out = normalize(frame.to_world(b.direction));
      if (b.direction.z > 0) {
        tally.specular += weight;
        return {weight, out};
      }
      walk(p, out, weight, rng, recorder, tally);
      return {};
    }
    const double n_out = geometry_.n_outside(boundary);
    double cos_t = cos_i;
    const double r = n_out == medium_.n ? 0.0 : fresnel_dielectric(cos_i, n_out, medium_.n, &cos_t);
    const EntryResult entry{weight * r, direction + 2 * cos_i * n};
    tally.specular += entry.specular_weight;
    if (r < 1) {
      const double eta = n_out / medium_.n;
      const Vec3 inside = normalize(eta * direction + (eta * cos_i - cos_t) * n);
      walk(p, inside, weight * (1 - r), rng, recorder, tally);
    }
    return entry;
  }

  // (b) A photon of weight w starting inside the medium at 'position' along unit 'direction'.
  template <ExitRecorder Recorder>
  void launch_internal(const Vec3& position, const Vec3& direction, double weight, Rng& rng,
                       Recorder& recorder, PhotonTally& tally) const {
    if (!is_finite(position) || !geometry_.contains(position))
      throw Error("", "position", "must lie inside the medium");
    if (!(std::abs(length_squared(direction) - 1) < 1e-9))
      throw Error("", "direction", "must be a unit vector");
    if (!(weight >= 0) || !std::isfinite(weight))
      throw Error("", "weight", "must be finite and >= 0");
    tally.photons += 1;
    tally.launched += weight;
    walk(position, direction, weight, rng, recorder, tally);
  }

 private:
  template <ExitRecorder Recorder>
  void walk(Vec3 p, Vec3 d, double w, Rng& rng, Recorder& recorder, PhotonTally& tally) const {
    const double n_in = medium_.n;
    const bool analog = options_.mode == WeightMode::analog;
    const bool weighted = options_.mode == WeightMode::absorption_weight;
    // Absorption over a length, as a weight (absorption_weight only).
    const auto attenuate = [&](double length) {
      const double kept = w * std::exp(-medium_.mu_a * length);
      tally.absorbed += w - kept;
      w = kept;
    };
    uint64_t events = 0, scatterings = 0;
    // Next-event estimation: the boundary hits of this flight's chain that were recorded as
    // expected exits, and the walk's internal reflections since the flight began.
    const bool expected = options_.expected_exits;
    int flight_chain = expected ? record_expected_exits(p, d, w, 0, recorder, tally) : 0;
    int flight_reflections = 0;
    // The walk's own exit along 'out': recorded, unless the flight's chain already stood for it.
    const auto leave = [&](const Vec3& out, int boundary) {
      if (flight_reflections < flight_chain) {
        tally.expected_exit_excess -= w;
      } else {
        recorder.on_exit(ExitEvent{p, out, w, boundary, scatterings});
        tally.exited += w;
      }
      tally.scatterings += scatterings;
    };
    // A weighted photon walks on at weight 0 (underflow), so that the draws it makes, and so the
    // next photon's, do not depend on mu_a.
    while (w > 0 || weighted) {
      const BoundaryHit hit = geometry_.distance_to_boundary(p, d);
      const double s = mu_t_ > 0 ? -std::log(rng.uniform_open0()) * inv_mu_t_ : kTransportInfinity;
      if (s >= hit.distance) {
        if (!std::isfinite(hit.distance)) break;  // never interacts, never leaves: lost
        if (weighted) attenuate(hit.distance);
        p = geometry_.snap(p + hit.distance * d, hit.boundary);
        const Vec3 n = geometry_.outward_normal(p, hit.boundary);
        const double n_out = geometry_.n_outside(hit.boundary);
        const double cos_i = dot(d, n);
        if (options_.boundary_scatter) {
          const Frame frame = Frame::from_normal(n);
          const BoundaryScatter b = options_.boundary_scatter(frame.to_local(d), rng);
          if (b.lost) break;
          const Vec3 out = normalize(frame.to_world(b.direction));
          if (b.direction.z > 0) {
            leave(out, hit.boundary);
            return;
          }
          d = out;
          ++tally.reflections;
          if (++events >= options_.max_events) break;
          continue;
        }
        if (n_out == n_in) {
          leave(d, hit.boundary);
          return;
        }
        double cos_t = 0;
        double r = fresnel_dielectric(cos_i, n_in, n_out, &cos_t);
        if (options_.exit_reflectance && r < 1) r = options_.exit_reflectance(cos_t);
        if (r < 1 && rng.uniform() >= r) {
          const double eta = n_in / n_out;
          leave(normalize(eta * d + (cos_t - eta * cos_i) * n), hit.boundary);
          return;
        }
        // Reflect only if the photon really moves outwards (rounding at grazing incidence).
        if (cos_i > 0) d = normalize(d - 2 * cos_i * n);
        ++tally.reflections;
        ++flight_reflections;
        if (++events >= options_.max_events) break;
        continue;
      }
      p += s * d;
      if (weighted) {
        attenuate(s);
      } else if (analog) {
        if (rng.uniform() < absorb_fraction_) {
          tally.absorbed += w;
          w = 0;
          break;
        }
      } else {
        const double dw = w * absorb_fraction_;
        tally.absorbed += dw;
        w -= dw;
        if (!(w > 0)) break;  // mu_s = 0: the interaction was pure absorption, not a scattering
      }
      const double u1 = rng.uniform(), u2 = rng.uniform();
      d = medium_.phase.sample_direction(d, u1, u2);
      ++scatterings;
      if (++events >= options_.max_events) break;
      if (!analog && !weighted) roulette(w, rng, tally);
      if (expected && w > 0)
        flight_chain = record_expected_exits(p, d, w, scatterings, recorder, tally);
      flight_reflections = 0;
    }
    tally.lost += w;  // zero unless the cap or an endless path stopped the walk
    tally.scatterings += scatterings;
  }

  // MCML's Russian roulette below the weight threshold: survivors' weight divided by the survival
  // probability (unbiased); both sides booked.
  void roulette(double& w, Rng& rng, PhotonTally& tally) const {
    if (!(w < options_.roulette_threshold && w > 0)) return;
    if (rng.uniform() < options_.roulette_survival) {
      const double w_new = w * inv_survival_;
      tally.roulette_gain += w_new - w;
      w = w_new;
    } else {
      tally.roulette_loss += w;
      w = 0;
    }
  }

  // Next-event estimation of one flight's exits (see the conventions above): follows the specular
  // chain from p along d, records each hit's expected transmitted weight and returns how many hits
  // it covered. Draws no random numbers.
  template <ExitRecorder Recorder>
  int record_expected_exits(Vec3 p, Vec3 d, double w, uint64_t scatterings, Recorder& recorder,
                            PhotonTally& tally) const {
    const double n_in = medium_.n;
    double carried = w;  // the weight still travelling along the chain
    int hits = 0;
    while (hits < kMaxExpectedExitHits) {
      const BoundaryHit hit = geometry_.distance_to_boundary(p, d);
      if (!std::isfinite(hit.distance)) break;  // the walk never meets the boundary either
      carried *= std::exp(-mu_total_ * hit.distance);
      p = geometry_.snap(p + hit.distance * d, hit.boundary);
      ++hits;
      const Vec3 n = geometry_.outward_normal(p, hit.boundary);
      const double n_out = geometry_.n_outside(hit.boundary);
      const double cos_i = dot(d, n);
      double r = 0, cos_t = cos_i;
      Vec3 out = d;
      if (n_out != n_in) {
        r = fresnel_dielectric(cos_i, n_in, n_out, &cos_t);
        if (options_.exit_reflectance && r < 1) r = options_.exit_reflectance(cos_t);
        const double eta = n_in / n_out;
        if (r < 1) out = normalize(eta * d + (cos_t - eta * cos_i) * n);
      }
      if (r < 1 && carried > 0) {
        const double x = carried * (1 - r);
        recorder.on_exit(ExitEvent{p, out, x, hit.boundary, scatterings});
        tally.exited += x;
        tally.expected_exit_excess += x;
      }
      carried *= r;
      if (!(carried >= options_.expected_exit_cutoff * w)) break;
      if (cos_i > 0) d = normalize(d - 2 * cos_i * n);
    }
    return hits;
  }

  Geometry geometry_;
  TransportMedium medium_;
  TransportOptions options_;
  double mu_t_ = 0, inv_mu_t_ = 0, absorb_fraction_ = 0, inv_survival_ = 1;
  double mu_total_ = 0;  // mu_a + mu_s: a flight's survival to the boundary in every weight mode
};

using SlabTransport = PhotonTransport<SlabGeometry>;
using CylinderTransport = PhotonTransport<CylinderGeometry>;

}  // namespace weft
