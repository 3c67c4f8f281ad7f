#pragma once
// Loaded-once tables shared between materials (MaterialContext::cache). Keyed by the canonical
// path of the file, so two spellings of one file share one copy. Thread-safe.
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "weft/materials/measured_nbrdf.h"
#include "weft/materials/tabulated_bsdf.h"
#include "weft/materials/weave_modulation.h"

namespace weft {

struct TableCache {
  // The prepared table in 'file' (read, validated and reduced to RGB on first use).
  std::shared_ptr<const TabulatedBsdfData> tabulated(const std::filesystem::path& file);
  // The weave table in 'file' (weave_table.h), read, validated and prepared on first use.
  std::shared_ptr<const WeaveModulation> weave(const std::filesystem::path& file);
  // The network in an nbrdf_weights.txt file.
  std::shared_ptr<const NbrdfNetwork> nbrdf(const std::filesystem::path& file);
  // Number of distinct files held.
  size_t size() const;

 private:
  mutable std::mutex mutex_;
  std::map<std::string, std::shared_ptr<const TabulatedBsdfData>> tables_;
  std::map<std::string, std::shared_ptr<const NbrdfNetwork>> networks_;
  std::map<std::string, std::shared_ptr<const WeaveModulation>> weaves_;
};

// Loads without a cache (what TableCache does on a miss).
std::shared_ptr<const TabulatedBsdfData> load_tabulated_bsdf(const std::filesystem::path& file);
std::shared_ptr<const WeaveModulation> load_weave(const std::filesystem::path& file);

}  // namespace weft
