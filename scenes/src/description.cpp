#include "weft/scenes/description.h"

#include <fstream>
#include <sstream>

#include "weft/core/error.h"
#include "weft/core/frame.h"
#include "weft/core/math.h"
#include "weft/core/params.h"
#include "weft/scenes/primitives.h"

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

// {"type": "environment", "file": "sky.exr", "scale": c}: an equirectangular OpenEXR map
// (environment_map.h) in the description's angle frame; without "file", constant radiance.
void parse_environment_map(ParamReader& f, const AngleFrame& frame,
                           const std::filesystem::path& base_dir, Lights& lights,
                           std::vector<std::filesystem::path>& files) {
  if (f.has("radiance"))
    throw Error(f.file(), f.field("radiance"), "give either 'radiance' or 'file' (use 'scale')");
  std::filesystem::path file = f.string("file");
  if (file.is_relative()) file = base_dir / file;
  const Rgb scale = f.has("scale") ? f.rgb("scale", 0, kMaxRadiometric) : Rgb(1.0);
  try {
    lights.environment_maps.emplace_back(read_environment_exr(file),
                                         Frame::from_normal_tangent(frame.normal, frame.tangent),
                                         scale, file.string());
  } catch (const Error& e) {
    throw Error(f.file(), f.field("file"), e.what());
  }
  files.push_back(file);
}

// {"type": "sky", "zenith_radiance": c, "sun_zenith_deg": t, "sun_azimuth_deg": p,
//  "resolution": [w, h]}: the CIE standard clear sky (environment_map.h) as an environment map.
void parse_sky(ParamReader& f, const AngleFrame& frame, Lights& lights) {
  const Rgb zenith = f.rgb("zenith_radiance", 0, kMaxRadiometric);
  const double sun_zen = deg_to_rad(f.number("sun_zenith_deg", 0.0, 0.0, 90.0));
  const double sun_azi = deg_to_rad(f.number("sun_azimuth_deg", 0.0, -360.0, 360.0));
  int w = 256, h = 128;
  if (f.has("resolution")) {
    const auto& r = f.at("resolution");
    if (!r.is_array() || r.size() != 2)
      throw Error(f.file(), f.field("resolution"), "must be [width, height]");
    for (int k = 0; k < 2; ++k)
      if (!r[k].is_number_integer())
        throw Error(f.file(), f.field("resolution") + "[" + std::to_string(k) + "]",
                    "must be an integer");
    w = int(f.check_number(r[0], f.field("resolution") + "[0]", 4, 4096));
    h = int(f.check_number(r[1], f.field("resolution") + "[1]", 2, 2048));
  }
  try {
    lights.environment_maps.emplace_back(cie_clear_sky_texels(zenith, sun_zen, sun_azi, w, h),
                                         Frame::from_normal_tangent(frame.normal, frame.tangent),
                                         Rgb(1.0), f.file());
  } catch (const Error& e) {
    throw Error(f.file(), f.field("zenith_radiance"), e.what());
  }
}

