#include "weft/fiber/fiber_layer.h"

#include <cmath>
#include <optional>

#include "weft/core/error.h"
#include "weft/core/frame.h"
#include "weft/core/math.h"
#include "weft/core/task_batch.h"
#include "weft/fiber/elliptic_cylinder.h"
#include "weft/fiber/fiber_physics.h"
#include "weft/materials/fresnel.h"

namespace weft {
namespace {

constexpr double kRowGap = 1.02;            // rows 2 % taller than their tallest fiber
constexpr uint64_t kMaxCrossings = 100000;  // fiber crossings and cell steps per photon

// Turns (y, z) by the angle whose cosine and sine are c, s (about the fiber's axis x).
Vec3 turn(const Vec3& v, double c, double s) {
  return {v.x, c * v.y - s * v.z, s * v.y + c * v.z};
}

struct Semi {
  double a, b;  // along the long axis (in the cloth's plane before tilting) and across it
};
Semi semi_axes(double radius_um, double aspect) {
  return {radius_um * std::sqrt(aspect), radius_um / std::sqrt(aspect)};
}

// The layer as the tracer sees it: fibers with the cosine and sine of their tilt.
struct PlacedFiber {
  double y, z, c, s;
};

struct LayerHit {
  size_t fiber = 0;
  double centre_y = 0;  // the image's centre
  double t = 0;
};

class Layer {
 public:
  Layer(const std::vector<LayerFiber>& fibers, Semi semi, double period, double bottom)
      : semi_(semi), period_(period), bottom_(bottom) {
    for (const LayerFiber& f : fibers)
      fibers_.push_back({f.y_um, f.z_um, std::cos(f.tilt_rad), std::sin(f.tilt_rad)});
  }
  double period() const { return period_; }
  double bottom() const { return bottom_; }
  const PlacedFiber& fiber(size_t k) const { return fibers_[k]; }

  // The nearest fiber the ray p + t d meets from outside with 1e-7 um < t < t_max, p.y in
  // [0, period): every fiber and its images one period either side (fibers are narrower than
  // half a period, so these cover the cell).
  std::optional<LayerHit> nearest(const Vec3& p, const Vec3& d, double t_max) const {
    std::optional<LayerHit> best;
    for (size_t k = 0; k < fibers_.size(); ++k) {
      const PlacedFiber& f = fibers_[k];
      const Vec3 dl = turn(d, f.c, -f.s);
      const double dy = dl.y / semi_.a, dz = dl.z / semi_.b;
      const double qa = dy * dy + dz * dz;
      if (!(qa > 0)) continue;
      for (int m = -1; m <= 1; ++m) {
        const double cy = f.y + m * period_;
        const Vec3 q = turn(Vec3{0, p.y - cy, p.z - f.z}, f.c, -f.s);
        const double py = q.y / semi_.a, pz = q.z / semi_.b;
        const double qb = py * dy + pz * dz, qc = py * py + pz * pz - 1;
        const double disc = qb * qb - qa * qc;
        if (!(disc > 0) || qc <= 0) continue;  // missed, or starting on or in this fiber
        const double t = (-qb - std::sqrt(disc)) / qa;
        if (t > 1e-7 && t < t_max && (!best || t < best->t)) best = LayerHit{k, cy, t};
      }
    }
    return best;
  }

 private:
  std::vector<PlacedFiber> fibers_;
  Semi semi_;
  double period_, bottom_;
};

// Per task: beta per ring (above, below) and the books, per photon.
struct LayerTally {
  std::vector<MeanAccumulator> up, down;
  MeanAccumulator reflected, transmitted, absorbed, lost, roulette, excess;
  uint64_t photons = 0, crossings = 0;

  LayerTally& operator+=(const LayerTally& o) {
    if (up.empty()) {
      up.resize(o.up.size());
      down.resize(o.down.size());
    }
    for (size_t k = 0; k < o.up.size(); ++k) {
      up[k] += o.up[k];
      down[k] += o.down[k];
    }
    reflected += o.reflected;
    transmitted += o.transmitted;
    absorbed += o.absorbed;
    lost += o.lost;
    roulette += o.roulette;
    excess += o.excess;
    photons += o.photons;
    crossings += o.crossings;
    return *this;
  }
};

// One photon's fate: where it left (if it did) and its books.
struct PhotonFate {
  bool left = false;
  Vec3 direction;
  double weight = 0;
  double absorbed = 0, lost = 0, roulette = 0, excess = 0;
  uint64_t crossings = 0;
};

struct Exit {
  bool left = false;
  Vec3 position, direction;
  double weight = 0;
  void on_exit(const ExitEvent& e) {
    left = true;
    position = e.position;
    direction = e.direction;
    weight = e.weight;
  }
};

class LayerTracer {
 public:
  LayerTracer(const Layer& layer, const FiberBandPhysics& fiber,
              const EllipticCylinderTransport& transport)
      : layer_(layer), fiber_(fiber), transport_(transport) {}

