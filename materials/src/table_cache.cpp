#include "weft/materials/table_cache.h"

#include <map>
#include <memory>
#include <string>
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

// The entry of 'slots' for the canonical path of 'file', loaded on first use; a load that fails
// leaves no entry, so the next request tries again. The caller holds the cache's lock.
template <class T, class Load>
std::shared_ptr<const T> load_once(std::map<std::string, std::shared_ptr<const T>>& slots,
                                   const std::string& key, const Load& load) {
  auto& slot = slots[key];
  if (!slot) {
    try {
      slot = load(key);
    } catch (...) {
      slots.erase(key);
      throw;
    }
  }
  return slot;
}

}  // namespace

std::shared_ptr<const TabulatedBsdfData> load_tabulated_bsdf(const std::filesystem::path& file) {
  return TabulatedBsdfData::prepare(TabulatedBsdfTable::read_exr(file));
}

std::shared_ptr<const TabulatedBsdfData> TableCache::tabulated(const std::filesystem::path& file) {
  const std::string key = canonical_key(file);
  std::lock_guard lock(mutex_);
  return load_once(tables_, key, [](const std::string& path) { return load_tabulated_bsdf(path); });
}

std::shared_ptr<const WeaveModulation> load_weave(const std::filesystem::path& file) {
  return std::make_shared<const WeaveModulation>(WeaveTable::read_exr(file));
}

std::shared_ptr<const WeaveModulation> TableCache::weave(const std::filesystem::path& file) {
  const std::string key = canonical_key(file);
  std::lock_guard lock(mutex_);
  return load_once(weaves_, key, [](const std::string& path) { return load_weave(path); });
}

std::shared_ptr<const NbrdfNetwork> TableCache::nbrdf(const std::filesystem::path& file) {
  const std::string key = canonical_key(file);
  std::lock_guard lock(mutex_);
  return load_once(networks_, key, [](const std::string& path) {
    return std::make_shared<const NbrdfNetwork>(NbrdfNetwork::load(path));
  });
}

size_t TableCache::size() const {
  std::lock_guard lock(mutex_);
  return tables_.size() + networks_.size() + weaves_.size();
}

}  // namespace weft