void parse_light(ParamReader f, const AngleFrame& frame, const std::filesystem::path& base_dir,
                 Lights& lights, std::vector<std::filesystem::path>& files) {
  const std::string type = f.string("type");
  if (type == "parallel") {
    DirectionalLight d;
    d.irradiance = f.has("irradiance") ? f.rgb("irradiance", 0, kMaxRadiometric) : Rgb(1.0);
    d.to_light = parse_direction(f, frame, "direction");
    lights.directional.push_back(d);
  } else if (type == "environment" && f.has("file")) {
    parse_environment_map(f, frame, base_dir, lights, files);
  } else if (type == "sky") {
    parse_sky(f, frame, lights);
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
    throw Error(
        f.file(), f.field("type"),
        "unknown light type '" + type + "' (valid: parallel, environment, sky, point, spot)");
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
    m = make_quad(c, n, t, w, h);
  } else if (type == "sphere") {
    const Vec3 c = f.vec3("center");
    const double r = f.number("radius", 1e-30, 1e30);
    const int sub = static_cast<int>(f.integer("subdivisions", 3, 0, 7));
    const bool inward = f.boolean("inward", false);
    m = make_sphere(c, r, sub, inward);
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
    // KHR_lights_punctual's units (gltf.h): photometric unless the exporter wrote watts.
    const GltfLightUnits light_units =
        f.choice("gltf_light_units", "photometric", {"photometric", "radiometric"}) == "photometric"
            ? GltfLightUnits::photometric
            : GltfLightUnits::radiometric;
    for (const auto& [file, field] : files) {
      const auto path = base_dir / file;
      std::error_code ec;
      if (!std::filesystem::is_regular_file(path, ec))
        throw Error(source, field, "glTF file not found: " + path.string());
      GltfContent content = load_gltf(path, light_units);
      for (auto& m : content.meshes) d.meshes.push_back(std::move(m));
      for (auto& c : content.curves) d.curves.push_back(std::move(c));
      for (const auto& [key, info] : content.materials) d.gltf_materials[key] = info;
      for (auto& c : content.cameras) gltf_cameras.push_back(std::move(c));
      d.lights.directional.insert(d.lights.directional.end(), content.lights.directional.begin(),
                                  content.lights.directional.end());
      d.lights.points.insert(d.lights.points.end(), content.lights.points.begin(),
                             content.lights.points.end());
      for (auto& w : content.warnings) d.warnings.push_back(std::move(w));
      for (auto& n : content.notes) d.notes.push_back(std::move(n));
      d.files.insert(d.files.end(), content.files.begin(), content.files.end());
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
                  base_dir, d.lights, d.files);
  }
  if (f.has("fiber_geometry")) d.fiber_geometry = parse_fiber_geometry(f.object("fiber_geometry"));
  if (f.has("render")) d.render = f.at("render");
  if (f.has("sweep")) d.sweep = f.at("sweep");
  if (f.has("camera"))
    d.camera = parse_camera(f.object("camera"), d, gltf_cameras);
  else if (!gltf_cameras.empty())
    d.camera = gltf_cameras.front().camera;
  d.gltf_cameras = std::move(gltf_cameras);
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

namespace {

// One step of an override's key: a name (possibly joined with the next ones by '.') or an index.
struct KeyToken {
  std::string name;
  bool index = false;
  size_t i = 0;
};

std::vector<KeyToken> tokenize_key(const std::string& key, const std::string& source) {
  auto bad = [&](const std::string& why) { throw Error(source, "-D " + key, why); };
  std::vector<KeyToken> out;
  size_t p = 0;
  while (p < key.size()) {
    if (key[p] == '[') {
      const size_t close = key.find(']', p);
      if (close == std::string::npos || close == p + 1) bad("'[' without an index and ']'");
      const std::string digits = key.substr(p + 1, close - p - 1);
      if (digits.find_first_not_of("0123456789") != std::string::npos || digits.size() > 9)
        bad("'[" + digits + "]' is not an index");
      out.push_back({digits, true, std::stoul(digits)});
      p = close + 1;
      if (p < key.size() && key[p] == '.') {
        ++p;
        if (p == key.size()) bad("ends in '.'");
      } else if (p < key.size() && key[p] != '[') {
        bad("expected '.' or '[' after ']'");
      }
      continue;
    }
    const size_t end = key.find_first_of(".[", p);
    const std::string name = key.substr(p, end == std::string::npos ? end : end - p);
    if (name.empty()) bad("has an empty name");
    out.push_back({name});
    p = end == std::string::npos ? key.size() : end;
    if (p < key.size() && key[p] == '.') {
      ++p;
      if (p == key.size()) bad("ends in '.'");
    }
  }
  if (out.empty()) bad("is empty");
  return out;
}

const char* kind_of(const nlohmann::json& v) {
  if (v.is_number()) return "a number";
  if (v.is_boolean()) return "true or false";
  if (v.is_string()) return "text";
  if (v.is_array()) return "a list";
  if (v.is_object()) return "an object";
  return "null";
}

bool numeric_list(const nlohmann::json& v) {
  if (!v.is_array() || v.empty()) return false;
  for (const auto& e : v)
    if (!e.is_number()) return false;
  return true;
}

void apply_override(nlohmann::json& root, const SceneOverride& o, const std::string& source) {
  const std::string field = "-D " + o.key;
  const std::vector<KeyToken> tokens = tokenize_key(o.key, source);
  nlohmann::json* node = &root;
  std::string where;  // the path walked so far, as errors print it
  size_t t = 0;
  while (true) {
    const bool at_root = node == &root;
    if (node->is_array()) {
      const KeyToken& tok = tokens[t];
      const bool digits = !tok.name.empty() && !tok.index &&
                          tok.name.find_first_not_of("0123456789") == std::string::npos &&
                          tok.name.size() <= 9;
      if (!tok.index && !digits)
        throw Error(
            source, field,
            "addresses nothing: '" + where + "' is a list; give an index, as " + where + "[0]");
      const size_t i = tok.index ? tok.i : std::stoul(tok.name);
      if (i >= node->size())
        throw Error(
            source, field,
            "addresses nothing: '" + where + "' has " + std::to_string(node->size()) +
                (node->size() == 1 ? " entry" : " entries") +
                (node->empty() ? std::string()
                               : " (indices 0 to " + std::to_string(node->size() - 1) + ")"));
      where.append("[").append(std::to_string(i)).append("]");
      node = &(*node)[i];
      ++t;
    } else if (node->is_object()) {
      if (tokens[t].index)
        throw Error(source, field,
                    "addresses nothing: '" +
                        (where.empty() ? std::string("the description") : where) +
                        "' is an object, not a list");
      // The longest run of names joined by '.' that is a key of this object.
      size_t run = 0;
      while (t + run < tokens.size() && !tokens[t + run].index) ++run;
      size_t used = 0;
      std::string name;
      for (size_t k = run; k >= 1; --k) {
        std::string joined = tokens[t].name;
        for (size_t m = 1; m < k; ++m) joined += "." + tokens[t + m].name;
        if (node->contains(joined)) {
          used = k, name = joined;
          break;
        }
      }
      if (used == 0) {
        name = tokens[t].name;
        if (t + 1 == tokens.size()) {
          // A new last name: the parser checks it like any key in the file.
          (*node)[name] = nlohmann::json::parse(o.value, nullptr, false).is_discarded()
                              ? nlohmann::json(o.value)
                              : nlohmann::json::parse(o.value);
          return;
        }
        if (at_root) {
          (*node)[name] = nlohmann::json::object();
          used = 1;
        } else {
          std::string known;
          for (const auto& [k, v] : node->items()) known += (known.empty() ? "" : ", ") + k;
          throw Error(source, field,
                      "addresses nothing: '" + where + "' has no '" + name +
                          "' (it has: " + (known.empty() ? "nothing" : known) + ")");
        }
      }
      where += (where.empty() ? "" : ".") + name;
      node = &(*node)[name];
      t += used;
    } else {
      throw Error(source, field,
                  "addresses nothing: '" + where + "' is " + kind_of(*node) + ", not an object");
    }
    if (t == tokens.size()) break;
  }
  // Replace an existing value by one of the same kind.
  nlohmann::json value;
  if (node->is_string()) {
    value = o.value;
  } else {
    value = nlohmann::json::parse(o.value, nullptr, false);
    if (value.is_discarded()) value = o.value;
  }
  const bool same = std::string(kind_of(value)) == kind_of(*node) ||
                    (node->is_number() && numeric_list(value)) ||
                    (numeric_list(*node) && value.is_number());
  if (!same)
    throw Error(source, field,
                "'" + where + "' is " + kind_of(*node) + " in the description, but '" + o.value +
                    "' is " + kind_of(value));
  *node = std::move(value);
}

}  // namespace

SceneOverride parse_scene_override(const std::string& text) {
  const size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0)
    throw Error("", "-D", "'" + text + "' is not key=value (e.g. -D render.spp=64)");
  return {text.substr(0, eq), text.substr(eq + 1)};
}

