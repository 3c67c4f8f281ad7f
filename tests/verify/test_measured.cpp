// The measured-table reader (verify/measured.h): the bundled table's values and the errors of
// bad tables.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "mutate.h"
#include "test_util.h"
#include "weft/core/atomic_file.h"
#include "weft/core/math.h"
#include "weft/verify/measured.h"

namespace fs = std::filesystem;
using weft::testing::error_of;
using weft::testing::fresh_test_dir;

namespace weft {
namespace {

TEST(VerifyMeasured, BundledTableHasNineIncidencesAndThePapersSign) {
  const MeasuredInplane m = read_measured_inplane(bundled_measured_inplane());
  ASSERT_EQ(m.curves.size(), 9u);
  const std::vector<double> want = {0, 10, 20, 30, 40, 45, 50, 60, 70};
  for (size_t i = 0; i < want.size(); ++i) {
    EXPECT_EQ(m.curves[i].theta_i_deg, want[i]);
    EXPECT_EQ(m.curves[i].view_deg.size(), 35u);  // -85..85 in 5 deg steps
  }
  // Rows of materials/data/measured/merl-red-fabric/inplane.csv: "0,0,...,0.280098,..." and
  // "30,-30,...,0.257877,..." (theta_o = -30 is the mirror side there, view +30 here).
  const auto& c0 = m.curves[0];
  const size_t v0 = std::find(c0.view_deg.begin(), c0.view_deg.end(), 0.0) - c0.view_deg.begin();
  EXPECT_DOUBLE_EQ(c0.beta[v0].r, 0.280098);
  const auto& c30 = m.curves[3];
  const size_t v30 =
      std::find(c30.view_deg.begin(), c30.view_deg.end(), 30.0) - c30.view_deg.begin();
  EXPECT_DOUBLE_EQ(c30.beta[v30].r, 0.257877);
  EXPECT_DOUBLE_EQ(c30.beta[v30].b, 0.0255022);
  // The table's two other fits, as beta = pi f_r: its row "0,-85,...", sgd_fr_R 0.0678578 and
  // abc_fr_B 0.00365227 (theta_o = -85 is view +85 here, the last of incidence 0).
  ASSERT_EQ(m.other_fits.size(), 2u);
  EXPECT_EQ(m.other_fits[0].name, "sgd");
  EXPECT_EQ(m.other_fits[1].name, "abc");
  ASSERT_EQ(m.other_fits[0].beta.size(), 9u);
  ASSERT_EQ(m.other_fits[0].beta[0].size(), 35u);
  EXPECT_EQ(c0.view_deg.back(), 85.0);
  EXPECT_DOUBLE_EQ(m.other_fits[0].beta[0].back().r, kPi * 0.0678578);
  EXPECT_DOUBLE_EQ(m.other_fits[1].beta[0].back().b, kPi * 0.00365227);
  const std::vector<MeasuredFit> fits = measured_fits(m);
  ASSERT_EQ(fits.size(), 3u);
  EXPECT_EQ(fits[0].name, "nbrdf");
  EXPECT_DOUBLE_EQ(fits[0].beta[0][v0].r, 0.280098);
}

TEST(VerifyMeasured, ColourSpaceFromItsCommentLine) {
  // The bundled MERL tables are camera RGB (materials/data/measured/README.md).
  EXPECT_EQ(read_measured_inplane(bundled_measured_inplane()).colour_space,
            MeasuredColourSpace::kCamera);
  const fs::path dir = fresh_test_dir();
  const fs::path p = dir / "space.csv";
  const std::string table =
      "theta_i_deg,theta_o_deg,nbrdf_beta_R,nbrdf_beta_G,nbrdf_beta_B\n0,0,1,1,1\n";
  // Absent: unknown. Quoted as a spreadsheet writes it, with CRLF: read.
  write_text_atomically(p, "# a table\n" + table);
  EXPECT_EQ(read_measured_inplane(p).colour_space, MeasuredColourSpace::kUnknown);
  write_text_atomically(p, "\"# a table\"\r\n\"# colour_space: srgb\"\r\n" + table);
  EXPECT_EQ(read_measured_inplane(p).colour_space, MeasuredColourSpace::kSrgb);
  // A bad value, or two lines: the file and the field.
  for (const std::string head : {"# colour_space: xyz\n", "# colour_space:\n",
                                 "# colour_space: srgb\n# colour_space: camera\n"}) {
    write_text_atomically(p, head + table);
    const std::string e = error_of([&] { read_measured_inplane(p); });
    EXPECT_NE(e.find(p.string()), std::string::npos) << e;
    EXPECT_NE(e.find("colour_space"), std::string::npos) << head << " -> " << e;
  }
  EXPECT_NE(
      error_of([] { parse_colour_space("sRGB", "", "--colour-space"); }).find("--colour-space"),
      std::string::npos);
}

TEST(VerifyMeasured, OtherFitsAreOptionalButWholeAndChecked) {
  const fs::path dir = fresh_test_dir();
  const fs::path p = dir / "fits.csv";
  // Without them: the reference only.
  write_text_atomically(
      p, "theta_i_deg,theta_o_deg,nbrdf_beta_R,nbrdf_beta_G,nbrdf_beta_B\n0,0,1,1,1\n");
  EXPECT_TRUE(read_measured_inplane(p).other_fits.empty());
  // One fit's columns, in any order among the others: f_r times pi.
  write_text_atomically(p,
                        "abc_fr_B,theta_i_deg,theta_o_deg,abc_fr_G,nbrdf_beta_R,nbrdf_beta_G,"
                        "nbrdf_beta_B,abc_fr_R\n0.5,0,0,0.25,1,1,1,2\n");
  const MeasuredInplane m = read_measured_inplane(p);
  ASSERT_EQ(m.other_fits.size(), 1u);
  EXPECT_EQ(m.other_fits[0].name, "abc");
  EXPECT_DOUBLE_EQ(m.other_fits[0].beta[0][0].r, 2 * kPi);
  EXPECT_DOUBLE_EQ(m.other_fits[0].beta[0][0].g, 0.25 * kPi);
  EXPECT_DOUBLE_EQ(m.other_fits[0].beta[0][0].b, 0.5 * kPi);
  // A fit with some of its columns, a non-number and a negative value: the file and the field.
  const std::string head = "theta_i_deg,theta_o_deg,nbrdf_beta_R,nbrdf_beta_G,nbrdf_beta_B";
  const std::pair<std::string, std::string> cases[] = {
      {head + ",sgd_fr_R,sgd_fr_B\n0,0,1,1,1,1,1\n", "sgd_fr_G"},
      {head + ",sgd_fr_R,sgd_fr_G,sgd_fr_B\n0,0,1,1,1,1,x,1\n", "line 2 sgd_fr_G"},
      {head + ",sgd_fr_R,sgd_fr_G,sgd_fr_B\n0,0,1,1,1,1,1,-1\n", "line 2 sgd_fr_B"}};
  for (const auto& [text, part] : cases) {
    write_text_atomically(p, text);
    const std::string e = error_of([&] { read_measured_inplane(p); });
    EXPECT_NE(e.find(p.string()), std::string::npos) << e;
    EXPECT_NE(e.find(part), std::string::npos) << text << " -> " << e;
  }
}

TEST(VerifyMeasured, BadTablesNameFileAndField) {
  const fs::path dir = fresh_test_dir();
  const std::string head = "theta_i_deg,theta_o_deg,nbrdf_beta_R,nbrdf_beta_G,nbrdf_beta_B\n";
  struct Case {
    std::string text, part;
  } cases[] = {
      {"theta_i_deg,theta_o_deg,nbrdf_beta_R,nbrdf_beta_B\n0,0,1,1\n", "nbrdf_beta_G"},
      {head + "0,0,1,x,1\n", "line 2 nbrdf_beta_G"},
      {head + "0,0,1,1,1\n0,0,1,1,1\n", "duplicate"},
      {head + "0,0,1,-1,1\n", "line 2 nbrdf_beta_G"},
      {head + "95,0,1,1,1\n", "theta_i_deg"},
      {head + "0,0,1,1\n", "line 2"},
      {head, "no data rows"},
  };
  for (const auto& c : cases) {
    const fs::path p = dir / "bad.csv";
    write_text_atomically(p, c.text);
    const std::string e = error_of([&] { read_measured_inplane(p); });
    EXPECT_NE(e.find(p.string()), std::string::npos) << e;
    EXPECT_NE(e.find(c.part), std::string::npos) << c.text << " -> " << e;
  }
  EXPECT_NE(error_of([&] { read_measured_inplane(dir / "missing.csv"); }).find("missing.csv"),
            std::string::npos);
}

// Hostile tables are refused with the file and the field, and the huge ones before they are held
// in memory: one past each limit of measured.h, the first row past it named.
TEST(VerifyMeasured, HugeOrDegenerateTablesAreRefused) {
  const fs::path dir = fresh_test_dir();
  const fs::path p = dir / "hostile.csv";
  const std::string head = "theta_i_deg,theta_o_deg,nbrdf_beta_R,nbrdf_beta_G,nbrdf_beta_B\n";
  const auto refused = [&](const std::string& text, const std::string& part) {
    write_text_atomically(p, text);
    const std::string e = error_of([&] { read_measured_inplane(p); });
    EXPECT_NE(e.find(p.string()), std::string::npos) << e;
    EXPECT_NE(e.find(part), std::string::npos) << part << " -> " << e;
  };
  // One incidence too many (distinct theta_i in [0, 90)), one view too many at one incidence.
  std::string incidences = head, views = head;
  for (size_t i = 0; i <= kMaxMeasuredIncidences; ++i)
    incidences += std::to_string(i * 0.25) + ",0,1,1,1\n";
  for (size_t v = 0; v <= kMaxMeasuredViews; ++v)
    views += "0," + std::to_string(-89.75 + v * 0.25) + ",1,1,1\n";
  refused(incidences, "line " + std::to_string(kMaxMeasuredIncidences + 2) + " theta_i_deg");
  refused(incidences, "incidences");
  refused(views, "line " + std::to_string(kMaxMeasuredViews + 2) + " theta_o_deg");
  // Absurd, non-finite and negative values, and a channel of zeros at every row.
  refused(head + "0,0,1,1e300,1\n", "line 2 nbrdf_beta_G");
  refused(head + "0,0,1,1e300,1\n", "absurd");
  refused(head + "0,0,inf,1,1\n", "line 2 nbrdf_beta_R");
  refused(head + "0,0,1,1,nan\n", "line 2 nbrdf_beta_B");
  refused(head + "0,0,-1e300,1,1\n", "line 2 nbrdf_beta_R");
  refused(head + "0,0,0,0,0\n10,0,0,0,0\n", "nbrdf_beta_R");
  refused(head + "0,0,1,0,1\n10,0,1,0,1\n", "field 'nbrdf_beta_G': zero at every row");
  // A file over the size limit is refused before a byte of it is read (a sparse file: instant).
  write_text_atomically(p, head + "0,0,1,1,1\n");
  fs::resize_file(p, kMaxMeasuredBytes + 1);
  const std::string e = error_of([&] { read_measured_inplane(p); });
  EXPECT_NE(e.find(p.string() + ": field 'size'"), std::string::npos) << e;
  // A single zero among positive values is a measurement (the bundled purple felt has zeros).
  write_text_atomically(p, head + "0,0,1,0,1\n10,0,1,1,1\n");
  EXPECT_EQ(read_measured_inplane(p).curves.size(), 2u);
}

// Random byte edits of the bundled table's first 40 rows (comment lines, header and numbers),
// seeded: every mutant is read or refused with a weft::Error naming the file.
TEST(VerifyMeasured, ByteMutationsAreReadOrRefusedNeverCrash) {
  const fs::path dir = fresh_test_dir();
  const std::string whole = testing::slurp(bundled_measured_inplane());
  size_t cut = 0;
  for (int line = 0; line < 43; ++line) cut = whole.find('\n', cut) + 1;
  const std::string valid = whole.substr(0, cut);
  Rng rng(20261203);
  int read = 0, refused = 0;
  const fs::path p = dir / "mutant.csv";
  for (int trial = 0; trial < 200; ++trial) {
    std::ofstream(p, std::ios::binary | std::ios::trunc) << testing::mutated(valid, rng);
    try {
      const MeasuredInplane m = read_measured_inplane(p);
      EXPECT_FALSE(m.curves.empty());
      ++read;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(p.string()), std::string::npos) << e.what();
      ++refused;
    }
  }
  EXPECT_GT(read, 0);
  EXPECT_GT(refused, 0);
}

}  // namespace
}  // namespace weft
