// The car-seat generator (car_seat.h): rounded boxes on an integer lattice (so that the vertices
// that several faces share get bit-identical positions), closed piping tubes, injective
// deformations, smooth normals averaged over welded positions, tangents from the UVs.
#include "weft/scenes/car_seat.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <map>

#include "weave_internal.h"
#include "weft/core/error.h"
#include "weft/core/math.h"

namespace weft {
namespace {

using Deform = std::function<Vec3(const Vec3&)>;

// A rotation (columns are the images of x, y, z) followed by a translation.
struct Rigid {
  Vec3 cx{1, 0, 0}, cy{0, 1, 0}, cz{0, 0, 1}, t{0, 0, 0};
  Vec3 rotate(const Vec3& v) const { return cx * v.x + cy * v.y + cz * v.z; }
  Vec3 apply(const Vec3& v) const { return rotate(v) + t; }
  // this after 'first'
  Rigid then_after(const Rigid& first) const {
    return {rotate(first.cx), rotate(first.cy), rotate(first.cz), apply(first.t)};
  }
};

Rigid rot_x(double deg) {
  const double a = deg_to_rad(deg), c = std::cos(a), s = std::sin(a);
  return {{1, 0, 0}, {0, c, s}, {0, -s, c}, {}};
}
Rigid rot_y(double deg) {
  const double a = deg_to_rad(deg), c = std::cos(a), s = std::sin(a);
  return {{c, 0, -s}, {0, 1, 0}, {s, 0, c}, {}};
}
Rigid rot_z(double deg) {
  const double a = deg_to_rad(deg), c = std::cos(a), s = std::sin(a);
  return {{c, s, 0}, {-s, c, 0}, {0, 0, 1}, {}};
}
Rigid translate(const Vec3& t) {
  Rigid r;
  r.t = t;
  return r;
}

// Smooth normals: area-weighted face normals summed over vertices with the same position, so
// that duplicated vertices along UV seams (cube edges, the tube's closing ring) share a normal.
void smooth_normals(TriangleMesh& m) {
  std::map<std::array<float, 3>, size_t> weld;
  std::vector<size_t> id(m.vertex_count());
  for (size_t v = 0; v < m.vertex_count(); ++v) {
    const std::array<float, 3> key{m.positions[3 * v], m.positions[3 * v + 1],
                                   m.positions[3 * v + 2]};
    id[v] = weld.emplace(key, weld.size()).first->second;
  }
  std::vector<Vec3> acc(weld.size());
  for (size_t t = 0; t < m.triangle_count(); ++t) {
    const uint32_t i0 = m.indices[3 * t], i1 = m.indices[3 * t + 1], i2 = m.indices[3 * t + 2];
    const Vec3 p0 = m.position(i0);
    const Vec3 face = cross(m.position(i1) - p0, m.position(i2) - p0);
    for (uint32_t i : {i0, i1, i2}) acc[id[i]] += face;
  }
  m.normals.resize(3 * m.vertex_count());
  for (size_t v = 0; v < m.vertex_count(); ++v) {
    const Vec3 n = normalize(acc[id[v]]);
    m.normals[3 * v] = float(n.x), m.normals[3 * v + 1] = float(n.y),
                  m.normals[3 * v + 2] = float(n.z);
  }
}

void finish(TriangleMesh& m) {
  smooth_normals(m);
  m.tangents.clear();
  derive_tangents(m);
}

void push(TriangleMesh& m, const Vec3& p, double u, double v) {
  m.positions.insert(m.positions.end(), {float(p.x), float(p.y), float(p.z)});
  m.uvs.insert(m.uvs.end(), {float(u), float(v)});
}

struct BoxSpec {
  Vec3 half;      // half extents (metres), local axes
  double radius;  // rounding radius, <= the smallest half extent
  int warp_axis;  // local axis the warp follows on the faces it lies in
  Deform deform;  // local -> local, injective
  Rigid place;    // local -> world
};

// A rounded box: the cube of half extents 'half' on a lattice of cells about cell_m wide, each
// lattice point s mapped to c + r (s - c) / |s - c| with c the nearest point of the inner box
// (half - r). Faces keep their own vertices (their own UVs); shared edges have equal positions.
TriangleMesh rounded_box(const BoxSpec& b, double cell_m) {
  const Vec3 inner = b.half - Vec3(b.radius, b.radius, b.radius);
  std::array<int, 3> n{};
  for (int k = 0; k < 3; ++k) n[k] = std::max(2, int(std::ceil(2 * b.half[k] / cell_m)));
  auto lattice = [&](const std::array<int, 3>& i) {
    Vec3 s;
    for (int k = 0; k < 3; ++k) s[k] = -b.half[k] + 2 * b.half[k] * double(i[k]) / n[k];
    return s;
  };
  auto position = [&](const Vec3& s) {
    Vec3 c;
    for (int k = 0; k < 3; ++k) c[k] = std::clamp(s[k], -inner[k], inner[k]);
    const Vec3 d = s - c;
    const double len = length(d);
    const Vec3 p = len > 0 ? c + d * (b.radius / len) : s;
    return b.place.apply(b.deform ? b.deform(p) : p);
  };
  TriangleMesh m;
  for (int k = 0; k < 3; ++k)
    for (int sign : {-1, 1}) {
      const int a = (k + 1) % 3, c = (k + 2) % 3;  // (a, c, k) right-handed
      const int u_axis = b.warp_axis != k ? b.warp_axis : (k != 1 ? 1 : 0);
      const uint32_t base = static_cast<uint32_t>(m.vertex_count());
      for (int j = 0; j <= n[c]; ++j)
        for (int i = 0; i <= n[a]; ++i) {
          std::array<int, 3> idx{};
          idx[k] = sign > 0 ? n[k] : 0;
          idx[a] = i, idx[c] = j;
          const Vec3 s = lattice(idx);
          const int v_axis = 3 - k - u_axis;
          push(m, position(s), s[u_axis], s[v_axis]);
        }
      const uint32_t row = static_cast<uint32_t>(n[a] + 1);
      for (int j = 0; j < n[c]; ++j)
        for (int i = 0; i < n[a]; ++i) {
          const uint32_t v00 = base + j * row + i, v10 = v00 + 1, v01 = v00 + row, v11 = v01 + 1;
          if (sign > 0)
            m.indices.insert(m.indices.end(), {v00, v10, v11, v00, v11, v01});
          else
            m.indices.insert(m.indices.end(), {v00, v11, v10, v00, v01, v11});
        }
    }
  return m;
}

// A closed tube of radius 'r' around the closed path 'path' (local, sampled without repeating its
// first point) lying in a plane with unit normal 'up'; u runs along the path (metres), v around.
TriangleMesh closed_tube(const std::vector<Vec3>& path, const Vec3& up, double r, int sides,
                         const Deform& deform, const Rigid& place) {
  const size_t np = path.size();
  std::vector<double> arc(np + 1, 0.0);
  for (size_t i = 0; i < np; ++i) arc[i + 1] = arc[i] + length(path[(i + 1) % np] - path[i]);
  std::vector<Vec3> ring_pos;  // np x sides, computed once so the closing ring repeats the bits
  for (size_t i = 0; i < np; ++i) {
    const Vec3 tangent = normalize(path[(i + 1) % np] - path[(i + np - 1) % np]);
    const Vec3 side = normalize(cross(tangent, up));  // in the plane, across the path
    for (int k = 0; k < sides; ++k) {
      const double phi = 2 * kPi * k / sides;
      const Vec3 p = path[i] + (side * std::cos(phi) + up * std::sin(phi)) * r;
      ring_pos.push_back(place.apply(deform ? deform(p) : p));
    }
  }
  TriangleMesh m;
  const uint32_t row = static_cast<uint32_t>(sides + 1);
  for (size_t i = 0; i <= np; ++i)
    for (int k = 0; k <= sides; ++k)
      push(m, ring_pos[(i % np) * sides + (k % sides)], arc[i], 2 * kPi * r * k / sides);
  for (uint32_t i = 0; i < np; ++i)
    for (uint32_t k = 0; k < uint32_t(sides); ++k) {
      const uint32_t v00 = i * row + k, v01 = v00 + 1, v10 = v00 + row, v11 = v10 + 1;
      // Outward: the ring's radial direction is side cos(phi) + up sin(phi) with side =
      // tangent x up, so tangent x d(phi) is outward and (v00, v11, v01) winds that way.
      m.indices.insert(m.indices.end(), {v00, v11, v01, v00, v10, v11});
    }
  return m;
}

// A rounded rectangle in the plane y = y0 (half extents hx, hz, corner radius rc), sampled every
// ~step metres, starting on the +x side.
std::vector<Vec3> rounded_rect_xz(double hx, double hz, double rc, double y0, double step) {
  std::vector<Vec3> out;
  const double ax = hx - rc, az = hz - rc;
  auto line = [&](const Vec3& a, const Vec3& b) {
    const int n = std::max(1, int(std::ceil(length(b - a) / step)));
    for (int i = 0; i < n; ++i) out.push_back(a + (b - a) * (double(i) / n));
  };
  auto corner = [&](double cx, double cz, double a0) {
    const int n = std::max(2, int(std::ceil(0.5 * kPi * rc / step)));
    for (int i = 0; i < n; ++i) {
      const double a = a0 + 0.5 * kPi * i / n;
      out.push_back({cx + rc * std::cos(a), y0, cz - rc * std::sin(a)});
    }
  };
  // Angles measured from +x towards -z (counter-clockwise seen from +y).
  line({hx, y0, az}, {hx, y0, -az});
  corner(ax, -az, 0);
  line({ax, y0, -hz}, {-ax, y0, -hz});
  corner(-ax, -az, 0.5 * kPi);
  line({-hx, y0, -az}, {-hx, y0, az});
  corner(-ax, az, kPi);
  line({-ax, y0, hz}, {ax, y0, hz});
  corner(ax, az, 1.5 * kPi);
  return out;
}

// Bump in [0, 1] that is 1 at the centre and 0 at |t| = 1.
double dome(double t) {
  return std::max(0.0, 1 - t * t);
}
double groove(double x, double centre, double width) {
  const double t = (x - centre) / width;
  return std::exp(-t * t);
}

CarSeatPart part(const std::string& name, const std::string& material, TriangleMesh m,
                 const Vec3& warp) {
  m.material = material;
  m.names = {name, "seat"};
  finish(m);
  return {name, std::move(m), warp};
}

// The rounding radius of the seat's upholstered panels.
constexpr double kPanelRounding = 0.035;

// Piping along the middle of a panel's rounded edge around its face at height 'face' above the
// box's centre: a rounded rectangle in the plane y = that middle, half extents a, b less the inset
// of the edge's middle.
std::vector<Vec3> piping_path(double a, double b, double face, double cell) {
  const double r = kPanelRounding, inset = r * (1 - std::cos(kPi / 4));
  const double y0 = face - r * (1 - std::sin(kPi / 4));
  return rounded_rect_xz(a - inset, b - inset, 0.03, y0, cell);
}

// Seat cushion: centre panel pillowed on top with two seams along z, rising towards the front
// (thigh support), tilted 5 degrees front up, between two bolsters. Shifts of y by functions of
// (x, z), and of y by a factor 1 + g(x, z) / hy > 0 on the top half, keep the map injective.
void add_cushion(CarSeat& seat, const CarSeatOptions& o, double cell, double pipe_r) {
  const Vec3 ch{0.19, 0.05, 0.23};
  const Deform cushion = [ch](const Vec3& p) {
    const double top = std::max(0.0, p.y / ch.y);
    const double pillow = 0.018 * dome(p.x / ch.x) * dome(p.z / ch.z);
    const double seams = 0.007 * (groove(p.x, -0.07, 0.006) + groove(p.x, 0.07, 0.006));
    const double rise = 0.012 * (p.z / ch.z + 1) * 0.5;
    return Vec3{p.x, p.y + (pillow - seams) * top + rise, p.z};
  };
  const Rigid cushion_place = translate({0, 0.30, 0.03}).then_after(rot_x(-5));
  seat.parts.push_back(part("cushion_centre", "centre",
                            rounded_box({ch, kPanelRounding, 2, cushion, cushion_place}, cell),
                            cushion_place.rotate({0, 0, 1})));
  for (int side : {-1, 1}) {
    const Vec3 bh{0.05, 0.07, 0.24};
    const Rigid place =
        cushion_place.then_after(translate({side * 0.235, 0.03, 0}).then_after(rot_z(side * 10.0)));
    seat.parts.push_back(part(side < 0 ? "cushion_bolster_left" : "cushion_bolster_right",
                              "bolster", rounded_box({bh, 0.045, 2, nullptr, place}, cell),
                              place.rotate({0, 0, 1})));
  }
  // Piping on the centre panel's top edge.
  seat.parts.push_back(part("cushion_piping", "piping",
                            closed_tube(piping_path(ch.x, ch.z, ch.y, cell), {0, 1, 0}, pipe_r,
                                        o.piping_sides, cushion, cushion_place),
                            {}));
}

// The backrest's hinge above the cushion's rear (it is tilted 18 degrees back about it) and its
// centre panel's half extents; the headrest stands on it.
Rigid backrest_hinge() {
  return translate({0, 0.33, -0.24}).then_after(rot_x(-18));
}
constexpr Vec3 kBackrestHalf{0.19, 0.29, 0.045};

// Backrest: built upright (height along y, front +z) from its bottom edge, wrapped towards the
// occupant at the sides, with a lumbar bulge and a pillowed front with two horizontal seams;
// then tilted back about its hinge, between two bolsters.
void add_backrest(CarSeat& seat, const CarSeatOptions& o, double cell, double pipe_r) {
  const Vec3 bh = kBackrestHalf;
  const Deform back = [bh](const Vec3& p) {
    const double front = std::max(0.0, p.z / bh.z);
    const double pillow = 0.015 * dome(p.x / bh.x) * dome((p.y - bh.y) / bh.y);
    const double seams =
        0.006 * (groove(p.y, bh.y - 0.09, 0.006) + groove(p.y, bh.y + 0.11, 0.006));
    const double wrap = 0.9 * p.x * p.x;  // sides come 3 cm forward
    const double lumbar = 0.02 * groove(p.y, 0.15, 0.08);
    return Vec3{p.x, p.y, p.z + (pillow - seams) * front + wrap + lumbar};
  };
  const Rigid hinge = backrest_hinge();
  const Rigid back_place = hinge.then_after(translate({0, bh.y, 0}));
  // 'back' measures y from the bottom edge; the box is built around its centre.
  const Deform back_local = [back, bh](const Vec3& p) {
    const Vec3 q = back({p.x, p.y + bh.y, p.z});
    return Vec3{q.x, q.y - bh.y, q.z};
  };
  seat.parts.push_back(part("backrest_centre", "centre",
                            rounded_box({bh, kPanelRounding, 1, back_local, back_place}, cell),
                            back_place.rotate({0, 1, 0})));
  for (int side : {-1, 1}) {
    const Vec3 sh{0.05, 0.28, 0.065};
    const Rigid place =
        hinge.then_after(translate({side * 0.235, sh.y, 0.03}).then_after(rot_y(-side * 12.0)));
    seat.parts.push_back(part(side < 0 ? "backrest_bolster_left" : "backrest_bolster_right",
                              "bolster", rounded_box({sh, 0.045, 1, nullptr, place}, cell),
                              place.rotate({0, 1, 0})));
  }
  // Piping around the front face: the path in the box's (x, z, y) plane is the cushion's
  // rounded rectangle turned so that its plane faces +z.
  auto path = piping_path(bh.x, bh.y, bh.z, cell);
  for (Vec3& p : path) p = {p.x, -p.z, p.y};  // (x, y0, z) -> (x, -z, y0): plane z = y0
  seat.parts.push_back(
      part("backrest_piping", "piping",
           closed_tube(path, {0, 0, 1}, pipe_r, o.piping_sides, back_local, back_place), {}));
}

// Headrest above the backrest on two posts, pillowed at the front; its warp runs across (x).
void add_headrest(CarSeat& seat, double cell) {
  const Vec3 hh{0.13, 0.095, 0.055};
  const Deform head = [hh](const Vec3& p) {
    const double front = std::max(0.0, p.z / hh.z);
    return Vec3{p.x, p.y, p.z + 0.012 * dome(p.x / hh.x) * dome(p.y / hh.y) * front};
  };
  const Rigid hinge = backrest_hinge();
  const Vec3 bh = kBackrestHalf;
  const Rigid head_place = hinge.then_after(translate({0, 2 * bh.y + 0.07 + hh.y, 0.0}));
  seat.parts.push_back(part("headrest", "headrest",
                            rounded_box({hh, 0.045, 0, head, head_place}, cell),
                            head_place.rotate({1, 0, 0})));
  for (int side : {-1, 1}) {
    const Vec3 ph{0.006, 0.065, 0.006};
    const Rigid place = hinge.then_after(translate({side * 0.07, 2 * bh.y + 0.04, 0}));
    // A rod with rounded ends: the rounding radius just under the rod's half width.
    seat.parts.push_back(part(side < 0 ? "headrest_post_left" : "headrest_post_right", "post",
                              rounded_box({ph, 0.0059, 1, nullptr, place}, std::min(cell, 0.003)),
                              place.rotate({0, 1, 0})));
  }
}

}  // namespace

void CarSeatOptions::validate() const {
  if (!(cell_mm >= 1 && cell_mm <= 100))
    throw Error("", "cell_mm", "must lie in [1, 100] mm (got " + std::to_string(cell_mm) + ")");
  if (!(piping_radius_mm >= 1 && piping_radius_mm <= 10))
    throw Error("", "piping_radius_mm", "must lie in [1, 10] mm");
  if (piping_sides < 3 || piping_sides > 64) throw Error("", "piping_sides", "must lie in [3, 64]");
}

size_t CarSeat::triangle_count() const {
  size_t n = 0;
  for (const auto& p : parts) n += p.mesh.triangle_count();
  return n;
}
size_t CarSeat::vertex_count() const {
  size_t n = 0;
  for (const auto& p : parts) n += p.mesh.vertex_count();
  return n;
}

CarSeat make_car_seat(const CarSeatOptions& o) {
  o.validate();
  const double cell = o.cell_mm * 1e-3, pipe_r = o.piping_radius_mm * 1e-3;
  CarSeat seat;
  add_cushion(seat, o, cell, pipe_r);
  add_backrest(seat, o, cell, pipe_r);
  add_headrest(seat, cell);
  // The frame under the cushion, down to the floor (y = 0), so the seat stands on the ground.
  const Vec3 fh{0.2, 0.125, 0.21};
  const Rigid place = translate({0, fh.y + 0.002, 0.0});
  seat.parts.push_back(
      part("base", "base", rounded_box({fh, 0.02, 2, nullptr, place}, 2 * cell), {}));
  return seat;
}

void write_car_seat_gltf(const std::filesystem::path& path, const CarSeat& seat,
                         const CarSeatOptions& o) {
  std::vector<TriangleMesh> meshes;
  for (const auto& p : seat.parts) meshes.push_back(p.mesh);
  const nlohmann::json extras = {{"cell_mm", o.cell_mm},
                                 {"piping_radius_mm", o.piping_radius_mm},
                                 {"piping_sides", o.piping_sides},
                                 {"triangles", seat.triangle_count()}};
  detail::GltfDocument d = detail::build_gltf(&meshes, nullptr, extras, {});
  // The shared writer names things for woven samples; name them for the seat.
  d.doc["asset"]["generator"] = "weft scene car-seat";
  d.doc["extras"] = {{"weft_scene", {{"scene", "car-seat"}, {"options", extras}}}};
  d.doc["scenes"][0]["name"] = "seat";
  d.doc["nodes"][0]["name"] = "seat";
  for (size_t i = 0; i < seat.parts.size(); ++i) {
    d.doc["nodes"][i + 1]["name"] = seat.parts[i].name;
    d.doc["meshes"][i]["name"] = seat.parts[i].name;
  }
  detail::write_gltf(path, d);
}

}  // namespace weft
