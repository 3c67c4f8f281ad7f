#include "weft/scenes/weave_request.h"

#include <stdexcept>

#include "weft/core/error.h"
#include "weft/core/output_guard.h"

namespace weft {
namespace {

// Parses "N" or "NxM" into repeats along x and z.
void parse_weave_repeats(const std::string& text, int& nx, int& nz) {
  const auto x = text.find_first_of("xX");
  try {
    size_t used = 0;
    if (x == std::string::npos) {
      nx = nz = std::stoi(text, &used);
      if (used != text.size()) throw std::invalid_argument(text);
    } else {
      nx = std::stoi(text.substr(0, x), &used);
      if (used != x) throw std::invalid_argument(text);
      nz = std::stoi(text.substr(x + 1), &used);
      if (used != text.size() - x - 1) throw std::invalid_argument(text);
    }
  } catch (const std::exception&) {
    throw Error("", "repeats", "expected N or NxM, got '" + text + "'");
  }
}

bool legacy_weave_requested(const WeaveRequest& q) {
  return q.yarns || q.yarn_radius_mm || q.spacing_mm || q.segments || q.amplitude_mm;
}

// The open-mesh patch of earlier versions; its options cannot be mixed with the sample's.
WeaveParams plan_legacy_weave(const WeaveRequest& q) {
  const WeaveOptions& w = q.options;
  const std::pair<const char*, bool> sample_options[] = {
      {"sample", q.sample.has_value()},
      {"wif", w.wif.has_value()},
      {"detail", w.detail.has_value()},
      {"repeats", q.repeats.has_value()},
      {"warp-spacing-mm", w.warp_spacing_mm.has_value()},
      {"weft-spacing-mm", w.weft_spacing_mm.has_value()},
      {"yarn-width-mm", q.yarn_width_mm.has_value()},
      {"yarn-thickness-mm", q.yarn_thickness_mm.has_value()},
      {"fibers-per-yarn", w.fibers_per_yarn.has_value()},
      {"packing", w.packing.has_value()},
      {"segments-per-crossing", w.segments_per_crossing.has_value()}};
  for (const auto& [name, given] : sample_options)
    if (given)
      throw Error("", name,
                  "cannot be combined with the legacy open-mesh options (--yarns, "
                  "--yarn-radius-mm, --spacing-mm, --segments, --amplitude-mm)");
  WeaveParams p;
  if (q.yarns) p.yarns = *q.yarns;
  if (q.yarn_radius_mm) p.yarn_radius_mm = *q.yarn_radius_mm;
  if (q.spacing_mm) p.spacing_mm = *q.spacing_mm;
  if (q.segments) p.segments = *q.segments;
  if (q.amplitude_mm) p.amplitude_mm = *q.amplitude_mm;
  p.pattern = w.pattern.value_or("plain");
  if (w.sides) p.sides = *w.sides;
  return p;
}

// --yarn-<size>-mm sets both directions' size, instead of either of its own options.
void set_both_yarn_sizes(const std::optional<double>& yarn, const std::string& size,
                         std::optional<double>& warp, std::optional<double>& weft) {
  if (!yarn) return;
  if (warp || weft)
    throw Error("", "yarn-" + size + "-mm",
                "give it or --warp-" + size + "-mm/--weft-" + size + "-mm, not both");
  warp = weft = yarn;
}

void check_one_of_weave(bool a, bool b, const char* field, const char* what) {
  if (a && b) throw Error("", field, std::string("give either ") + what + ", not both");
}

// The options the request gives, its rules checked.
WeaveOptions given_weave_options(const WeaveRequest& q) {
  WeaveOptions given = q.options;
  if (q.repeats && !q.repeats->empty()) {
    int nx = 1, nz = 1;
    parse_weave_repeats(*q.repeats, nx, nz);
    given.repeats_x = nx, given.repeats_z = nz;
  }
  set_both_yarn_sizes(q.yarn_width_mm, "width", given.warp_width_mm, given.weft_width_mm);
  set_both_yarn_sizes(q.yarn_thickness_mm, "thickness", given.warp_thickness_mm,
                      given.weft_thickness_mm);
  check_one_of_weave(given.pattern.has_value(), given.wif.has_value(), "wif", "--pattern or --wif");
  check_one_of_weave(given.packing.has_value(), given.fibers_per_yarn.has_value(), "packing",
                     "--packing or --fibers-per-yarn");
  check_one_of_weave(given.twist_per_mm.has_value(), given.twist_angle_deg.has_value(),
                     "twist-angle-deg", "--twist-per-mm or --twist-angle-deg");
  check_one_of_weave(given.thickness_mm.has_value(), given.solidity.has_value(), "solidity",
                     "--thickness-mm or --solidity");
  return given;
}

}  // namespace

WeavePlan plan_weave(const WeaveRequest& q) {
  WeavePlan plan;
  plan.output = q.output;
  if (legacy_weave_requested(q)) {
    plan.legacy = plan_legacy_weave(q);
    validate_output_paths(q.limits, {{q.output, "--output"}}, {});
    return plan;
  }
  const WeaveOptions given = given_weave_options(q);
  const std::string sample = q.sample.value_or("");
  const WeaveOptions base = sample.empty() ? WeaveOptions{} : read_weave_options(sample);
  plan.options = overlay(base, given);
  validate_output_paths(
      q.limits, {{q.output, "--output"}},
      {{sample, "sample description"}, {plan.options.wif.value_or(""), "WIF draft"}});
  return plan;
}

WeaveOutcome run_weave(const WeavePlan& plan) {
  WeaveOutcome out;
  if (plan.legacy) {
    for (const auto& m : make_weave(*plan.legacy))
      out.legacy_triangles += m.triangle_count(), out.legacy_vertices += m.vertex_count();
    write_weave(plan.output, *plan.legacy);
    return out;
  }
  const WovenSample sample = make_woven_sample(plan.options);
  write_woven(plan.output, sample);
  out.summary = sample.summary;
  return out;
}

}  // namespace weft
