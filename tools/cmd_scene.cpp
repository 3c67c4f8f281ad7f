// weft scene: generated scenes. `weft scene car-seat -o seat.gltf` writes the car seat
// (scenes/car_seat.h) and prints its part and triangle counts.
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "weft/scenes/car_seat.h"

namespace weft::cli {
namespace {

struct SceneOptions {
  std::string output;
  CarSeatOptions seat;
  bool json = false;
};

int run_car_seat(const SceneOptions& o, const RunLimits& limits) {
  validate_output_paths(limits, {{o.output, "--output"}}, {});
  const CarSeat seat = make_car_seat(o.seat);
  write_car_seat_gltf(o.output, seat, o.seat);
  if (o.json) {
    nlohmann::json parts = nlohmann::json::array();
    for (const auto& p : seat.parts)
      parts.push_back({{"name", p.name},
                       {"material", p.mesh.material},
                       {"triangles", p.mesh.triangle_count()},
                       {"vertices", p.mesh.vertex_count()}});
    std::cout << nlohmann::json({{"output", o.output},
                                 {"scene", "car-seat"},
                                 {"cell_mm", o.seat.cell_mm},
                                 {"parts", parts},
                                 {"triangles", seat.triangle_count()},
                                 {"vertices", seat.vertex_count()}})
                     .dump(2)
              << "\n";
  } else {
    std::printf("%s: car seat, %zu parts, %zu triangles, %zu vertices (cell %.3g mm)\n",
                o.output.c_str(), seat.parts.size(), seat.triangle_count(), seat.vertex_count(),
                o.seat.cell_mm);
  }
  return 0;
}

}  // namespace

void add_scene_command(CLI::App& app, Commands& commands) {
  auto* scene = app.add_subcommand("scene", "Generated scenes (glTF)");
  scene->require_subcommand(1);
  auto o = std::make_shared<SceneOptions>();
  auto* seat = scene->add_subcommand(
      "car-seat",
      "Car seat: cushion and backrest (centre panels with seams, bolsters, piping) and a headrest; "
      "materials centre, bolster, piping, headrest, post, base");
  seat->add_option("-o,--output", o->output, "output .gltf or .glb")->required();
  seat->add_option("--cell-mm", o->seat.cell_mm, "surface grid cell (mm)")
      ->check(CLI::Range(1.0, 100.0))
      ->capture_default_str();
  seat->add_option("--piping-radius-mm", o->seat.piping_radius_mm, "piping tube radius (mm)")
      ->check(CLI::Range(1.0, 10.0))
      ->capture_default_str();
  seat->add_flag("--json", o->json, "print a JSON summary");
  commands.push_back({seat, [o](const RunLimits& l) { return run_car_seat(*o, l); }});
}

}  // namespace weft::cli
