// weft spectrum: colour of a 33-band reflectance spectrum under D65 (XYZ, linear sRGB, HSV).
#include <cmath>
#include <iostream>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "weft/core/error.h"
#include "weft/core/spectrum.h"

namespace weft::cli {

void add_spectrum_command(CLI::App& app, Commands& commands) {
  struct Options {
    std::vector<double> values;
  };
  auto opt = std::make_shared<Options>();
  auto* sub = app.add_subcommand(
      "spectrum", "Colour (XYZ, linear sRGB, HSV under D65) of a 33-band reflectance, 390-710 nm");
  sub->add_option("values", opt->values, "33 reflectance values, 390..710 nm in 10 nm steps")
      ->required();
  commands.push_back(
      {sub, [opt](const RunLimits&) {
         if (opt->values.size() != kNumBands)
           throw Error("", "values",
                       "expected 33 values, got " + std::to_string(opt->values.size()));
         Spectrum s{};
         for (int b = 0; b < kNumBands; ++b) {
           if (!std::isfinite(opt->values[b]))
             throw Error("", "values", "value " + std::to_string(b) + " is not finite");
           s[b] = opt->values[b];
         }
         const Xyz xyz = reflectance_to_xyz_d65(s);
         const Rgb rgb = xyz_to_linear_srgb(xyz);
         const Hsv hsv = rgb_to_hsv(rgb);
         nlohmann::json j = {{"xyz", {xyz.x, xyz.y, xyz.z}},
                             {"linear_srgb", {rgb.r, rgb.g, rgb.b}},
                             {"hsv", {hsv.h, hsv.s, hsv.v}}};
         std::cout << j.dump(2) << "\n";
         return 0;
       }});
}

}  // namespace weft::cli
