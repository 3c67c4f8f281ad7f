#include "weft/scenes/lights.h"

#include <algorithm>
#include <cmath>

#include "message_format.h"
#include "weft/core/distribution.h"
#include "weft/core/math.h"

namespace weft {
namespace {

// Uniform direction on the unit sphere: azimuth from u.x, z from u.y.
Vec3 uniform_sphere(Vec2 u) {
  const double z = 1 - 2 * u.y;
  const double r = safe_sqrt(1 - z * z);
  const double phi = 2 * kPi * u.x;
  return {r * std::cos(phi), r * std::sin(phi), z};
}

Vec3 corner(const TriangleMesh& m, uint32_t prim, int k) {
  return m.position(m.indices[3 * prim + k]);
}

double triangle_area(const TriangleMesh& m, uint32_t prim) {
  const Vec3 p0 = corner(m, prim, 0);
  return 0.5 * length(cross(corner(m, prim, 1) - p0, corner(m, prim, 2) - p0));
}

}  // namespace

std::optional<LightSample> DirectionalLight::sample(const Vec3&, Rng&) const {
  LightSample s;
  s.wi = to_light;
  s.L = irradiance;
  s.at_infinity = true;
  return s;
}

double PointLight::falloff(const Vec3& from_light) const {
  if (!is_spot()) return 1;
  // KHR_lights_punctual's reference falloff: squared linear ramp in cos between the cones.
  const double cd = dot(spot_direction, from_light);
  const double scale = 1.0 / std::max(1e-3, cos_inner - cos_outer);
  const double a = std::clamp((cd - cos_outer) * scale, 0.0, 1.0);
  return a * a;
}

std::optional<LightSample> PointLight::sample(const Vec3& p, Rng&) const {
  const Vec3 to = position - p;
  const double dist = length(to);
  if (!(dist > 0)) return std::nullopt;
  const Vec3 dir = to / dist;
  const double fall = falloff(-dir);
  if (fall <= 0) return std::nullopt;
  LightSample s;
  s.wi = dir;
  s.L = intensity;
  s.falloff = fall;
  s.pdf = dist * dist;
  s.p_light = position;
  return s;
}

std::optional<LightSample> EnvironmentLight::sample(const Vec3&, Rng& rng) const {
  const Vec2 u{rng.uniform(), rng.uniform()};
  LightSample s;
  s.wi = uniform_sphere(u);
  s.L = radiance;
  s.pdf = kInv4Pi;
  s.at_infinity = true;
  return s;
}

double EnvironmentLight::pdf(const LightHit& hit) const {
  return hit.escaped ? kInv4Pi : 0;
}

Rgb EnvironmentLight::eval(const LightHit& hit) const {
  return hit.escaped ? radiance : Rgb(0.0);
}

struct AreaLight::Data {
  struct MeshRecord {
    std::shared_ptr<const TriangleMesh> mesh;
    Emission emission;
    int64_t first = -1;  // index of the mesh's first triangle in 'triangles' (-1: none)
  };
  std::vector<MeshRecord> meshes;
  std::vector<std::pair<uint32_t, uint32_t>> triangles;  // (mesh, prim) of every emitter
  Distribution1D pick;                                   // by power, over 'triangles'

