// Per-yarn fiber tables of the fiber-level ray trace (fabric_raytrace.h, FiberTables): the map from
// a sample's yarns and yarn tubes to the tables, checked against the sample.
#include <string>

#include "weft/core/error.h"
#include "weft/fabric/fabric_raytrace.h"

namespace weft {
namespace {

// Every entry of 'map' indexes a table; 'map' has one entry per yarn (or mesh) of the sample, or
// none (then every one takes table 0).
void check_map(const std::vector<int>& map, size_t needed, size_t tables, const char* field) {
  if (!map.empty() && map.size() != needed)
    throw Error("", field,
                "has " + std::to_string(map.size()) + " entries for the sample's " +
                    std::to_string(needed));
  for (size_t i = 0; i < map.size(); ++i)
    if (map[i] < 0 || static_cast<size_t>(map[i]) >= tables)
      throw Error("", std::string(field) + "[" + std::to_string(i) + "]",
                  "must index one of the " + std::to_string(tables) + " fiber tables");
}

}  // namespace

std::string fiber_table_field(const FiberTables& f, size_t k) {
  std::string s = "fiber tables[" + std::to_string(k) + "]";
  if (k < f.names.size() && !f.names[k].empty()) s += " (" + f.names[k] + ")";
  return s;
}

FiberTables fiber_tables_by_direction(const WovenSample& sample, const TabulatedBsdfTable& warp,
                                      const TabulatedBsdfTable& weft) {
  FiberTables f;
  f.tables = {&warp, &weft};
  f.names = {"warp", "weft"};
  for (const std::string& m : sample.fibers.yarn_material) f.table_of_yarn.push_back(m != "warp");
  for (const TriangleMesh& m : sample.meshes) f.table_of_mesh.push_back(m.material != "warp");
  return f;
}

FiberTables fiber_tables_by_colour(const WovenSample& sample,
                                   std::vector<std::array<double, 3>>& colours,
                                   const std::string& field) {
  const std::vector<std::array<double, 3>>& rgb = sample.yarn_rgb;
  const WeaveSummary& s = sample.summary;
  const size_t warps = static_cast<size_t>(s.warps) * static_cast<size_t>(s.repeats_z);
  const size_t wefts = static_cast<size_t>(s.wefts) * static_cast<size_t>(s.repeats_x);
  if (rgb.empty() || rgb.size() != warps + wefts)
    throw Error("", field, "the woven sample has no thread colours (they come from a WIF draft)");
  colours.clear();
  std::vector<int> of_yarn;
  for (const auto& c : rgb) {
    size_t k = 0;
    while (k < colours.size() && colours[k] != c) ++k;
    if (k == colours.size()) colours.push_back(c);
    of_yarn.push_back(static_cast<int>(k));
  }
  FiberTables f;
  f.tables.assign(colours.size(), nullptr);
  if (!sample.fibers.yarn_material.empty()) {
    if (sample.fibers.yarn_material.size() != rgb.size())
      throw Error("", field, "the sample's fibers are not one yarn per thread of the draft");
    f.table_of_yarn = of_yarn;
  }
  for (const TriangleMesh& m : sample.meshes) {
    const bool warp = m.material == "warp";
    const size_t first = warp ? 0 : warps, end = warp ? warps : warps + wefts;
    for (size_t y = first; y < end; ++y)
      if (of_yarn[y] != of_yarn[first])
        throw Error("", field,
                    std::string("at yarn detail all ") + (warp ? "warps" : "wefts") +
                        " are one tube mesh, but the draft's differ in colour: trace it at fiber "
                        "detail");
    f.table_of_mesh.push_back(of_yarn[first]);
  }
  return f;
}

void validate_fiber_tables(const FiberTables& f, const WovenSample& sample) {
  if (f.tables.empty() || f.tables.size() > static_cast<size_t>(kMaxFiberTables))
    throw Error("", "fiber tables",
                "takes 1 to " + std::to_string(kMaxFiberTables) + " tables, got " +
                    std::to_string(f.tables.size()));
  if (!f.names.empty() && f.names.size() != f.tables.size())
    throw Error("", "fiber tables", "names one table each, or none");
  for (size_t k = 0; k < f.tables.size(); ++k) {
    const TabulatedBsdfTable* t = f.tables[k];
    if (!t) throw Error("", fiber_table_field(f, k), "is missing");
    t->validate(fiber_table_field(f, k));
    if (t->kind != "fiber")
      throw Error("", fiber_table_field(f, k), "expected a fiber table, got " + t->kind);
    const TabulatedBsdfTable& first = *f.tables[0];
    if (t->resolution != first.resolution || t->channels != first.channels)
      throw Error("", fiber_table_field(f, k),
                  "has resolution " + std::to_string(t->resolution) + " and " +
                      std::to_string(t->channels) + " channels, " + fiber_table_field(f, 0) + " " +
                      std::to_string(first.resolution) + " and " + std::to_string(first.channels) +
                      ": every yarn's table must have the same resolution and channels");
  }
  check_map(f.table_of_yarn, sample.fibers.yarn_material.size(), f.tables.size(), "table_of_yarn");
  check_map(f.table_of_mesh, sample.meshes.size(), f.tables.size(), "table_of_mesh");
}

FiberTables distinct_fiber_tables(const FiberTables& f) {
  FiberTables d;
  std::vector<std::string> sums;
  std::vector<int> index_of(f.tables.size());
  for (size_t k = 0; k < f.tables.size(); ++k) {
    const std::string sum = f.tables[k]->checksum();
    size_t j = 0;
    while (j < sums.size() && sums[j] != sum) ++j;
    if (j == sums.size()) {
      sums.push_back(sum);
      d.tables.push_back(f.tables[k]);
      d.names.push_back(k < f.names.size() ? f.names[k] : "");
    }
    index_of[k] = static_cast<int>(j);
  }
  for (int y : f.table_of_yarn) d.table_of_yarn.push_back(index_of[y]);
  for (int m : f.table_of_mesh) d.table_of_mesh.push_back(index_of[m]);
  return d;
}

}  // namespace weft
