#include <gtest/gtest.h>

#include "../test_util.h"
#include "weft/core/colour_target.h"

using namespace weft;
using namespace weft::testing;

TEST(ColourTarget, ParsesEachForm) {
  const ColourTarget red = parse_colour_target("srgb:#ff0000", "--colour");
  EXPECT_EQ(red.kind, ColourTarget::Kind::kSrgb);
  EXPECT_NEAR(red.lab.l, 53.24, 0.05);  // test_colorimetry.cpp: sRGB red's published Lab
  EXPECT_EQ(parse_colour_target("srgb:FF0000", "--colour").lab, red.lab);
  const ColourTarget lab = parse_colour_target("lab:45,60.5,-3", "--colour");
  EXPECT_EQ(lab.kind, ColourTarget::Kind::kLab);
  EXPECT_EQ(lab.observer, Observer::kCie1931TwoDegree);
  EXPECT_EQ(lab.lab, (Lab{45, 60.5, -3}));
  EXPECT_EQ(parse_colour_target("lab10:45,60.5,-3", "--colour").observer,
            Observer::kCie1964TenDegree);
  EXPECT_NE(lab.key(), parse_colour_target("lab10:45,60.5,-3", "--colour").key());
}

TEST(ColourTarget, RefusesMalformedSpecsNamingTheField) {
  for (const char* bad : {"red", "srgb:#ff00", "srgb:#gg0000", "lab:45,60", "lab:145,0,0",
                          "lab:50,nan,0", "lab:50,0,1e9", "hsv:0,1,1", "lab:", "spectrum:"}) {
    const std::string e = error_of([&] { parse_colour_target(bad, "--colour"); });
    EXPECT_NE(e.find("--colour"), std::string::npos) << bad << ": " << e;
  }
  EXPECT_NE(error_of([] { parse_colour_target("hsv:0,1,1", "--colour"); }).find("srgb:#RRGGBB"),
            std::string::npos);
}

TEST(ColourTarget, ReadsASpectrophotometerExport) {
  const auto dir = fresh_test_dir();
  // 400-700 nm at 10 nm, as a d/8 instrument exports: a ramp from 0.1 to 0.7.
  std::string csv = "Wavelength (nm);R\n# instrument comment\n";
  for (int nm = 400; nm <= 700; nm += 10)
    csv += std::to_string(nm) + ";" + std::to_string(0.1 + 0.002 * (nm - 400)) + "\r\n";
  write_file(dir / "swatch.csv", csv);
  const ColourTarget t =
      parse_colour_target("spectrum:" + (dir / "swatch.csv").string(), "--colour");
  ASSERT_TRUE(t.reflectance);
  // A linear ramp's band averages are its values at the band centres; past the ends it is flat.
  EXPECT_NEAR((*t.reflectance)[2], 0.12, 1e-12);  // 410 nm
  EXPECT_NEAR((*t.reflectance)[16], 0.4, 1e-12);  // 550 nm
  EXPECT_NEAR((*t.reflectance)[0], 0.1, 1e-12);   // 390 nm, held
  EXPECT_NEAR((*t.reflectance)[32], 0.7, 1e-12);  // 710 nm, held
  // 400 nm's band (395-405 nm) is half held at 0.1, half on the ramp: (0.1 + 0.105) / 2.
  EXPECT_NEAR((*t.reflectance)[1], 0.1025, 1e-12);
  EXPECT_EQ(t.lab, reflectance_to_lab(*t.reflectance, Observer::kCie1964TenDegree));
}

TEST(ColourTarget, RefusesBadSpectrumFilesNamingFileAndLine) {
  const auto dir = fresh_test_dir();
  const auto bad = [&](const std::string& name, const std::string& text) {
    write_file(dir / name, text);
    return error_of([&] { read_reflectance_csv((dir / name).string(), "--colour"); });
  };
  std::string percent, narrow, back;
  for (int nm = 400; nm <= 700; nm += 10) percent += std::to_string(nm) + ",45\n";
  for (int nm = 420; nm <= 700; nm += 10) narrow += std::to_string(nm) + ",0.4\n";
  EXPECT_NE(bad("percent.csv", percent).find("a percentage?"), std::string::npos);
  EXPECT_NE(bad("narrow.csv", narrow).find("must cover 400-700 nm"), std::string::npos);
  EXPECT_NE(
      bad("back.csv", "400,0.1\n390,0.2\n700,0.3\n").find("line 2: wavelengths must increase"),
      std::string::npos);
  EXPECT_NE(bad("junk.csv", "400,0.1\nfoo,bar\n").find("line 2"), std::string::npos);
  EXPECT_NE(bad("nan.csv", "400,0.1\n500,nan\n700,0.3\n").find("line 2"), std::string::npos);
  EXPECT_NE(bad("empty.csv", "").find("must cover"), std::string::npos);
  EXPECT_NE(error_of([&] {
              read_reflectance_csv((dir / "none.csv").string(), "--colour");
            }).find("none.csv"),
            std::string::npos);
}