void apply_scene_overrides(nlohmann::json& j, const std::vector<SceneOverride>& overrides,
                           const std::string& source) {
  if (!j.is_object()) throw Error(source, "", "the scene description must be a JSON object");
  for (const auto& o : overrides) apply_override(j, o, source);
}

NamedCamera select_camera(const SceneDescription& d, const std::string& which) {
  auto listing = [&] {
    if (d.gltf_cameras.empty()) return std::string("the scene has no glTF cameras");
    std::string s = "glTF cameras: ";
    for (size_t i = 0; i < d.gltf_cameras.size(); ++i)
      s += (i ? ", " : "") + std::to_string(i) + " " +
           (d.gltf_cameras[i].name.empty() ? std::string("(unnamed)")
                                           : "'" + d.gltf_cameras[i].name + "'");
    return s;
  };
  if (!which.empty() && which.size() <= 9 &&
      which.find_first_not_of("0123456789") == std::string::npos) {
    const size_t i = std::stoul(which);
    if (i < d.gltf_cameras.size()) return d.gltf_cameras[i];
    throw Error(d.source, "--camera", "no camera with index " + which + " (" + listing() + ")");
  }
  for (const auto& c : d.gltf_cameras)
    if (c.name == which) return c;
  throw Error(d.source, "--camera", "no camera named '" + which + "' (" + listing() + ")");
}

SceneDescription load_scene_description(const std::filesystem::path& path,
                                        const std::vector<SceneOverride>& overrides) {
  const std::string source = path.string();
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(source, "", "cannot open scene description");
  std::stringstream ss;
  ss << in.rdbuf();
  nlohmann::json j = parse_json(ss.str(), source);
  apply_scene_overrides(j, overrides, source);
  const auto base = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  return parse_scene_description(j, base, source);
}

}  // namespace weft
