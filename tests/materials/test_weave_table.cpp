// The weave table (weave_table.h): validation and its OpenEXR format, bit-exact round trips and a
// named error for each malformed file.
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
#include <limits>

#include "test_util.h"
#include "weft/core/rng.h"
#include "weft/core/spectrum.h"
#include "weft/materials/bsdf_table.h"
#include "weft/materials/weave_table.h"

using namespace weft;
using namespace weft::testing;
namespace fs = std::filesystem;

namespace {

// A small weave table of distinct values with metadata; positions 3 x 2 (not square, so u and v
// cannot be swapped unnoticed).
WeaveTable sample_weave(int resolution, int channels) {
  WeaveTable t;
  t.resolution = resolution;
  t.channels = channels;
  t.positions_u = 3;
  t.positions_v = 2;
  t.repeat_u_m = 0.00072;
  t.repeat_v_m = 1.0 / 3000;  // not a short decimal: the text must round-trip
  t.metadata = {{"fabric_checksum", "0123456789abcdef"}, {"seed", "7"}};
  t.modulation.resize(static_cast<size_t>(t.positions()) * t.bins() * t.bins() * channels);
  Rng rng(11);
  for (float& v : t.modulation) v = static_cast<float>(rng.uniform() * 2);
  t.modulation[3] = 0.0f;
  return t;
}

// Writes a weave EXR the way write_exr does (checksum of the values after 'edit_values'), then
// lets 'edit_header' change or add attributes; 'omit' leaves attributes out.
void write_raw(const fs::path& path, const WeaveTable& t,
               const std::function<void(Imf::Header&)>& edit_header,
               const std::function<void(std::vector<float>&)>& edit_values = {},
               const std::set<std::string>& omit = {}) {
  std::vector<float> values = t.modulation;
  if (edit_values) edit_values(values);
  WeaveTable for_checksum;
  for_checksum.modulation = values;
  const int w = t.bins(), h = t.positions() * t.bins();
  Imf::Header hd(w, h);
  hd.compression() = Imf::ZIP_COMPRESSION;
  const std::vector<std::string> names = {"R", "G", "B"};
  for (const auto& c : names) hd.channels().insert(c, Imf::Channel(Imf::FLOAT));
  auto put = [&](const char* name, const Imf::Attribute& a) {
    if (!omit.count(name)) hd.insert(name, a);
  };
  put("weft_format_version", Imf::IntAttribute(WeaveTable::kFormatVersion));
  put("kind", Imf::StringAttribute("fabric-weave"));
  put("resolution", Imf::IntAttribute(t.resolution));
  put("positions", Imf::StringAttribute("3x2"));
  put("repeat_m", Imf::StringAttribute("0.00072 0.0003"));
  put("bands", Imf::StringAttribute("rgb"));
  put("values_fnv1a64", Imf::StringAttribute(for_checksum.checksum()));
  edit_header(hd);
  Imf::FrameBuffer fb;
  for (size_t c = 0; c < 3; ++c)
    fb.insert(names[c], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(values.data() + c),
                                   sizeof(float) * 3, sizeof(float) * 3 * w));
  Imf::OutputFile out(path.c_str(), hd);
  out.setFrameBuffer(fb);
  out.writePixels(h);
}

}  // namespace

TEST(WeaveTableExr, RoundTripIsBitExactWithMetadata) {
  const fs::path dir = fresh_test_dir();
  for (int channels : {3, kNumBands}) {
    const auto t = sample_weave(channels == 3 ? 4 : 2, channels);
    const fs::path p = dir / ("w" + std::to_string(channels) + ".exr");
    t.write_exr(p);
    const auto back = WeaveTable::read_exr(p);
    EXPECT_EQ(back.resolution, t.resolution);
    EXPECT_EQ(back.channels, t.channels);
    EXPECT_EQ(back.positions_u, 3);
    EXPECT_EQ(back.positions_v, 2);
    EXPECT_EQ(back.repeat_u_m, t.repeat_u_m);  // exactly: the text is the shortest round trip
    EXPECT_EQ(back.repeat_v_m, t.repeat_v_m);
    EXPECT_EQ(back.metadata, t.metadata);
    ASSERT_EQ(back.modulation.size(), t.modulation.size());
    EXPECT_EQ(std::memcmp(back.modulation.data(), t.modulation.data(),
                          t.modulation.size() * sizeof(float)),
              0);
  }
}

