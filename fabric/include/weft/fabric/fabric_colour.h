#pragma once
// A fabric bake's colour match (`weft bake fabric --colour`, fiber/colour_match.h): the reading the
// solver asks for is what a d/8 spectrophotometer (specular component included) reads of the cloth
// the bake makes, the directional reflectance of its normal's incident bin, per band.
#include <filesystem>
#include <optional>
#include <vector>

#include "weft/core/progress.h"
#include "weft/fabric/fabric_bake.h"
#include "weft/fiber/colour_match.h"

namespace weft {

// Readings at most per match (the two that set the model up included).
inline constexpr int kFabricColourReadings = 8;

// The reading of the cloth of 'sample' made of 'spec' by the plan's method: the spectral fiber
// table through the bake cache, then for a ray trace the normal's incident bin alone at the plan's
// settings (the other bins do not enter the reading), for a summation its whole table. Nothing
// when interrupted.
std::optional<Spectrum> fabric_d8_reading(const FabricBakePlan& plan, const WovenSample& sample,
                                          const FiberSpec& spec, const ProgressCallback& progress);

// What a reading depends on of the woven sample: its summary, without the time it took to make.
nlohmann::json woven_sample_identity(const WovenSample& sample);

// The spectral fiber table a reading of 'spec' uses (through the bake cache): the table a
// matched bake traces, so that its normal's row is the reading's bit for bit.
TabulatedBsdfTable colour_fiber_table(const FabricBakePlan& plan, const FiberSpec& spec,
                                      const ProgressCallback& progress);

// The reading of the cloth of 'sample' made of a spectral 'fiber' table by a ray trace with
// options 'r': the normal's incident bin alone. Nothing when interrupted.
std::optional<Spectrum> raytrace_d8_reading(const WovenSample& sample,
                                            const TabulatedBsdfTable& fiber,
                                            FabricRaytraceOptions r,
                                            const ProgressCallback& progress);

struct FabricColourMatch {
  ColourMatch match;
  bool cached = false;  // read from the cache: no reading was taken
};

// The match of 'base' to 'target' by these readings, from ./.weft-cache/colour-<key>.json when
// one with the same inputs ('inputs': what a reading depends on besides the fiber and the
// target) was made before (its readings replayed, none taken), else solved and stored.
FabricColourMatch cached_colour_match(const nlohmann::json& inputs, const FiberSpec& base,
                                      const ColourTarget& target,
                                      const ColourReadingFunction& read);

// The plan's colour match, from ./.weft-cache/colour-<key>.json when one with the same inputs
// (fiber spec, target, sample, method and settings) was made before, else solved and stored.
FabricColourMatch match_fabric_colour(const FabricBakePlan& plan, const WovenSample& sample,
                                      const ProgressCallback& progress);

// --thread-colours match: per distinct colour of the sample's threads (fiber_tables_by_colour's
// order), --fiber with the thread-colour absorbers solved so that a cloth of that thread alone
// (the plan's sample, method and settings) reads the colour, each match cached as a fabric bake's
// is; white is the undyed fiber itself. 'summary' gets each colour's colour_match. Nothing when
// interrupted.
std::optional<std::vector<FiberSpec>> match_thread_colours(const FabricBakePlan& plan,
                                                           const WovenSample& sample,
                                                           const ProgressCallback& progress,
                                                           nlohmann::json& summary);
// Checked before any work: --fiber undyed (its thread colours are its dyes) and the readings'
// time for 'colours' matches. weft::Error naming --thread-colour-method.
void check_thread_colour_match(const FabricBakeRequest& request, size_t colours);

// The table's own reading at normal incidence: the target's colour of its spectrum, or of its
// linear sRGB for an RGB table (then under the 2-degree observer whatever the target's).
Lab table_d8_lab(const TabulatedBsdfTable& table, const ColourTarget& target);
// --json's colour_match: the match's summary (colour_match_summary), whether it came from the
// cache, and the written table's own reading and its distance to the target.
nlohmann::json colour_summary(const FabricColourMatch& colour, const TabulatedBsdfTable& table);
// The table's metadata "colour" (the target and the delta E reached), and the note for the user
// (reached or how near, how many readings, the dyes' depths).
std::string colour_metadata(const FabricColourMatch& colour);
std::string colour_match_note(const FabricColourMatch& colour);
// Both, into the table and the result's notes.
void describe_colour_match(const FabricColourMatch& colour, TabulatedBsdfTable& table,
                           FabricBakeResult& out);

// Checked before any work (plan_fabric_bake): the target, a fiber that is a spec (a table's
// colour is fixed), no per-yarn fibers, and the readings' time. weft::Error naming --colour.
ColourTarget check_fabric_colour(const FabricBakeRequest& request, FabricMethod method);

}  // namespace weft
