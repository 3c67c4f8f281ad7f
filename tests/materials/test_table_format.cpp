// The tabulated-BSDF table: octahedral indexing, from_function, and the OpenEXR format with its
// validation.
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>

#include "test_util.h"
#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/core/rng.h"
#include "weft/core/spectrum.h"
#include "weft/materials/bsdf_table.h"
#include "weft/materials/lambert.h"

using namespace weft;
using namespace weft::testing;
namespace fs = std::filesystem;

namespace {

// A small table with distinct, exactly representable values and full metadata.
TabulatedBsdfTable sample_table(int resolution, int channels) {
  TabulatedBsdfTable t;
  t.resolution = resolution;
  t.channels = channels;
  t.kind = "fabric";
  t.metadata = {{"spec_hash", "3f9a0c"},
                {"photons", "123456789012"},
                {"seed", "42"},
                {"program_version", "weft 0.1.0"}};
  t.values.resize(static_cast<size_t>(t.bins()) * t.bins() * channels);
  Rng rng(5);
  for (float& v : t.values) v = static_cast<float>(rng.uniform() * 3);
  t.values[7] = 0.0f;
  t.values[8] = 1e-30f;  // denormal-adjacent values survive too
  return t;
}

// Writes an EXR like write_exr does (checksum included), letting the edits damage the pixels
// (before the checksum is taken) or the header.
// 'omit' leaves attributes out (OpenEXR 3.1's Header::erase leaks the erased attribute).
void write_raw(const fs::path& path, int resolution, const std::vector<std::string>& channels,
               const std::function<void(Imf::Header&)>& edit_header,
               const std::function<void(std::vector<float>&)>& edit_values = {},
               const std::set<std::string>& omit = {}) {
  const int n = 2 * resolution * resolution;
  const size_t nc = channels.size();
  std::vector<float> values(static_cast<size_t>(n) * n * nc, 0.25f);
  if (edit_values) edit_values(values);
  TabulatedBsdfTable for_checksum;
  for_checksum.values = values;
  Imf::Header h(n, n);
  h.compression() = Imf::ZIP_COMPRESSION;
  for (const auto& c : channels) h.channels().insert(c, Imf::Channel(Imf::FLOAT));
  if (!omit.count("weft_format_version"))
    h.insert("weft_format_version", Imf::IntAttribute(TabulatedBsdfTable::kFormatVersion));
  if (!omit.count("cell_average"))
    h.insert("cell_average", Imf::StringAttribute(TabulatedBsdfTable::kCellAverage));
  if (!omit.count("parameterization"))
    h.insert("parameterization", Imf::StringAttribute(TabulatedBsdfTable::kParameterization));
  if (!omit.count("resolution")) h.insert("resolution", Imf::IntAttribute(resolution));
  if (!omit.count("bands")) h.insert("bands", Imf::StringAttribute("rgb"));
  if (!omit.count("units")) h.insert("units", Imf::StringAttribute("1/sr"));
  if (!omit.count("kind")) h.insert("kind", Imf::StringAttribute("fiber"));
  if (!omit.count("values_fnv1a64"))
    h.insert("values_fnv1a64", Imf::StringAttribute(for_checksum.checksum()));
  edit_header(h);
  Imf::FrameBuffer fb;
  for (size_t c = 0; c < nc; ++c)
    fb.insert(channels[c], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(values.data() + c),
                                      sizeof(float) * nc, sizeof(float) * nc * n));
  Imf::OutputFile out(path.c_str(), h);
  out.setFrameBuffer(fb);
  out.writePixels(n);
}

}  // namespace

TEST(TableFromFunction, LambertGivesRhoOverPiInsideTheHemisphere) {
  const LambertBsdf lambert{Rgb(0.8, 0.5, 0.2)};
  const auto t = TabulatedBsdfTable::from_function(
      8, 3,
      [&](const Vec3& wo, const Vec3& wi, std::span<double> v) {
        const Rgb f = lambert.eval(wo, wi);
        v[0] = f.r, v[1] = f.g, v[2] = f.b;
      },
      4, 1);
  const DirectionGrid g = t.grid();
  int checked = 0;
  for (int wi = 0; wi < g.bins(); ++wi)
    for (int wo = 0; wo < g.bins(); ++wo) {
      // Every cell lies wholly on one side of the horizon: all of them hold rho / pi or 0.
      const double zi = g.bin_center(wi).z, zo = g.bin_center(wo).z;
      const double expect_g = zi * zo > 0 ? 0.5 / kPi : 0.0;
      EXPECT_NEAR(t.at(wi, wo, 1), expect_g, 1e-7);
      EXPECT_NEAR(t.at(wi, wo, 0), zi * zo > 0 ? 0.8 / kPi : 0.0, 1e-7);
      ++checked;
    }
  EXPECT_EQ(checked, g.bins() * g.bins());
}