  // The patch's tilt: its fibers' axes tilted out of the cloth's plane by the crimp, the patch
  // turned about them by the yarn's curvature; each the slope of a sine profile (uniform over the
  // projected area), at most the given angles.
  LayerTracer& tilted(double crimp_deg, double yarn_tilt_deg) {
    tan_crimp_ = std::tan(deg_to_rad(crimp_deg));
    tan_yarn_ = std::tan(deg_to_rad(yarn_tilt_deg));
    return *this;
  }

  // The photon's fate; its exit direction in the cloth's frame.
  PhotonFate trace(Rng& rng) const {
    const double crimp = std::atan(tan_crimp_ * std::cos(2 * kPi * rng.uniform()));
    const double yarn = std::atan(tan_yarn_ * std::cos(2 * kPi * rng.uniform()));
    // Patch to cloth: turn about x (the yarn's curvature), then about y (the crimp).
    const double cg = std::cos(crimp), sg = std::sin(crimp), cb = std::cos(yarn),
                 sb = std::sin(yarn);
    const auto to_cloth = [&](const Vec3& v) {
      const Vec3 u = turn(v, cb, sb);
      return Vec3{cg * u.x + sg * u.z, u.y, -sg * u.x + cg * u.z};
    };
    const auto to_patch = [&](const Vec3& v) {
      const Vec3 u{cg * v.x - sg * v.z, v.y, sg * v.x + cg * v.z};
      return turn(u, cb, -sb);
    };
    PhotonFate fate = trace_in_patch(to_patch(Vec3{0, 0, -1}), rng);
    if (fate.left) fate.direction = normalize(to_cloth(fate.direction));
    return fate;
  }

 private:
  PhotonFate trace_in_patch(Vec3 d, Rng& rng) const {
    PhotonFate fate;
    const double period = layer_.period();
    Vec3 p{0, rng.uniform() * period, 1.0};
    double w = 1;
    while (fate.crossings++ < kMaxCrossings) {
      const double inf = kTransportInfinity;
      const double t_cell = d.y > 0 ? (period - p.y) / d.y : d.y < 0 ? -p.y / d.y : inf;
      const double t_out = d.z > 0   ? (1.0 - p.z) / d.z
                           : d.z < 0 ? (layer_.bottom() - 1.0 - p.z) / d.z
                                     : inf;
      const auto hit = layer_.nearest(p, d, std::min(t_cell, t_out));
      if (!hit) {
        if (t_out <= t_cell) {
          fate.left = true;
          fate.direction = d;
          fate.weight = w;
          return fate;
        }
        p += t_cell * d;
        p.y = d.y > 0 ? 0.0 : period;
        continue;
      }
      const PlacedFiber& f = layer_.fiber(hit->fiber);
      const Vec3 centre{0, hit->centre_y, f.z};
      Vec3 q = transport_.geometry().snap(turn(p + hit->t * d - centre, f.c, -f.s), 0);
      Vec3 dl = turn(d, f.c, -f.s);
      if (!cross_fiber(q, dl, w, rng, fate)) return fate;
      p = centre + turn(q, f.c, f.s);
      d = normalize(turn(dl, f.c, f.s));
      p.y -= period * std::floor(p.y / period);
    }
    fate.lost += w;
    return fate;
  }

