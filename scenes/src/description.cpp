#include "weft/scenes/description.h"

#include <fstream>
#include <sstream>

#include "primitives.h"
#include "weft/core/error.h"
#include "weft/core/frame.h"
#include "weft/core/math.h"
#include "weft/core/params.h"

namespace weft {
namespace {

constexpr double kMaxRadiometric = kMaxDescriptionRadiometric;

MaterialBinding parse_binding(ParamReader f, bool allow_emission) {
  MaterialBinding b;
  b.field = f.path();
  b.type = f.string("type");
  if (f.has("params")) {
    b.params = f.at("params");
    if (!b.params.is_object()) throw Error(f.file(), f.field("params"), "must be a JSON object");
  }
  if (allow_emission) {
    if (f.has("emission")) b.emission = f.rgb("emission", 0, kMaxRadiometric);
    if (f.has("double_sided")) b.double_sided = f.boolean("double_sided", false);
  }
  f.finish();
  return b;
}

AngleFrame parse_frame(ParamReader f) {
  AngleFrame a;
  if (f.has("normal")) a.normal = f.unit_vec3("normal");
  if (f.has("tangent")) a.tangent = f.unit_vec3("tangent");
  f.finish();
  const Vec3 t = a.tangent - dot(a.tangent, a.normal) * a.normal;
  if (!(length(t) > 1e-6)) throw Error(f.file(), f.field("tangent"), "is parallel to the normal");
  a.tangent = normalize(t);
  return a;
}

// Zenith/azimuth in degrees, or an explicit direction vector, read from fields with these names.
Vec3 parse_direction(ParamReader& f, const AngleFrame& frame, const std::string& vec_key) {
  if (f.has(vec_key)) {
    if (f.has("zenith_deg") || f.has("azimuth_deg"))
      throw Error(f.file(), f.field(vec_key), "give either a vector or zenith_deg/azimuth_deg");
    return f.unit_vec3(vec_key);
  }
  const double zen = f.number("zenith_deg", 0.0, 0.0, 180.0);
  const double azi = f.number("azimuth_deg", 0.0, -360.0, 360.0);
  return frame.direction(deg_to_rad(zen), deg_to_rad(azi));
}

void parse_light(ParamReader f, const AngleFrame& frame, Lights& lights) {
  const std::string type = f.string("type");
  if (type == "parallel") {
    DirectionalLight d;
    d.irradiance = f.has("irradiance") ? f.rgb("irradiance", 0, kMaxRadiometric) : Rgb(1.0);
    d.to_light = parse_direction(f, frame, "direction");
    lights.directional.push_back(d);
  } else if (type == "environment") {
    lights.environment += f.rgb("radiance", 0, kMaxRadiometric);
  } else if (type == "point" || type == "spot") {
    PointLight p;
    p.position = f.vec3("position");
    p.intensity = f.rgb("intensity", 0, kMaxRadiometric);
    if (type == "spot") {
      p.spot_direction = f.unit_vec3("direction");
      const double inner = f.number("inner_cone_deg", 0.0, 0.0, 90.0);
      const double outer = f.number("outer_cone_deg", 45.0, 0.0, 90.0);
      if (!(inner < outer))
        throw Error(f.file(), f.field("outer_cone_deg"), "must exceed inner_cone_deg");
      p.cos_inner = std::cos(deg_to_rad(inner));
      p.cos_outer = std::cos(deg_to_rad(outer));
    }
    lights.points.push_back(p);
  } else {
    throw Error(f.file(), f.field("type"),
                "unknown light type '" + type + "' (valid: parallel, environment, point, spot)");
  }
  f.finish();
}

Camera parse_camera(ParamReader f, const SceneDescription& d,
                    const std::vector<NamedCamera>& gltf_cameras) {
  Camera cam;
  if (f.has("gltf_camera")) {
    const std::string name = f.string("gltf_camera");
    f.finish();
    for (const auto& c : gltf_cameras)
      if (c.name == name) return c.camera;
    throw Error(f.file(), f.field("gltf_camera"), "no glTF camera named '" + name + "'");
  }
  const std::string type = f.string("type");
  if (type != "perspective" && type != "orthographic")
    throw Error(f.file(), f.field("type"), "must be perspective or orthographic");
  const auto ctype = type == "perspective" ? Camera::Type::perspective : Camera::Type::orthographic;
  if (ctype == Camera::Type::orthographic && f.has("frame_object")) {
    const std::string object = f.string("frame_object");
    const Vec3 view = parse_direction(f, d.frame, "direction");
    f.finish();
    Bounds3 box;
    try {
      box = d.object_bounds(object);
    } catch (const Error& e) {
      throw Error(f.file(), f.field("frame_object"), e.what());
    }
    return frame_box_orthographic(box, view, d.frame.tangent);
  }
  const Vec3 pos = f.vec3("position"), target = f.vec3("look_at");
  const Vec3 up = f.has("up") ? f.unit_vec3("up") : Vec3{0, 1, 0};
  try {
    cam = Camera::look_at(ctype, pos, target, up);
  } catch (const Error& e) {
    throw Error(f.file(), f.path(), e.what());
  }
  if (ctype == Camera::Type::perspective) {
    cam.yfov_rad = deg_to_rad(f.number("yfov_deg", 40.0, 1e-3, 179.0));
  } else {
    cam.half_width = f.number("half_width", 1e-30, 1e30);
    cam.half_height = f.number("half_height", 1e-30, 1e30);
  }
  f.finish();
  return cam;
}

FiberGeometry parse_fiber_geometry(ParamReader f) {
  FiberGeometry g;
  const std::string type = f.choice("type", "curves", {"curves", "tubes"});
  if (type == "tubes") {
    g.type = FiberGeometry::Type::tubes;
    g.tube_sides = static_cast<int>(f.integer("sides", g.tube_sides, FiberGeometry::kMinTubeSides,
                                              FiberGeometry::kMaxTubeSides));
  }
  f.finish();
  return g;
}

void parse_object(ParamReader f, SceneDescription& d) {
  const std::string type = f.string("type");
  TriangleMesh m;
  if (type == "quad") {
    const Vec3 c = f.vec3("center"), n = f.unit_vec3("normal");
    const Vec3 t = f.has("tangent") ? f.unit_vec3("tangent") : Frame::from_normal(n).s;
    double w = 1, h = 1;
    if (f.has("size")) {
      const auto& s = f.at("size");
      if (!s.is_array() || s.size() != 2)
        throw Error(f.file(), f.field("size"), "must be [width, height]");
      w = f.check_number(s[0], f.field("size") + "[0]", 1e-30, 1e30);
      h = f.check_number(s[1], f.field("size") + "[1]", 1e-30, 1e30);
    }
    if (length(cross(n, t)) < 1e-6)
      throw Error(f.file(), f.field("tangent"), "is parallel to the normal");
    m = detail::make_quad(c, n, t, w, h);
  } else if (type == "sphere") {
    const Vec3 c = f.vec3("center");
    const double r = f.number("radius", 1e-30, 1e30);
    const int sub = static_cast<int>(f.integer("subdivisions", 3, 0, 7));
    const bool inward = f.boolean("inward", false);
    m = detail::make_sphere(c, r, sub, inward);
    // Flat facets (no vertex normals) make shading and geometry agree exactly (furnace tests).
    if (!f.boolean("smooth", true)) m.normals.clear();
  } else if (type == "fiber") {
    FiberCurves c;
    const Vec3 from = f.vec3("from"), to = f.vec3("to");
    if (!(length(to - from) > 0)) throw Error(f.file(), f.field("to"), "equals 'from'");
    const double r = f.number("radius", 1e-30, 1e30);
    const int segments = static_cast<int>(f.integer("segments", 1, 1, 1 << 20));
    for (int k = 0; k <= segments; ++k) {
      const Vec3 p = from + (to - from) * (double(k) / segments);
      c.points.insert(c.points.end(), {float(p.x), float(p.y), float(p.z), float(r)});
    }
    c.curve_first = {0};
    c.curve_points = {static_cast<uint32_t>(segments + 1)};
    c.curve_yarn = {0};
    c.yarn_material = {f.string("material")};
    if (f.has("name")) c.names = {f.string("name")};
    f.finish();
    d.curves.push_back(std::make_shared<const FiberCurves>(std::move(c)));
    return;
  } else {
    throw Error(f.file(), f.field("type"),
                "unknown object type '" + type + "' (valid: quad, sphere, fiber)");
  }
  m.material = f.string("material");
  if (f.has("name")) m.names = {f.string("name")};
  f.finish();
  d.meshes.push_back(std::make_shared<const TriangleMesh>(std::move(m)));
}

}  // namespace

Vec3 AngleFrame::direction(double zenith_rad, double azimuth_rad) const {
  const Frame f = Frame::from_normal_tangent(normal, tangent);
  return normalize(f.to_world(spherical_direction(zenith_rad, azimuth_rad)));
}

Bounds3 SceneDescription::object_bounds(const std::string& object) const {
  const auto sel = select_object(object);
  Bounds3 b;
  for (size_t i = 0; i < meshes.size(); ++i)
    if (sel[i]) b.expand(meshes[i]->bounds());
  for (size_t k = 0; k < curves.size(); ++k)
    if (sel[meshes.size() + k]) b.expand(curves[k]->bounds());
  if (b.empty()) throw Error(source, "", "object '" + object + "' has no vertices");
  return b;
}

std::vector<uint8_t> SceneDescription::select_object(const std::string& object) const {
  std::vector<uint8_t> sel(shape_count(), 0);
  bool any = false;
  for (size_t i = 0; i < meshes.size(); ++i)
    if (object.empty() || meshes[i]->has_name(object)) sel[i] = 1, any = true;
  for (size_t k = 0; k < curves.size(); ++k)
    if (object.empty() || curves[k]->has_name(object)) sel[meshes.size() + k] = 1, any = true;
  if (!any) {
    std::string known;
    std::set<std::string> seen;
    auto add = [&](const std::vector<std::string>& names) {
      for (const auto& n : names)
        if (seen.insert(n).second) known += (known.empty() ? "" : ", ") + n;
    };
    for (const auto& m : meshes) add(m->names);
    for (const auto& c : curves) add(c->names);
    throw Error(
        source, "",
        "no object named '" + object + "' (known: " + (known.empty() ? "none" : known) + ")");
  }
  return sel;
}

const MaterialBinding& SceneDescription::binding_for(const std::string& key) const {
  const auto it = materials.find(key);
  if (it != materials.end()) return it->second;
  if (default_material) return *default_material;
  throw Error(source, "materials",
              key.empty() ? "a mesh has no glTF material: bind one with 'default_material'"
                          : "no binding for glTF material '" + key +
                                "': add it to 'materials' or set 'default_material'");
}

SceneDescription parse_scene_description(const nlohmann::json& j,
                                         const std::filesystem::path& base_dir,
                                         const std::string& source) {
  SceneDescription d;
  d.source = source;
  d.base_dir = base_dir;
  ParamReader f(j, source, "");
  if (f.has("frame")) d.frame = parse_frame(f.object("frame"));

  std::vector<NamedCamera> gltf_cameras;
  if (f.has("gltf")) {
    const auto& g = f.at("gltf");
    std::vector<std::pair<std::string, std::string>> files;  // (path, field)
    if (g.is_string()) {
      files.push_back({g.get<std::string>(), "gltf"});
    } else if (g.is_array()) {
      for (size_t i = 0; i < g.size(); ++i) {
        if (!g[i].is_string())
          throw Error(source, "gltf[" + std::to_string(i) + "]", "must be a file name");
        files.push_back({g[i].get<std::string>(), "gltf[" + std::to_string(i) + "]"});
      }
    } else {
      throw Error(source, "gltf", "must be a file name or a list of them");
    }
    for (const auto& [file, field] : files) {
      const auto path = base_dir / file;
      std::error_code ec;
      if (!std::filesystem::is_regular_file(path, ec))
        throw Error(source, field, "glTF file not found: " + path.string());
      GltfContent content = load_gltf(path);
      for (auto& m : content.meshes) d.meshes.push_back(std::move(m));
      for (auto& c : content.curves) d.curves.push_back(std::move(c));
      for (const auto& [key, info] : content.materials) d.gltf_materials[key] = info;
      for (auto& c : content.cameras) gltf_cameras.push_back(std::move(c));
      d.lights.directional.insert(d.lights.directional.end(), content.lights.directional.begin(),
                                  content.lights.directional.end());
      d.lights.points.insert(d.lights.points.end(), content.lights.points.begin(),
                             content.lights.points.end());
      for (auto& w : content.warnings) d.warnings.push_back(std::move(w));
    }
  }
  if (f.has("objects")) {
    const auto& objs = f.at("objects");
    if (!objs.is_array()) throw Error(source, "objects", "must be a list");
    for (size_t i = 0; i < objs.size(); ++i)
      parse_object(ParamReader(objs[i], source, "objects[" + std::to_string(i) + "]"), d);
  }
  if (f.has("materials")) {
    const auto& mats = f.at("materials");
    if (!mats.is_object()) throw Error(source, "materials", "must be an object of bindings");
    for (const auto& [key, value] : mats.items())
      d.materials[key] = parse_binding(ParamReader(value, source, "materials." + key), true);
  }
  if (f.has("default_material"))
    d.default_material = parse_binding(f.object("default_material"), false);
  if (f.has("lights")) {
    const auto& ls = f.at("lights");
    if (!ls.is_array()) throw Error(source, "lights", "must be a list");
    for (size_t i = 0; i < ls.size(); ++i)
      parse_light(ParamReader(ls[i], source, "lights[" + std::to_string(i) + "]"), d.frame,
                  d.lights);
  }
  if (f.has("fiber_geometry")) d.fiber_geometry = parse_fiber_geometry(f.object("fiber_geometry"));
  if (f.has("render")) d.render = f.at("render");
  if (f.has("sweep")) d.sweep = f.at("sweep");
  if (f.has("camera"))
    d.camera = parse_camera(f.object("camera"), d, gltf_cameras);
  else if (!gltf_cameras.empty())
    d.camera = gltf_cameras.front().camera;
  f.finish();

  if (d.meshes.empty() && d.curves.empty())
    throw Error(source, "gltf", "the scene has no geometry");
  // Every mesh and fiber needs a material: fail now rather than at render time.
  for (const auto& m : d.meshes) d.binding_for(m->material);
  for (const auto& c : d.curves) {
    c->validate(source, "curves");
    for (const auto& key : c->yarn_material) d.binding_for(key);
  }
  for (const auto& [key, b] : d.materials)
    if (!d.gltf_materials.count(key)) {
      bool used = false;
      for (const auto& m : d.meshes) used = used || m->material == key;
      for (const auto& c : d.curves)
        for (const auto& y : c->yarn_material) used = used || y == key;
      if (!used)
        d.warnings.push_back(source + ": materials." + key + ": no mesh uses this material");
    }
  return d;
}

SceneDescription load_scene_description(const std::filesystem::path& path) {
  const std::string source = path.string();
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(source, "", "cannot open scene description");
  std::stringstream ss;
  ss << in.rdbuf();
  const nlohmann::json j = parse_json(ss.str(), source);
  const auto base = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  return parse_scene_description(j, base, source);
}

}  // namespace weft