  // Radiance leaving the mesh's surface with unit geometric normal ng towards w (unit).
  Rgb emitted(uint32_t mesh, const Vec3& ng, const Vec3& w) const {
    const Emission& e = meshes[mesh].emission;
    if (e.radiance.is_black()) return Rgb(0.0);
    if (!e.two_sided && dot(ng, w) <= 0) return Rgb(0.0);
    return e.radiance;
  }
};

AreaLight::AreaLight(std::vector<std::shared_ptr<const TriangleMesh>> meshes,
                     const std::vector<Emission>& emission) {
  auto data = std::make_shared<Data>();
  std::vector<double> weights;
  for (size_t i = 0; i < meshes.size(); ++i) {
    Data::MeshRecord rec;
    rec.mesh = std::move(meshes[i]);
    rec.emission = i < emission.size() ? emission[i] : Emission{};
    if (!rec.emission.radiance.is_black()) {
      rec.first = static_cast<int64_t>(data->triangles.size());
      for (uint32_t t = 0; t < rec.mesh->triangle_count(); ++t) {
        data->triangles.push_back({static_cast<uint32_t>(i), t});
        weights.push_back(triangle_area(*rec.mesh, t) * rec.emission.radiance.average() *
                          (rec.emission.two_sided ? 2 : 1));
      }
    }
    data->meshes.push_back(std::move(rec));
  }
  if (!weights.empty()) data->pick = Distribution1D(weights);
  data_ = std::move(data);
}

bool AreaLight::empty() const {
  return !data_ || data_->triangles.empty();
}

bool AreaLight::emits(uint32_t mesh) const {
  return data_ && mesh < data_->meshes.size() && !data_->meshes[mesh].emission.radiance.is_black();
}

std::optional<LightSample> AreaLight::sample(const Vec3& p, Rng& rng) const {
  const double u_pick = rng.uniform();
  const Vec2 u{rng.uniform(), rng.uniform()};
  double pmf = 0;
  const auto [mesh, prim] = data_->triangles[data_->pick.sample_discrete(u_pick, &pmf)];
  const TriangleMesh& m = *data_->meshes[mesh].mesh;
  const Vec3 p0 = corner(m, prim, 0), p1 = corner(m, prim, 1), p2 = corner(m, prim, 2);
  // Uniform point on the triangle (square-root parameterisation).
  const double su = std::sqrt(u.x);
  const double b1 = 1 - su, b2 = u.y * su;
  const Vec3 pl = (1 - b1 - b2) * p0 + b1 * p1 + b2 * p2;
  const Vec3 c = cross(p1 - p0, p2 - p0);
  const double area = 0.5 * length(c);
  const Vec3 n = area > 0 ? c / (2 * area) : Vec3{0, 0, 1};
  const double pdf_area = area > 0 ? pmf / area : 0;

  const Vec3 to = pl - p;
  const double dist = length(to);
  if (!(dist > 0 && pdf_area > 0)) return std::nullopt;
  const Vec3 dir = to / dist;
  const double cos_l = std::abs(dot(n, dir));
  const Rgb Le = data_->emitted(mesh, n, -dir);
  if (!(cos_l > 0) || Le.is_black()) return std::nullopt;
  LightSample s;
  s.wi = dir;
  s.L = Le;
  s.pdf = pdf_area * dist * dist / cos_l;  // area density to solid angle
  s.p_light = pl;
  return s;
}

double AreaLight::pdf(const LightHit& hit) const {
  if (hit.escaped || !emits(hit.mesh)) return 0;
  const Data::MeshRecord& rec = data_->meshes[hit.mesh];
  const double cos_l = std::abs(dot(hit.ng, hit.dir));
  if (!(cos_l > 0)) return 0;
  const double area = triangle_area(*rec.mesh, hit.prim);
  const double pdf_area =
      area > 0 ? data_->pick.pmf(static_cast<size_t>(rec.first) + hit.prim) / area : 0;
  return pdf_area * hit.distance * hit.distance / cos_l;
}

Rgb AreaLight::eval(const LightHit& hit) const {
  if (hit.escaped || !emits(hit.mesh)) return Rgb(0.0);
  return data_->emitted(hit.mesh, hit.ng, -hit.dir);
}

std::vector<std::string> describe_lights(const Lights& lights) {
  auto vec = [](const Vec3& v) { return detail::format_triple(v.x, v.y, v.z); };
  auto rgb = [](const Rgb& c) { return detail::format_triple(c.r, c.g, c.b); };
  std::vector<std::string> out;
  for (const auto& d : lights.directional)
    out.push_back("parallel towards " + vec(d.to_light) + ": irradiance " + rgb(d.irradiance) +
                  " W/m^2");
  for (const auto& p : lights.points)
    out.push_back(std::string(p.is_spot() ? "spot" : "point") + " at " + vec(p.position) +
                  ": intensity " + rgb(p.intensity) + " W/sr");
  if (!lights.environment.is_black())
    out.push_back("environment: radiance " + rgb(lights.environment) + " W m^-2 sr^-1");
  return out;
}

}  // namespace weft
