#pragma once
// The dye depth that gives a cloth the colour a user knows (`--colour`, core/colour_target.h):
// the scale of each dye of a fiber's recipe such that a reading of the cloth made of the fiber
// meets the target. The reading is the caller's (a fabric bake's d/8 reading: the hemispherical
// reflectance of light near the normal, fabric/fabric_colour.h); the solver only asks for
// readings and chooses the next scales.
//
// How the next scales are chosen (docs/colour.md): the dyes change only the fibre's absorption
// mu(lambda) = host + sum_d s_d mu_d(lambda), band by band, and a cloth's reflectance in a band is
// a falling function of that band's absorption alone. Each band's reflectance is modelled as
// Kubelka-Munk's R = A * KM(q mu), KM(x) = 1 + x - sqrt(x^2 + 2x) the reflectance of an opaque
// layer of absorption-to-scattering ratio x, with A and q fitted through the two readings nearest
// in mu; the scales that bring the model's colour to the target are read next, and each reading
// refits the model where it is. The model only steers: the colour reported is always a reading's.
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "weft/core/colour_target.h"
#include "weft/fiber/fiber_spec.h"

namespace weft {

// What the solver scales: the recipe's dyes, each in % owf (its absorption per 1 % owf at the
// recipe's uptake), or for a fiber without dyes the three smooth absorbers of --thread-colours
// (fiber/thread_colour.h), each at scale 1 absorbing half the light along the fibre's mean chord.
struct DyeBasis {
  std::vector<std::string> names;
  std::vector<Spectrum> absorption_per_um;  // at scale 1
  std::vector<double> initial_scale;        // the recipe's (1 for the blocks)
  std::vector<double> max_scale;            // kMaxDyeOwfPercent; the blocks' 1 % floor
  bool recipe = true;                       // the spec's dyes (else the thread-colour blocks)
};
DyeBasis dye_basis(const FiberSpec& spec);
// The recipe completed to a trichromatic set (dye.h DyeHue), as a dyehouse matches a shade: where
// every dye of the recipe is of one class and a hue of the three has none, that class's bundled
// dye of the hue (its peak nearest the hue's middle: 440, 520, 620 nm) is added at 0 % owf, with
// the recipe's first uptake. Two dyes reach only a surface of the colours; three reach the
// colours between them (a dull red: red, yellow and a touch of blue). Unchanged: no dyes, mixed
// or unnamed classes, or every hue present.
FiberSpec trichromatic_recipe(const FiberSpec& spec);
// 'base' with its dyes at these scales (or the blocks' absorption added), named "<base> dyed".
FiberSpec with_dye_scale(const FiberSpec& base, const DyeBasis& basis,
                         const std::vector<double>& scale);

struct ColourMatchOptions {
  double tolerance_delta_e00 = 1.0;  // stop at a reading this close (a just-noticeable difference)
  int max_readings = 8;              // readings in all, the two first ones included
  bool complete_hues = true;         // scale trichromatic_recipe(base), not base's dyes alone
  void validate() const;             // weft::Error naming the field
};

struct ColourReading {
  std::vector<double> scale;
  Spectrum reflectance{};
  Lab lab;
  double delta_e00 = 0;
  double cpu_seconds = 0;
};

struct ColourMatch {
  ColourTarget target;
  DyeBasis basis;
  std::vector<ColourReading> readings;  // in the order taken
  size_t best = 0;                      // the reading closest to the target
  bool reached = false;                 // best's delta_e00 <= the tolerance
  bool cancelled = false;
  // Not reached with a scale at its bound: the target lies outside what the dyes can give; the
  // best reading is then the nearest reachable colour.
  bool outside_reach = false;
  FiberSpec spec;                       // the base with best's scales (and the dyes added to it)
  std::vector<std::string> added_dyes;  // by trichromatic_recipe, at the basis's end
  const ColourReading& best_reading() const { return readings.at(best); }
};

// The reflectance of the cloth made of a fiber (per band, what a d/8 instrument reads), or
// nothing when the work was interrupted.
using ColourReadingFunction = std::function<std::optional<Spectrum>(const FiberSpec&)>;

// Readings at the recipe as written (scale 1) and without dyes, then at the scales the model
// steers to until one is within the tolerance, max_readings are taken, or a step stops moving.
// The dyes scaled are those of trichromatic_recipe(base) (options.complete_hues): the added ones
// start at 0.
ColourMatch match_colour(const FiberSpec& base, const ColourTarget& target,
                         const ColourReadingFunction& read, const ColourMatchOptions& options);

// --json's colour_match: target and achieved Lab, delta_e00, dye_scale per dye, the readings and
// their CPU time.
nlohmann::json colour_match_summary(const ColourMatch& match);

}  // namespace weft