  // Light travelling along dl meets the fiber at q (both in the fiber's frame); on return q and
  // dl are where and along which it leaves, w its weight. False: the photon ended in the fiber.
  bool cross_fiber(Vec3& q, Vec3& dl, double& w, Rng& rng, PhotonFate& fate) const {
    const EllipticCylinderGeometry& g = transport_.geometry();
    const Frame frame = Frame::from_normal_tangent(g.outward_normal(q, 0), Vec3{1, 0, 0});
    Vec3 inside;
    if (fiber_.boundary) {
      const RoughDielectricScatter s = fiber_.boundary->scatter(frame.to_local(dl), rng);
      if (s.lost) return fate.lost += w, false;
      if (s.outside) return dl = frame.to_world(s.direction), true;
      inside = frame.to_world(s.direction);
    } else {
      // The surface lobe or the interior, drawn by the lobe's albedo: one path per photon.
      const Vec3 omega = frame.to_local(-dl);
      const double albedo = fiber_.surface.albedo(std::max(0.0, omega.z));
      if (rng.uniform() < albedo) {
        Vec3 out;
        double weight = 0;
        const Vec2 u{rng.uniform(), rng.uniform()};
        const bool ok = fiber_.surface.sample(omega, u, rng.uniform(), &out, &weight);
        const double w_new = ok && weight > 0 ? w * weight / albedo : 0.0;
        fate.excess += w_new - w;
        w = w_new;
        return dl = frame.to_world(out), w > 0;
      }
      if (!refract(dl, frame.n, g.n_outside(0), transport_.medium().n, &inside))
        return fate.lost += w, false;
    }
    Exit exit;
    PhotonTally books;
    transport_.launch_internal(q * (1 - 1e-12), normalize(inside), w, rng, exit, books);
    fate.absorbed += books.absorbed;
    fate.lost += books.lost;
    fate.roulette += books.roulette_loss - books.roulette_gain;
    if (!exit.left) return false;
    q = exit.position;
    dl = exit.direction;
    w = exit.weight;
    return true;
  }

