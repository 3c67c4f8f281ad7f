#include "weft/fiber/bake_cache.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <system_error>

#include "weft/core/error.h"
#include "weft/core/hash.h"
#include "weft/core/params.h"

namespace weft {

std::filesystem::path fiber_table_cache_file(const std::filesystem::path& dir,
                                             const FiberSpec& spec,
                                             const FiberTableBakeOptions& o) {
  const std::string key =
      canonical_json(spec) + "|R" + std::to_string(o.resolution) + "|N" +
      std::to_string(o.photons_per_band) + "|S" + std::to_string(o.seed) + "|P" +
      std::to_string(o.passes) + (o.spectral ? "|spectral" : "|rgb") +
      // Format 4 only added the optional surface lobe, which has its own part of the key below:
      // entries keep the names format 3 gave them.
      "|v3" +
      // Only when not the former defaults (plain, unfolded, one surface sample, random entries),
      // so entries baked with them keep their names and are never read for other options.
      (o.weight_mode == WeightMode::absorption_weight ? "|absorption_weight" : "") +
      (o.route == FiberBakeRoute::kBssrdf ? "|bssrdf" : "") +
      // "|walk_energy": next-event tables scaled to the walk's exits, never read for the
      // unscaled ones baked before.
      (o.estimator != FiberExitEstimator::kPlain
           ? std::string("|") + fiber_exit_estimator_name(o.estimator) + "|walk_energy"
           : "") +
      (o.mirror_fold ? "|mirror_fold" : "") +
      (o.surface_lobe == FiberSurfaceLobe::kAnalytic ? "|surface_lobe_analytic" : "") +
      (o.surface_samples != 1 ? "|surface_samples" + std::to_string(o.surface_samples) : "") +
      (o.entry != FiberEntrySampling::kRandom
           ? std::string("|entry_") + fiber_entry_sampling_name(o.entry)
           : "") +
      (o.max_events_per_photon != FiberTableBakeOptions{}.max_events_per_photon
           ? "|E" + std::to_string(o.max_events_per_photon)
           : "");
  return dir / ("fiber-" + fiber_spec_hash_hex(spec) + "-" + hex64(fnv1a64(key)) + ".exr");
}

std::string volume_albedo_metadata(const FiberTableBakeResult& r) {
  Spectrum s{};
  for (const auto& b : r.bands)
    if (b.band >= 0 && b.band < kNumBands) s[b.band] = b.walk_exit_fraction() - b.surface_fraction;
  std::string out;
  for (double v : s) out += (out.empty() ? "" : ",") + exact_number(v);
  return out;
}

Spectrum volume_albedo_of(const TabulatedBsdfTable& table, const std::string& file) {
  const auto it = table.metadata.find("volume_albedo");
  if (it == table.metadata.end())
    throw Error(file, "volume_albedo",
                "missing (a cache entry written before it was recorded: remove the file)");
  Spectrum s{};
  std::stringstream in(it->second);
  std::string item;
  size_t n = 0;
  while (std::getline(in, item, ',')) {
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (n >= s.size() || item.empty() || *end != '\0' || !std::isfinite(v))
      throw Error(file, "volume_albedo", "is not " + std::to_string(s.size()) + " numbers");
    s[n++] = v;
  }
  if (n != s.size())
    throw Error(file, "volume_albedo", "is not " + std::to_string(s.size()) + " numbers");
  return s;
}

namespace {

// An entry is usable when it reads back whole (the table format checks sizes and a checksum).
bool usable(const std::filesystem::path& file) {
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) return false;
  try {
    TabulatedBsdfTable::read_exr(file);
    return true;
  } catch (const Error&) {
    return false;
  }
}

// An exclusive lock on 'path' (created if missing), released when the holder closes it or dies:
// processes that need the same entry wait here while one of them bakes it.
class FileLock {
 public:
  explicit FileLock(const std::filesystem::path& path) {
    fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0) throw Error(path.string(), "", "cannot open the bake-cache lock");
    while (::flock(fd_, LOCK_EX) != 0) {
      if (errno != EINTR) {
        ::close(fd_);
        throw Error(path.string(), "", "cannot lock the bake cache");
      }
    }
  }
  ~FileLock() { ::close(fd_); }
  FileLock(const FileLock&) = delete;
  FileLock& operator=(const FileLock&) = delete;

