#pragma once
// A material context whose folder holds a fiber table and a fabric table, for the tests that build
// every material by name.
#include <filesystem>
#include <memory>
#include <utility>

#include "test_util.h"
#include "weft/materials/bsdf_table.h"
#include "weft/materials/registry.h"
#include "weft/materials/table_cache.h"

namespace weft::testing {

// Writes 'table' to dir/tables/fiber.exr and, as kind "fabric", to dir/tables/fabric.exr; the
// context resolves files against dir and shares one fresh cache.
inline MaterialContext context_with_tables(const std::filesystem::path& dir,
                                           TabulatedBsdfTable table) {
  std::filesystem::create_directories(dir / "tables");
  table.kind = "fiber";
  table.write_exr(dir / "tables" / "fiber.exr");
  table.kind = "fabric";
  table.write_exr(dir / "tables" / "fabric.exr");
  MaterialContext ctx;
  ctx.base_dir = dir;
  ctx.cache = std::make_shared<TableCache>();
  return ctx;
}

// The same in the running test's fresh folder (fresh_test_dir), which is then ctx.base_dir.
inline MaterialContext context_with_tables(TabulatedBsdfTable table) {
  return context_with_tables(fresh_test_dir(), std::move(table));
}

}  // namespace weft::testing