  const Layer& layer_;
  const FiberBandPhysics& fiber_;
  const EllipticCylinderTransport& transport_;
  double tan_crimp_ = 0, tan_yarn_ = 0;
};

// beta = pi f averaged over a ring: its power over the ring's projected solid angle over pi.
double ring_beta_per_power(int ring, int rings) {
  const double t0 = deg_to_rad(90.0 * ring / rings), t1 = deg_to_rad(90.0 * (ring + 1) / rings);
  return 1.0 / (sqr(std::sin(t1)) - sqr(std::sin(t0)));
}

}  // namespace

void FiberLayerSettings::validate(double fiber_radius_um) const {
  if (!(aspect >= 1) || !std::isfinite(aspect))
    throw Error("", "aspect", "must be finite and >= 1");
  if (rows < 1) throw Error("", "rows", "must be >= 1");
  if (fibers_per_row < 1) throw Error("", "fibers_per_row", "must be >= 1");
  if (!(tilt_spread_deg >= 0 && tilt_spread_deg <= 90))
    throw Error("", "tilt_spread_deg", "must lie in [0, 90]");
  if (rings < 1) throw Error("", "rings", "must be >= 1");
  if (!(crimp_deg >= 0 && crimp_deg < 90)) throw Error("", "crimp_deg", "must lie in [0, 90)");
  if (!(yarn_tilt_deg >= 0 && yarn_tilt_deg < 90))
    throw Error("", "yarn_tilt_deg", "must lie in [0, 90)");
  if (photons_per_band < 1) throw Error("", "photons_per_band", "must be >= 1");
  if (!(fiber_radius_um > 0)) throw Error("", "fiber_radius_um", "must be > 0");
  const Semi semi = semi_axes(fiber_radius_um, aspect);
  if (!(pitch_um >= 2 * semi.a) || !std::isfinite(pitch_um))
    throw Error("", "pitch_um",
                "must be finite and at least the fiber's width (" + std::to_string(2 * semi.a) +
                    " um at this aspect)");
}

std::vector<LayerFiber> fiber_layer_fibers(const FiberLayerSettings& s, double radius_um) {
  s.validate(radius_um);
  const Semi semi = semi_axes(radius_um, s.aspect);
  const double spread = deg_to_rad(s.tilt_spread_deg);
  const double row_h =
      2 * kRowGap * std::hypot(semi.a * std::sin(spread), semi.b * std::cos(spread));
  const double period = s.fibers_per_row * s.pitch_um;
  Rng rng(s.seed, 0, 1);  // the tasks' streams are (seed, task, 0)
  std::vector<LayerFiber> fibers;
  for (int r = 0; r < s.rows; ++r) {
    const double offset = rng.uniform() * s.pitch_um;
    for (int j = 0; j < s.fibers_per_row; ++j) {
      const double tilt = (2 * rng.uniform() - 1) * spread;
      const double half_w = std::hypot(semi.a * std::cos(tilt), semi.b * std::sin(tilt));
      const double half_h = std::hypot(semi.a * std::sin(tilt), semi.b * std::cos(tilt));
      double y = offset + (j + 0.5) * s.pitch_um +
                 (2 * rng.uniform() - 1) * std::max(0.0, s.pitch_um / 2 - half_w);
      y -= period * std::floor(y / period);
      const double z = -(r + 0.5) * row_h + (2 * rng.uniform() - 1) * (row_h / 2 - half_h);
      fibers.push_back({y, z, tilt});
    }
  }
  return fibers;
}

FiberLayerBandResult simulate_fiber_layer_band(const FiberSpec& spec, const MediumBand& band,
                                               const FiberLayerSettings& settings) {
  const std::vector<LayerFiber> fibers = fiber_layer_fibers(settings, spec.fiber_radius_um);
  const Semi semi = semi_axes(spec.fiber_radius_um, settings.aspect);
  double bottom = 0;  // below every fiber (a >= b bounds a tilted fiber's reach)
  for (const LayerFiber& f : fibers) bottom = std::min(bottom, f.z_um - semi.a);
  const Layer layer(fibers, semi, settings.fibers_per_row * settings.pitch_um, bottom);
  const FiberBandPhysics fiber = fiber_band_physics(spec, band);
  const EllipticCylinderTransport transport(
      EllipticCylinderGeometry(semi.a, semi.b, 1.0), fiber_band_medium(band),
      fiber_band_transport_options(fiber, 10'000'000, WeightMode::absorption_weight));
  LayerTracer tracer(layer, fiber, transport);
  tracer.tilted(settings.crimp_deg, settings.yarn_tilt_deg);
  const int rings = settings.rings;

  TaskBatch batch;
  batch.items = settings.photons_per_band;
  batch.seed = settings.seed;  // every band: the same random numbers (fiber_layer.h)
  batch.threads = settings.threads;
  batch.items_per_task = 1024;
  LayerTally total;
  run_batch<LayerTally>(
      photon_batch(batch),
      [&](uint64_t, uint64_t, uint64_t count, Rng& rng, LayerTally& tally) {
        tally.up.resize(rings);
        tally.down.resize(rings);
        for (uint64_t i = 0; i < count; ++i) {
          const PhotonFate fate = tracer.trace(rng);
          double up = 0, down = 0;
          if (fate.left) {
            const double c = std::abs(fate.direction.z);
            const int ring = std::min(rings - 1, static_cast<int>(std::acos(std::min(1.0, c)) /
                                                                  deg_to_rad(90.0 / rings)));
            (fate.direction.z > 0 ? up : down) = fate.weight;
            (fate.direction.z > 0 ? tally.up : tally.down)[ring].add(
                fate.weight * ring_beta_per_power(ring, rings));
          }
          tally.reflected.add(up);
          tally.transmitted.add(down);
          tally.absorbed.add(fate.absorbed);
          tally.lost.add(fate.lost);
          tally.roulette.add(fate.roulette);
          tally.excess.add(fate.excess);
          tally.photons += 1;
          tally.crossings += fate.crossings;
        }
      },
      [&](const LayerTally& t) { total += t; });

  FiberLayerBandResult r;
  const uint64_t n = total.photons;
  for (int k = 0; k < rings; ++k) {
    r.reflected_beta.push_back(total.up[k].estimate(n));
    r.transmitted_beta.push_back(total.down[k].estimate(n));
  }
  r.reflected = total.reflected.estimate(n);
  r.transmitted = total.transmitted.estimate(n);
  r.absorbed = total.absorbed.estimate(n);
  r.lost = total.lost.estimate(n);
  r.roulette = total.roulette.estimate(n);
  r.surface_excess = total.excess.estimate(n);
  r.energy_imbalance = 1 - (r.reflected.mean + r.transmitted.mean + r.absorbed.mean + r.lost.mean +
                            r.roulette.mean - r.surface_excess.mean);
  r.photons = n;
  r.fiber_crossings = total.crossings;
  return r;
}

FiberLayerResult simulate_fiber_layer(const FiberSpec& spec, const FiberMedium& medium,
                                      const FiberLayerSettings& settings) {
  FiberLayerResult r;
  for (const MediumBand& band : medium.bands)
    r.bands.push_back(simulate_fiber_layer_band(spec, band, settings));
  if (static_cast<int>(medium.bands.size()) != kNumBands) return r;
  std::array<int, kNumBands> index{};
  for (int k = 0; k < kNumBands; ++k) index[medium.bands[k].band] = k;
  const auto reduce = [&](auto&& estimate) {
    return bands_to_linear_srgb([&](int b) { return estimate(r.bands[index[b]]).mean; });
  };
  for (int k = 0; k < settings.rings; ++k) {
    r.reflected_beta.push_back(reduce([k](const auto& b) { return b.reflected_beta[k]; }));
    r.transmitted_beta.push_back(reduce([k](const auto& b) { return b.transmitted_beta[k]; }));
  }
  r.reflected = reduce([](const auto& b) { return b.reflected; });
  r.transmitted = reduce([](const auto& b) { return b.transmitted; });
  return r;
}

}  // namespace weft