TEST(TableFromFunction, SameBitsAtAnyThreadCountAndSeedMatters) {
  auto f = [](const Vec3& wo, const Vec3& wi, std::span<double> v) {
    v[0] = std::exp(-3 * length_squared(wo - wi)), v[1] = wi.z * wi.z, v[2] = 0.1;
  };
  const auto a = TabulatedBsdfTable::from_function(4, 3, f, 9, 17, 1);
  const auto b = TabulatedBsdfTable::from_function(4, 3, f, 9, 17, 2);
  const auto c = TabulatedBsdfTable::from_function(4, 3, f, 9, 18, 2);
  EXPECT_EQ(a.values, b.values);
  EXPECT_NE(a.values, c.values);
}

TEST(TableFromFunction, ReportsProgressAndCanBeCancelled) {
  auto f = [](const Vec3&, const Vec3&, std::span<double> v) { v[0] = v[1] = v[2] = 1; };
  uint64_t last = 0, total = 0;
  int calls = 0;
  TabulatedBsdfTable::from_function(4, 3, f, 1, 0, 2, [&](const ProgressUpdate& u) {
    EXPECT_GT(u.done, last);
    last = u.done, total = u.total, ++calls;
    return true;
  });
  EXPECT_EQ(last, 32u);  // the 2 R^2 rows of wi bins
  EXPECT_EQ(total, 32u);
  EXPECT_GT(calls, 1);
  const std::string msg = error_of([&] {
    TabulatedBsdfTable::from_function(4, 3, f, 1, 0, 2,
                                      [](const ProgressUpdate&) { return false; });
  });
  EXPECT_NE(msg.find("cancelled"), std::string::npos) << msg;
}

TEST(TableFromFunction, RejectsBadInputAndBadValues) {
  auto ok = [](const Vec3&, const Vec3&, std::span<double> v) { v[0] = v[1] = v[2] = 1; };
  EXPECT_NE(error_of([&] { TabulatedBsdfTable::from_function(0, 3, ok, 1); }).find("resolution"),
            std::string::npos);
  EXPECT_NE(error_of([&] { TabulatedBsdfTable::from_function(2, 4, ok, 1); }).find("bands"),
            std::string::npos);
  EXPECT_NE(
      error_of([&] { TabulatedBsdfTable::from_function(2, 3, ok, 0); }).find("samples_per_cell"),
      std::string::npos);
  auto nan = [](const Vec3&, const Vec3&, std::span<double> v) { v[0] = std::nan(""); };
  EXPECT_NE(error_of([&] { TabulatedBsdfTable::from_function(2, 3, nan, 1); }).find("'f'"),
            std::string::npos);
}

TEST(TableExr, RoundTripIsBitExactWithMetadata) {
  const fs::path dir = fresh_test_dir();
  for (int channels : {3, kNumBands}) {
    const auto t = sample_table(channels == 3 ? 6 : 3, channels);
    const fs::path p = dir / ("t" + std::to_string(channels) + ".exr");
    t.write_exr(p);
    const auto back = TabulatedBsdfTable::read_exr(p);
    EXPECT_EQ(back.resolution, t.resolution);
    EXPECT_EQ(back.channels, t.channels);
    EXPECT_EQ(back.kind, t.kind);
    EXPECT_EQ(back.metadata, t.metadata);
    ASSERT_EQ(back.values.size(), t.values.size());
    EXPECT_EQ(std::memcmp(back.values.data(), t.values.data(), t.values.size() * sizeof(float)), 0);
  }
  // Spectral channels are named per band.
  EXPECT_EQ(sample_table(2, kNumBands).channel_names().front(), "w390");
  EXPECT_EQ(sample_table(2, kNumBands).channel_names().back(), "w710");
}

TEST(TableExr, WriteValidatesAndLeavesNoPartialFile) {
  const fs::path dir = fresh_test_dir();
  auto t = sample_table(4, 3);
  t.values[100] = -1.0f;
  const fs::path p = dir / "bad.exr";
  const std::string msg = error_of([&] { t.write_exr(p); });
  EXPECT_NE(msg.find(p.string()), std::string::npos) << msg;
  EXPECT_NE(msg.find("negative"), std::string::npos) << msg;
  EXPECT_FALSE(fs::exists(p));
  EXPECT_TRUE(fs::is_empty(dir)) << "no temporary left behind";
  t.values[100] = 1.0f;
  t.metadata["resolution"] = "9";
  EXPECT_NE(error_of([&] { t.write_exr(p); }).find("reserved"), std::string::npos);
  t.metadata.erase("resolution");
  EXPECT_NE(error_of([&] { t.write_exr(dir / "missing" / "t.exr"); }).find("directory"),
            std::string::npos);
}