 private:
  int fd_ = -1;
};

}  // namespace

std::filesystem::path cached_fiber_table(const std::filesystem::path& dir, const FiberSpec& spec,
                                         const FiberTableBakeOptions& options,
                                         const ProgressCallback& progress, bool* baked,
                                         const std::function<void()>& before_bake) {
  if (baked) *baked = false;
  const std::filesystem::path file = fiber_table_cache_file(dir, spec, options);
  if (usable(file)) return file;
  if (before_bake) before_bake();
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw Error(dir.string(), "", "cannot create the bake cache folder: " + ec.message());
  const FileLock lock(std::filesystem::path(file).concat(".lock"));
  // Another process may have baked it while this one waited; a damaged entry is baked again.
  if (usable(file)) return file;
  FiberTableBakeResult r = bake_fiber_table(spec, options, progress);
  if (r.cancelled) throw Error(file.string(), "", "bake interrupted; nothing was cached");
  r.table.metadata["cache_key"] = file.stem().string();
  r.table.metadata["volume_albedo"] = volume_albedo_metadata(r);
  r.table.write_exr(file);
  if (baked) *baked = true;
  return file;
}

FiberTableResolver fiber_table_resolver(std::filesystem::path cache_dir, FiberBakeCheck check) {
  return [cache_dir, check](ParamReader& p, const MaterialContext& ctx) {
    const std::string name = p.string("spec");
    std::filesystem::path spec_path = name;
    std::error_code ec;
    if (spec_path.is_relative() && std::filesystem::exists(ctx.base_dir / spec_path, ec))
      spec_path = ctx.base_dir / spec_path;
    FiberSpec spec;
    try {
      spec = load_fiber_spec(std::filesystem::exists(spec_path, ec) ? spec_path.string() : name);
    } catch (const Error& e) {
      throw Error(p.file(), p.field("spec"), e.what());
    }
    const FiberTableBakeOptions defaults = fiber_bake_defaults(spec);
    FiberTableBakeOptions o = defaults;
    o.spectral = false;  // the renderer is RGB
    o.resolution = static_cast<int>(
        p.integer("resolution", defaults.resolution, 2, TabulatedBsdfTable::kMaxResolution));
    o.photons_per_band = p.count("photons", defaults.photons_per_band, 1, kMaxPhotonsPerBand);
    o.seed = p.count("seed", defaults.seed, 0, uint64_t{1} << 53);
    const std::filesystem::path dir = cache_dir.empty() ? ctx.base_dir / ".weft-cache" : cache_dir;
    bool refused = false;  // the check names its own fields
    const auto before_bake = [&] {
      if (!check) return;
      refused = true;
      check(o, {p.file(), p.field("photons"), p.field("resolution")});
      refused = false;
    };
    try {
      return cached_fiber_table(dir, spec, o, ctx.progress, nullptr, before_bake);
    } catch (const Error& e) {
      if (refused) throw;
      throw Error(p.file(), p.field("spec"), e.what());
    }
  };
}

void check_fiber_bake(const RunLimits& limits, const FiberTableBakeOptions& o, uint64_t bands,
                      const FiberBakeSource& source) {
  check_memory(limits, fiber_table_bake_bytes(o), source.file, source.resolution_field,
               "a bake at resolution " + std::to_string(o.resolution));
  const double per_photon = fiber_bake_min_seconds_per_photon(o);
  char rate[64];
  std::snprintf(rate, sizeof rate, "%.2g us per photon per core at least", per_photon * 1e6);
  check_long_work(limits, static_cast<double>(o.photons_per_band) * static_cast<double>(bands),
                  per_photon, o.threads, source.file, source.photons_field,
                  std::to_string(o.photons_per_band) + " photons per band", rate);
}

FiberTableResolver checked_fiber_table_resolver(const RunLimits& limits) {
  return fiber_table_resolver({},
                              [limits](const FiberTableBakeOptions& o, const FiberBakeSource& s) {
                                check_fiber_bake(limits, o, kNumBands, s);
                              });
}

}  // namespace weft
