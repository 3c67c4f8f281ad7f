// The narrow sheen reference's file: each case's batch curves, so that tables baked later are
// measured against the same reference in seconds (bench/sheen_bench.h).
#include <fstream>
#include <limits>
#include <sstream>

#include "weft/bench/sheen_bench.h"
#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/core/params.h"

namespace weft {
namespace {

constexpr const char* kFormat = "weft narrow sheen reference";
constexpr int kVersion = 1;
// A file of more is not one this command wrote (64 incidences x 64 azimuths, 64 batches).
constexpr uint64_t kMaxFileBytes = uint64_t{1} << 30;
constexpr size_t kMaxCases = 64 * 64, kMaxBatches = 64;

nlohmann::json curve_json(const InplaneCurve& c) {
  return {{"view_deg", c.view_deg}, {"beta", c.beta}, {"beta_se", c.beta_se}};
}

// An array of 'size' finite numbers in [lo, hi] at key of r, its length checked before any
// element is.
std::vector<double> numbers(ParamReader& r, const std::string& key, size_t size, double lo,
                            double hi) {
  const nlohmann::json& a = r.at(key);
  if (!a.is_array() || a.size() != size)
    throw Error(r.file(), r.field(key), "must be an array of " + std::to_string(size) + " numbers");
  std::vector<double> out;
  out.reserve(size);
  for (size_t i = 0; i < size; ++i)
    out.push_back(r.check_number(a[i], r.field(key) + "[" + std::to_string(i) + "]", lo, hi));
  return out;
}

// A batch's curve: the views a light of these bins gives, exactly, and beta and its error.
InplaneCurve read_curve(ParamReader r, const NarrowLight& light) {
  InplaneCurve c;
  const std::vector<double> views = narrow_views_deg(light);
  c.view_deg = numbers(r, "view_deg", views.size(), 0, 90);
  if (c.view_deg != views)
    throw Error(r.file(), r.field("view_deg"),
                "are not the views of bins of " + ParamReader::fmt(light.bin_deg) + " degrees");
  c.beta = numbers(r, "beta", views.size(), 0, 1e12);
  c.beta_se = numbers(r, "beta_se", views.size(), 0, 1e12);
  r.finish();
  return c;
}

NarrowCase read_case(ParamReader r, const NarrowLight& light) {
  NarrowCase k;
  k.incidence_deg = r.number("incidence_deg", 0, 89);
  k.azimuth_deg = r.number("azimuth_deg", -360, 360);
  const nlohmann::json& list = r.at("batches");
  if (!list.is_array() || list.size() < 2 || list.size() > kMaxBatches)
    throw Error(r.file(), r.field("batches"),
                "must be an array of 2 to " + std::to_string(kMaxBatches) + " batches");
  for (size_t b = 0; b < list.size(); ++b)
    k.batches.push_back(read_curve(
        ParamReader(list[b], r.file(), r.field("batches") + "[" + std::to_string(b) + "]"), light));
  r.finish();
  return k;
}

}  // namespace

void write_narrow_reference(const std::filesystem::path& path, const SheenPlan& plan,
                            const SheenResult& result) {
  const SheenRequest& r = plan.request;
  nlohmann::json cases = nlohmann::json::array();
  for (const SheenCase& c : result.cases) {
    nlohmann::json batches = nlohmann::json::array();
    for (const InplaneCurve& b : c.reference_batches) batches.push_back(curve_json(b));
    cases.push_back(
        {{"incidence_deg", c.incidence_deg}, {"azimuth_deg", c.azimuth_deg}, {"batches", batches}});
  }
  const nlohmann::json j = {{"format", kFormat},
                            {"version", kVersion},
                            {"fiber_checksum", plan.fiber.checksum()},
                            {"weave", r.weave},
                            {"half_angle_deg", r.narrow.half_angle_deg},
                            {"band_deg", r.narrow.band_deg},
                            {"bin_deg", r.narrow.bin_deg},
                            {"particles", r.narrow_particles},
                            {"next_event_rays", r.narrow_next_event_rays},
                            {"seed", r.seed},
                            {"cases", cases}};
  write_atomically(path, [&](const std::filesystem::path& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    out << j.dump(1) << "\n";
    if (!out) throw Error(path.string(), "", "cannot write the reference");
  });
}

std::vector<NarrowCase> read_narrow_reference(const std::string& path, SheenRequest& request,
                                              const TabulatedBsdfTable& fiber) {
  std::error_code ec;
  const auto bytes = std::filesystem::file_size(path, ec);
  if (ec) throw Error(path, "", "cannot read the narrow reference");
  if (bytes > kMaxFileBytes)
    throw Error(path, "",
                "is " + std::to_string(bytes) + " bytes; a narrow reference is at most " +
                    std::to_string(kMaxFileBytes));
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  if (!in) throw Error(path, "", "cannot read the narrow reference");
  const nlohmann::json j = parse_json(text.str(), path);
  ParamReader r(j, path, "");
  if (r.string("format") != kFormat)
    throw Error(path, "format", std::string("must be '") + kFormat + "'");
  if (r.integer("version", 1, 1000) != kVersion)
    throw Error(path, "version", "must be " + std::to_string(kVersion) + " (written by this Weft)");
  if (r.string("fiber_checksum") != fiber.checksum())
    throw Error(path, "fiber_checksum",
                "the reference was traced with another fiber table than --fiber " + request.fiber);
  (void)r.string("weave");  // what it was traced on, for the reader
  NarrowLight& light = request.narrow;
  light.half_angle_deg = r.number("half_angle_deg", 0, NarrowLight::kMaxHalfAngleDeg);
  light.band_deg = r.number("band_deg", NarrowLight::kMinBandDeg, NarrowLight::kMaxBandDeg);
  light.bin_deg = r.number("bin_deg", NarrowLight::kMinBinDeg, NarrowLight::kMaxBinDeg);
  request.narrow_particles = r.count("particles", 1, uint64_t{1} << 32);
  request.narrow_next_event_rays =
      static_cast<int>(r.integer("next_event_rays", 0, kMaxNextEventRays));
  request.seed = r.count("seed", 0, std::numeric_limits<uint64_t>::max());
  const nlohmann::json& list = r.at("cases");
  if (!list.is_array() || list.empty() || list.size() > kMaxCases)
    throw Error(path, "cases", "must be an array of 1 to " + std::to_string(kMaxCases) + " cases");
  std::vector<NarrowCase> cases;
  for (size_t k = 0; k < list.size(); ++k)
    cases.push_back(
        read_case(ParamReader(list[k], path, "cases[" + std::to_string(k) + "]"), light));
  r.finish();
  request.batches = static_cast<int>(cases[0].batches.size());
  for (size_t k = 1; k < cases.size(); ++k)
    if (cases[k].batches.size() != cases[0].batches.size())
      throw Error(path, "cases[" + std::to_string(k) + "].batches",
                  "every case must have as many batches as the first");
  return cases;
}

}  // namespace weft