TEST(TableExr, DamagedFilesNameTheFileAndTheFault) {
  const fs::path dir = fresh_test_dir();
  const std::vector<std::string> rgb = {"R", "G", "B"};
  struct Case {
    std::string name, must_mention;
    std::function<void(const fs::path&)> make;
  };
  const fs::path good = dir / "good.exr";
  sample_table(8, 3).write_exr(good);
  const auto good_size = fs::file_size(good);
  auto copy_bytes = [&](const fs::path& p, size_t keep) {
    std::ifstream in(good, std::ios::binary);
    std::vector<char> bytes(keep);
    in.read(bytes.data(), static_cast<std::streamsize>(keep));
    std::ofstream(p, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(keep));
  };
  // Otherwise good 2 x 2 RGB tables with one header attribute changed or left out.
  auto with_int = [&](const char* name, int value) {
    return [&rgb, name, value](const fs::path& p) {
      write_raw(p, 2, rgb, [&](Imf::Header& h) { h.insert(name, Imf::IntAttribute(value)); });
    };
  };
  auto with_string = [&](const char* name, const char* value) {
    return [&rgb, name, value](const fs::path& p) {
      write_raw(p, 2, rgb, [&](Imf::Header& h) { h.insert(name, Imf::StringAttribute(value)); });
    };
  };
  auto without = [&](const char* name) {
    return
        [&rgb, name](const fs::path& p) { write_raw(p, 2, rgb, [](Imf::Header&) {}, {}, {name}); };
  };
  const Case cases[] = {
      {"missing.exr", "no such", [](const fs::path&) {}},
      {"text.exr", "not an OpenEXR", [](const fs::path& p) { std::ofstream(p) << "hello"; }},
      {"truncated.exr", "truncated", [&](const fs::path& p) { copy_bytes(p, good_size * 2 / 3); }},
      {"header_only.exr", "", [&](const fs::path& p) { copy_bytes(p, 300); }},
      {"corrupt.exr", "corrupt",
       [&](const fs::path& p) {
         copy_bytes(p, good_size);
         std::fstream f(p, std::ios::binary | std::ios::in | std::ios::out);
         f.seekp(static_cast<std::streamoff>(good_size - 2000));
         const std::string junk(600, '\x5a');
         f.write(junk.data(), static_cast<std::streamsize>(junk.size()));
       }},
      {"version.exr", "weft_format_version",
       with_int("weft_format_version", TabulatedBsdfTable::kFormatVersion + 1)},
      // A lobe named by a version 4 header must be whole.
      {"lobe.exr", "surface_lobe_distribution", with_string("surface_lobe", "cook-torrance")},
      // The stored quantity must be the one every reader assumes.
      {"plain_average.exr", "cell_average", with_string("cell_average", "plain")},
      {"no_cell_average.exr", "cell_average", without("cell_average")},
      // Versions 1 and 2 used the octahedral grid: refused with a request to re-bake.
      {"v2_octahedral.exr", "re-bake", with_int("weft_format_version", 2)},
      {"nochecksum.exr", "values_fnv1a64", without("values_fnv1a64")},
      {"noversion.exr", "weft_format_version", without("weft_format_version")},
      {"param.exr", "parameterization", with_string("parameterization", "theta-phi")},
      {"units.exr", "units", with_string("units", "1/m")},
      {"kind.exr", "kind", with_string("kind", "hair")},
      {"size.exr", "dataWindow", with_int("resolution", 3)},
      {"bands.exr", "bands", with_string("bands", "xyz")},
      {"channels.exr", "channels",
       [&](const fs::path& p) {
         write_raw(p, 2, {"R", "G"}, [](Imf::Header&) {});
       }},
      {"extra_channel.exr", "channels",
       [&](const fs::path& p) {
         write_raw(p, 2, {"A", "B", "G", "R"}, [](Imf::Header&) {});
       }},
      {"nan.exr", "values[wi 1][wo 2][G]",
       [&](const fs::path& p) {
         write_raw(
             p, 2, rgb, [](Imf::Header&) {},
             [](std::vector<float>& v) { v[(1 * 8 + 2) * 3 + 1] = std::nanf(""); });
       }},
      {"negative.exr", "negative",
       [&](const fs::path& p) {
         write_raw(
             p, 2, rgb, [](Imf::Header&) {}, [](std::vector<float>& v) { v[5] = -0.5f; });
       }},
  };
  // Version 3 (no lobe) still loads.
  with_int("weft_format_version", 3)(dir / "v3.exr");
  EXPECT_FALSE(TabulatedBsdfTable::read_exr(dir / "v3.exr").surface_lobe);
  for (const auto& c : cases) {
    const fs::path p = dir / c.name;
    c.make(p);
    const std::string msg = error_of([&] { TabulatedBsdfTable::read_exr(p); });
    ASSERT_FALSE(msg.empty()) << c.name << " was accepted";
    EXPECT_NE(msg.find(p.string()), std::string::npos) << msg;
    EXPECT_NE(msg.find(c.must_mention), std::string::npos) << c.name << ": " << msg;
  }
}
