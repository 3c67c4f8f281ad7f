#pragma once
// A car seat for upholstery renders (`weft scene car-seat`): seat cushion and backrest, each a
// centre panel with quilting seams between two side bolsters and a piping loop around the centre
// panel, a headrest on two posts, and a base under the cushion standing on y = 0. glTF units
// (metres, +y up); the seat faces +z.
//
// Every part is one closed surface (a rounded box or a closed tube) deformed by maps that shift
// one coordinate by a function of the others, so no part folds onto itself. Parts touch and
// interpenetrate where panels meet, as sewn panels do. Each part has its own UVs laid out so that
// u runs along the panel's warp direction (front to back on the cushion, bottom to top on the
// backrest, left to right on the headrest, along the piping); tangents are dP/du
// (mesh.h derive_tangents), so a fabric's warp follows each panel.
//
// Material keys (bind them in a scene description): centre, bolster, piping, headrest, post,
// base.
// Node names: the part names below, all under the root node "seat".
#include <filesystem>
#include <string>
#include <vector>

#include "weft/scenes/mesh.h"

namespace weft {

struct CarSeatOptions {
  // Edge length of the surface grid (millimetres); the seams are about 12 mm wide.
  double cell_mm = 5.0;
  double piping_radius_mm = 4.0;
  int piping_sides = 12;  // segments around the piping tube
  void validate() const;  // Error naming the field when out of range
};

struct CarSeatPart {
  std::string name;    // node name, e.g. "cushion_centre"
  TriangleMesh mesh;   // material = the panel's key, names = {name, "seat"}
  Vec3 warp{0, 0, 1};  // the panel's warp axis before deformation (world, unit)
};

struct CarSeat {
  std::vector<CarSeatPart> parts;
  size_t triangle_count() const;
  size_t vertex_count() const;
};

// Deterministic: the same options give the same bits.
CarSeat make_car_seat(const CarSeatOptions& options = {});
// .gltf (embedded buffer) or .glb by extension, written atomically; Error naming the path on a
// wrong extension.
void write_car_seat_gltf(const std::filesystem::path& path, const CarSeat& seat,
                         const CarSeatOptions& options);

}  // namespace weft
