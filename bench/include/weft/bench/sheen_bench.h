#pragma once
// How much of a cloth's mirror peak (its sheen) a fabric table keeps: the peak of a table's
// in-plane curve against a brute-force reference (weft bench sheen; docs/fabric-bsdf.md, "Sharp
// sheen: what a table keeps"). Two references: grid, the fiber-level ray trace at a fine grid (R 32
// by default, bins about 3.5 degrees across) of only the light bins the in-plane curves read; and
// narrow, a narrow light at each asked incidence whose reflected exits are booked by their angle in
// its plane of incidence (NarrowLight, fabric/fabric_raytrace.h), which averages the peak over
// neither a light bin nor an exit cell (docs/fabric-bsdf.md, "A narrow light").
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "weft/core/names.h"
#include "weft/core/progress.h"
#include "weft/fabric/fabric_raytrace.h"
#include "weft/materials/bsdf_table.h"
#include "weft/scenes/weave.h"

namespace weft {

// A table's mirror peak in one plane of incidence: beta = pi f (the channels' mean, interpolated
// as the renderer reads the table) at views on the mirror side every 0.5 degree; the peak is the
// largest beta within 10 degrees of the mirror view, the base the smaller beta 20 degrees either
// side of the mirror, the width (FWHM) that of the views around the peak above base + (peak -
// base) / 2; mirror_beta is beta at the mirror view itself (a cloth without a peak, whose largest
// point near the mirror a noisy reference would read from its noise, is compared there). A table
// with a sheen (half_vector_lobe.h) is read with it: the cells less the sheen's cell averages,
// interpolated, plus the sheen.
struct InplanePeak {
  double beta = 0, view_deg = 0, base = 0, fwhm_deg = 0, mirror_beta = 0;
};
InplanePeak inplane_peak(const TabulatedBsdfTable& table, double theta_i_deg, double azimuth_deg);

// The narrow reference's in-plane curve on the mirror's side: beta = pi f (the channels' mean)
// at each plane bin's view (a batch's, or the batches' mean), with its standard error (from the
// particles').
struct InplaneCurve {
  std::vector<double> view_deg, beta, beta_se;
};

// The views of a narrow light's curve: plane bin k's on the mirror's side is the view
// kMaxPlaneDeg - (k + 1/2) bin_deg, those above 0 degrees, ascending.
double mirror_view_deg(const NarrowLight& light, int k);
std::vector<double> narrow_views_deg(const NarrowLight& light);

enum class SheenReference { grid, narrow };
inline constexpr NameTable<SheenReference, 2> kSheenReferenceNames{{
    {SheenReference::grid, "grid", "the ray trace's cells at a fine grid"},
    {SheenReference::narrow, "narrow", "a narrow light's exits in its plane of incidence"},
}};

struct SheenRequest {
  std::string fiber;  // the fiber table (.exr) the reference traces (its surface lobe exact)
  std::string weave = "scenes/examples/polyester-satin-weave.json";  // woven sample options
  int resolution = 32;                                               // the reference's grid
  uint64_t particles_per_bin = 50000;                                // per light bin and batch
  int batches = 2;  // independent traces (seeds seed, seed + 1, ...)
  uint64_t seed = 1;
  std::vector<double> incidences_deg = {30, 45, 60};
  std::vector<double> azimuths_deg = {0, 90};  // planes of incidence (0: the warp's)
  std::vector<std::string> tables;             // fabric tables to measure against it
  // The reference's batches from an earlier run (SheenResult::batches, written by weft bench sheen
  // --reference-out): read instead of traced, two or more of one grid.
  std::vector<std::string> reference_batches;
  // The narrow reference's curves from an earlier run (write_narrow_reference): read instead of
  // traced; each asked case must be in it, traced with the same fiber table.
  std::string narrow_reference;
  SheenReference reference = SheenReference::grid;
  // The narrow reference: its light's cone, band and bins (theta and azimuth are each case's),
  // its particles per case and batch, the next-event draws per scattering (FabricRaytraceOptions::
  // next_event_rays: on the satin, 16 cut the variance per CPU second 2.2-fold against none), and
  // the running mean over smooth_deg (the bins within half of it either side of each bin's centre)
  // its curve is read after (its mirror_beta: the running mean at the bin nearest the mirror).
  NarrowLight narrow;
  uint64_t narrow_particles = uint64_t{1} << 18;
  int narrow_next_event_rays = 16;
  double smooth_deg = 1;
  int threads = 0;
};

// The narrow reference's batches per case (InplaneCurve each), as a file keeps them.
struct NarrowCase {
  double incidence_deg = 0, azimuth_deg = 0;
  std::vector<InplaneCurve> batches;
};

struct SheenPlan {
  SheenRequest request;
  TabulatedBsdfTable fiber;
  WovenSample sample;
  std::vector<TabulatedBsdfTable> tables;
  std::vector<TabulatedBsdfTable> reference_batches;  // read, when the request names them
  std::vector<int> rows;  // the reference's light bins: the in-plane curves' footprints
  std::vector<NarrowCase> narrow_cases;  // read, when the request names a narrow reference
};
// Reads and checks everything before any work: weft::Error naming the option.
SheenPlan plan_sheen(const SheenRequest& request);

struct SheenCase {
  double incidence_deg = 0, azimuth_deg = 0;
  InplanePeak reference;           // of the batches' mean table (narrow: mean curve, smoothed)
  double reference_beta_se = 0;    // standard error of the peak over the batches
  double reference_mirror_se = 0;  // and of mirror_beta
  InplaneCurve reference_curve;    // narrow only
  std::vector<InplaneCurve> reference_batches;  // narrow only: each batch's curve
  std::vector<InplanePeak> tables;
};
struct SheenResult {
  std::vector<SheenCase> cases;
  TabulatedBsdfTable reference;             // grid: the batches' mean (only the plan's rows)
  std::vector<TabulatedBsdfTable> batches;  // grid: each batch's rows
  double cpu_seconds = 0;
  bool cancelled = false;
};
SheenResult run_sheen(const SheenPlan& plan, const ProgressCallback& progress = no_progress());

// A narrow reference's curves (JSON: the fiber table's checksum, the light's cone, band and bins,
// its particles, next-event draws and seed, and per case each batch's curve), written whole or not
// at all, and read back: weft::Error naming the file and field on anything malformed or on another
// fiber table's reference; the file's light, particles, draws, seed and batch count replace the
// request's.
void write_narrow_reference(const std::filesystem::path& path, const SheenPlan& plan,
                            const SheenResult& result);
std::vector<NarrowCase> read_narrow_reference(const std::string& path, SheenRequest& request,
                                              const TabulatedBsdfTable& fiber);

}  // namespace weft
