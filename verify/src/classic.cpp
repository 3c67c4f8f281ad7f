#include "weft/verify/classic.h"

#include <sstream>

#include "weft/core/error.h"

namespace weft {

std::vector<double> classic_diffuse_from_fiber_table(const TabulatedBsdfTable& fiber,
                                                     const MicrofacetDistribution& d, double ior,
                                                     uint64_t seed, int threads) {
  // The lobe at a fixed fine resolution, not the table's: at R = 3 with 4 samples per cell pair
  // the tabulated lobe loses a fifth of its albedo (0.0587 for Beckmann 0.35, n 1.557); at R = 16
  // it is within 0.0002 of its value at R = 24 with 16 samples (0.0729).
  const double lobe = classic_fiber_table(Rgb(0.0), d, ior, 16, 4, seed, threads).total_albedo()[0];
  std::vector<double> out = fiber.total_albedo();
  for (double& v : out) v -= lobe;
  return out;
}

double classic_entering_fraction(const MicrofacetDistribution& d, double ior) {
  return 1 - ClassicFiberBsdf::create(Rgb(0.0), d, ior).surface_albedo->average;
}

std::optional<MicrofacetDistribution> fiber_table_roughness(const TabulatedBsdfTable& t,
                                                            const std::string& file) {
  const auto it = t.metadata.find("roughness");
  if (it == t.metadata.end()) return std::nullopt;
  std::istringstream in(it->second);
  std::string model, word;
  double alpha = 0;
  if (!(in >> model >> word >> alpha) || word != "alpha" || !(in >> std::ws).eof() ||
      !(model == "beckmann" || model == "ggx") || !(alpha > 0 && alpha <= 1))
    throw Error(file, "roughness",
                "'" + it->second + "' is not '<beckmann|ggx> alpha A' with A in (0, 1]");
  return MicrofacetDistribution{
      model == "beckmann" ? MicrofacetModel::kBeckmann : MicrofacetModel::kGgx, alpha};
}

}  // namespace weft