TEST(WeaveTableExr, IndexIsPositionThenWiThenWoThenChannel) {
  const auto t = sample_weave(2, 3);  // 8 bins per direction
  EXPECT_EQ(t.index(0, 0, 0, 1), 1u);
  EXPECT_EQ(t.index(0, 0, 1, 0), 3u);
  EXPECT_EQ(t.index(0, 1, 0, 0), 8u * 3);
  EXPECT_EQ(t.index(1, 0, 0, 0), 8u * 8 * 3);
  EXPECT_EQ(t.index(5, 7, 7, 2) + 1, t.modulation.size());
}

TEST(WeaveTableExr, ValidateNamesTheFieldAndWriteLeavesNoFile) {
  const fs::path dir = fresh_test_dir();
  const fs::path p = dir / "bad.exr";
  struct Case {
    std::string must_mention;
    std::function<void(WeaveTable&)> edit;
  };
  const std::vector<Case> cases = {
      {"negative", [](WeaveTable& t) { t.modulation[10] = -0.5f; }},
      {"not finite",
       [](WeaveTable& t) { t.modulation[4] = std::numeric_limits<float>::infinity(); }},
      {"modulation[pos 0][wi 0][wo 1][G]", [](WeaveTable& t) { t.modulation[4] = NAN; }},
      {"'modulation'", [](WeaveTable& t) { t.modulation.pop_back(); }},
      {"'positions'", [](WeaveTable& t) { t.positions_u = 65; }},
      {"'positions'", [](WeaveTable& t) { t.positions_v = 0; }},
      {"'repeat_m'", [](WeaveTable& t) { t.repeat_u_m = 0; }},
      {"'repeat_m'", [](WeaveTable& t) { t.repeat_v_m = NAN; }},
      {"'resolution'", [](WeaveTable& t) { t.resolution = 33; }},
      {"'bands'", [](WeaveTable& t) { t.channels = 4; }},
      {"reserved", [](WeaveTable& t) { t.metadata["repeat_m"] = "1 1"; }},
      {"reserved", [](WeaveTable& t) { t.metadata["kind"] = "fabric"; }},
  };
  for (const auto& c : cases) {
    auto t = sample_weave(2, 3);
    c.edit(t);
    const std::string msg = error_of([&] { t.write_exr(p); });
    EXPECT_NE(msg.find(p.string()), std::string::npos) << msg;
    EXPECT_NE(msg.find(c.must_mention), std::string::npos) << c.must_mention << ": " << msg;
    EXPECT_FALSE(fs::exists(p));
  }
  EXPECT_TRUE(fs::is_empty(dir)) << "no temporary left behind";
  // The size limit is checked before the values are counted (no huge allocation to fail first).
  WeaveTable huge = sample_weave(2, 3);
  huge.resolution = 32, huge.channels = kNumBands, huge.positions_u = huge.positions_v = 64;
  EXPECT_NE(error_of([&] { huge.validate("x.exr"); }).find("allowed"), std::string::npos);
}

