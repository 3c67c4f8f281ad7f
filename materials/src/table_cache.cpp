#include "weft/materials/table_cache.h"

#include <system_error>

#include "weft/core/error.h"

namespace weft {
namespace {

std::string canonical_key(const std::filesystem::path& file) {
  std::error_code ec;
  const auto canon = std::filesystem::canonical(file, ec);
  if (ec) throw Error(file.string(), "", "no such file");
  return canon.string();
}

}  // namespace

std::shared_ptr<const TabulatedBsdfData> load_tabulated_bsdf(const std::filesystem::path& file) {
  return TabulatedBsdfData::prepare(TabulatedBsdfTable::read_exr(file));
}

std::shared_ptr<const TabulatedBsdfData> TableCache::tabulated(const std::filesystem::path& file) {
  const std::string key = canonical_key(file);
  std::lock_guard lock(mutex_);
  auto& slot = tables_[key];
  if (!slot) {
    try {
      slot = load_tabulated_bsdf(key);
    } catch (...) {
      tables_.erase(key);
      throw;
    }
  }
  return slot;
}

std::shared_ptr<const NbrdfNetwork> TableCache::nbrdf(const std::filesystem::path& file) {
  const std::string key = canonical_key(file);
  std::lock_guard lock(mutex_);
  auto& slot = networks_[key];
  if (!slot) {
    try {
      slot = std::make_shared<const NbrdfNetwork>(NbrdfNetwork::load(key));
    } catch (...) {
      networks_.erase(key);
      throw;
    }
  }
  return slot;
}

size_t TableCache::size() const {
  std::lock_guard lock(mutex_);
  return tables_.size() + networks_.size();
}

}  // namespace weft
