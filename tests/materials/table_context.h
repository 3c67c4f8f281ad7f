#pragma once
// A material context whose folder holds a fiber table and a fabric table, for the tests that build
// every material by name.
#include <filesystem>
#include <memory>

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

}  // namespace weft::testing