TEST(WeaveTableExr, DamagedFilesNameTheFileAndTheFault) {
  const fs::path dir = fresh_test_dir();
  const auto t = sample_weave(2, 3);
  struct Case {
    std::string name, must_mention;
    std::function<void(const fs::path&)> make;
  };
  auto header = [&](std::function<void(Imf::Header&)> e) {
    return [&t, e](const fs::path& p) { write_raw(p, t, e); };
  };
  auto missing = [&](const char* attr) {
    return [&t, attr](const fs::path& p) { write_raw(p, t, [](Imf::Header&) {}, {}, {attr}); };
  };
  auto set_string = [&](const char* attr, const char* value) {
    return header([attr, value](Imf::Header& h) { h.insert(attr, Imf::StringAttribute(value)); });
  };
  const std::vector<Case> cases = {
      {"missing file", "no such table file", [](const fs::path&) {}},
      {"not exr", "not an OpenEXR file",
       [](const fs::path& p) { std::ofstream(p) << "hello, not an image"; }},
      {"a fabric table", "'kind'",
       [](const fs::path& p) {
         TabulatedBsdfTable f;
         f.resolution = 2, f.kind = "fabric";
         f.values.assign(8 * 8 * 3, 0.1f);
         f.write_exr(p);
       }},
      {"missing kind", "'kind'", missing("kind")},
      {"wrong kind", "'kind'", set_string("kind", "fiber")},
      {"missing version", "'weft_format_version'", missing("weft_format_version")},
      {"wrong version", "'weft_format_version'",
       header([](Imf::Header& h) { h.insert("weft_format_version", Imf::IntAttribute(2)); })},
      {"resolution out of range", "'resolution'",
       header([](Imf::Header& h) { h.insert("resolution", Imf::IntAttribute(40)); })},
      {"resolution not the image's", "'dataWindow'",
       header([](Imf::Header& h) { h.insert("resolution", Imf::IntAttribute(3)); })},
      {"positions not the image's", "'dataWindow'", set_string("positions", "2x2")},
      {"positions missing", "'positions'", missing("positions")},
      {"positions malformed", "'positions'", set_string("positions", "3 by 2")},
      {"positions too many", "'positions'", set_string("positions", "65x2")},
      {"positions zero", "'positions'", set_string("positions", "0x6")},
      {"repeat missing", "'repeat_m'", missing("repeat_m")},
      {"repeat one number", "'repeat_m'", set_string("repeat_m", "0.001")},
      {"repeat negative", "'repeat_m'", set_string("repeat_m", "0.001 -0.001")},
      {"repeat not finite", "'repeat_m'", set_string("repeat_m", "0.001 inf")},
      {"repeat trailing", "'repeat_m'", set_string("repeat_m", "0.001 0.001 3")},
      {"bands", "'bands'", set_string("bands", "xyz")},
      {"spectral bands, rgb channels", "'channels'", set_string("bands", "390:710:10")},
      {"negative value", "negative",
       [&](const fs::path& p) {
         write_raw(
             p, t, [](Imf::Header&) {}, [](std::vector<float>& v) { v[20] = -1; });
       }},
      {"non-finite value", "not finite",
       [&](const fs::path& p) {
         write_raw(
             p, t, [](Imf::Header&) {}, [](std::vector<float>& v) { v[20] = NAN; });
       }},
      {"checksum mismatch", "'values_fnv1a64'", set_string("values_fnv1a64", "0000000000000000")},
      {"checksum missing", "'values_fnv1a64'", missing("values_fnv1a64")},
  };
  for (const auto& c : cases) {
    const fs::path p = dir / (c.name + ".exr");
    c.make(p);
    const std::string msg = error_of([&] { WeaveTable::read_exr(p); });
    EXPECT_NE(msg.find(p.string()), std::string::npos) << c.name << ": " << msg;
    EXPECT_NE(msg.find(c.must_mention), std::string::npos) << c.name << ": " << msg;
  }
}

TEST(WeaveTableExr, TruncatedFileIsRefusedBeforeAllocating) {
  const fs::path dir = fresh_test_dir();
  auto t = sample_weave(4, 3);
  const fs::path p = dir / "w.exr";
  t.write_exr(p);
  const std::string bytes = slurp(p);
  for (const size_t keep : {bytes.size() / 2, bytes.size() - 9, size_t{40}}) {
    const fs::path q = dir / ("cut" + std::to_string(keep) + ".exr");
    std::ofstream(q, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(keep));
    const std::string msg = error_of([&] { WeaveTable::read_exr(q); });
    EXPECT_NE(msg.find(q.string()), std::string::npos) << msg;
  }
  // A small file whose header claims the largest weave (64x64 positions, R = 32): refused by its
  // size, not by an allocation of gigabytes.
  const fs::path big = dir / "claims_big.exr";
  WeaveTable small = sample_weave(1, 3);
  small.positions_u = small.positions_v = 1;
  small.modulation.assign(2 * 2 * 3, 1.0f);
  write_raw(big, small, [](Imf::Header& h) {
    h.insert("resolution", Imf::IntAttribute(8));
    h.insert("positions", Imf::StringAttribute("64x64"));
  });
  const std::string msg = error_of([&] { WeaveTable::read_exr(big); });
  EXPECT_NE(msg.find("'dataWindow'"), std::string::npos) << msg;
}
