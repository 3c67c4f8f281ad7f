// WIF weaving drafts: the two bundled drafts (scenes/data/wif/, from ThunderLoom and the
// handweaving.net library, see the README there) read as their files say, and malformed drafts
// are errors naming the file, section and key. Expected values are read off the draft files.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <tuple>

#include "mutate.h"
#include "test_util.h"
#include "weft/core/clock.h"
#include "weft/core/error.h"
#include "weft/core/rng.h"
#include "weft/scenes/weave.h"
#include "weft/scenes/wif.h"

using namespace weft;
namespace fs = std::filesystem;

namespace {

const fs::path kWif = fs::path(WEFT_SOURCE_DIR) / "scenes" / "data" / "wif";

// A small valid draft to break in the error tests: 4 threads each way, 2/2 twill on 4 shafts.
const std::string kSmall = R"([WIF]
Version=1.1
; a comment line
[WEAVING]
Shafts=4
Treadles=4
Rising Shed=yes
[WARP]
Threads=4
Units=Millimeters
Spacing=0.25
Thickness=0.2
[WEFT]
Threads=4
Units=Inches
Spacing=0.01
Thickness=0.008
[THREADING]
1=1
2=2
3=3
4=4
[TIEUP]
1=1,2
2=2,3
3=3,4
4=4,1
[TREADLING]
1=1
2=2
3=3
4=4
)";

std::string replace(std::string text, const std::string& from, const std::string& to) {
  const auto pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  if (pos != std::string::npos) text.replace(pos, from.size(), to);
  return text;
}

std::string wif_error(const std::string& text) {
  return weft::testing::error_of([&] { parse_wif(text, "draft.wif"); });
}

}  // namespace

TEST(Wif, TwoByTwoDraftIsPlainWeave) {
  const WifDraft d = read_wif(kWif / "54235-plain.wif");
  EXPECT_EQ(d.shafts, 2);
  EXPECT_EQ(d.treadles, 2);
  EXPECT_TRUE(d.rising_shed);
  ASSERT_EQ(d.warp.size(), 2u);
  ASSERT_EQ(d.weft.size(), 2u);
  // Spacing=0.0185, Thickness=0.0213, Units=Centimeters.
  EXPECT_NEAR(d.warp[0].spacing_mm, 0.185, 1e-12);
  EXPECT_NEAR(d.weft[1].thickness_mm, 0.213, 1e-12);
  // [COLOR TABLE] 1=0,102,0 (warp), 2=255,255,255 (weft) in Range 0..255.
  EXPECT_NEAR(d.warp[0].rgb[1], 102.0 / 255, 1e-12);
  EXPECT_NEAR(d.weft[0].rgb[0], 1.0, 1e-12);
  const Interlacing m = d.interlacing();
  // Pick 1 presses treadle 1, which lifts shaft 2 (warp 2); pick 2 lifts shaft 1 (warp 1).
  EXPECT_FALSE(m.over(0, 0));
  EXPECT_TRUE(m.over(1, 0));
  EXPECT_TRUE(m.over(0, 1));
  EXPECT_FALSE(m.over(1, 1));
  // That is the plain weave's checkerboard (shifted by one thread).
  const Interlacing plain = plain_weave();
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) EXPECT_EQ(m.over(i, j), plain.over((i + 1) % 2, j));
}

TEST(Wif, ThreadColoursAreGivenOrNot) {
  // The project's red/white twill (scenes/data/wif/red-white-twill.wif): [COLOR TABLE] 1=200,30,30
  // for every warp, 2=255,255,255 for every weft.
  const WifDraft d = read_wif(kWif / "red-white-twill.wif");
  EXPECT_TRUE(d.colours_given);
  ASSERT_EQ(d.warp.size(), 4u);
  for (const WifThread& t : d.warp) EXPECT_NEAR(t.rgb[0], 200.0 / 255, 1e-12);
  for (const WifThread& t : d.weft) EXPECT_EQ(t.rgb[1], 1.0);
  // kSmall states no colour: every thread is the default grey, and the draft says so.
  EXPECT_FALSE(parse_wif(kSmall, "small.wif").colours_given);
  EXPECT_TRUE(
      parse_wif(replace(kSmall, "Thickness=0.2\n", "Thickness=0.2\nColor=10,20,30\n"), "small.wif")
          .colours_given);
}

TEST(Wif, Draft8452DimensionsAndInterlacing) {
  const WifDraft d = read_wif(kWif / "8452.wif");
  EXPECT_EQ(d.shafts, 28);
  EXPECT_EQ(d.treadles, 47);
  EXPECT_EQ(d.warp.size(), 84u);
  EXPECT_EQ(d.weft.size(), 100u);
  EXPECT_EQ(d.weft_source, "TREADLING");
  const Interlacing m = d.interlacing();
  EXPECT_EQ(m.warps, 84);
  EXPECT_EQ(m.wefts, 100);
  // Warp 29 is on shaft 1 ([THREADING] 29=1); pick 1 presses treadle 1, tied to shafts
  // 1,2,3,4,5,9,11,12,24,28: warp 29 is over pick 1, warp 6 (shaft 6) under.
  EXPECT_TRUE(m.over(28, 0));
  EXPECT_FALSE(m.over(5, 0));
  // Pick 46 presses treadle 4 (shafts 1,8,9,10,14,15,16,17,18,19,26).
  ASSERT_EQ(d.weft[45].shafts, (std::vector<int>{1, 8, 9, 10, 14, 15, 16, 17, 18, 19, 26}));
  for (int i = 0; i < 84; ++i) {
    const int shaft = d.warp[i].shafts.at(0);
    const auto& lifted = d.weft[45].shafts;
    EXPECT_EQ(m.over(i, 45), std::find(lifted.begin(), lifted.end(), shaft) != lifted.end());
  }
  // Threading 1..28 three times: warps i and i + 28 are on the same shaft.
  for (int i = 0; i < 56; ++i) EXPECT_EQ(d.warp[i].shafts, d.warp[i + 28].shafts);
}

TEST(Wif, SinkingShedInvertsAndLiftplanReplacesTreadling) {
  const Interlacing rising = parse_wif(kSmall, "a.wif").interlacing();
  const Interlacing sinking =
      parse_wif(replace(kSmall, "Rising Shed=yes", "Rising Shed=no"), "b.wif").interlacing();
  for (size_t k = 0; k < rising.warp_over.size(); ++k)
    EXPECT_NE(rising.warp_over[k], sinking.warp_over[k]);
  // The same cloth as a liftplan, with lower-case names and extra blanks.
  const std::string lift =
      replace(replace(kSmall, "[TIEUP]\n1=1,2\n2=2,3\n3=3,4\n4=4,1\n", ""),
              "[TREADLING]\n1=1\n2=2\n3=3\n4=4\n", "[liftplan]\n1 = 1, 2\n2=2,3\n3=3,4\n4=4,1\n");
  const WifDraft l = parse_wif(replace(lift, "[WARP]", "[  warp ]"), "c.wif");
  EXPECT_EQ(l.weft_source, "LIFTPLAN");
  EXPECT_EQ(l.interlacing().warp_over, rising.warp_over);
  // 2/2 twill: every warp over two picks in four.
  for (int i = 0; i < 4; ++i) {
    int over = 0;
    for (int j = 0; j < 4; ++j) over += rising.over(i, j);
    EXPECT_EQ(over, 2);
  }
  // Units: Inches for the weft.
  EXPECT_NEAR(parse_wif(kSmall, "a.wif").weft[0].spacing_mm, 0.254, 1e-12);
}

TEST(Wif, MalformedDraftsAreErrorsNamingFileSectionAndKey) {
  struct Case {
    std::string from, to, expect;
  };
  const std::vector<Case> cases = {
      {"[WEAVING]\nShafts=4\n", "", "[WEAVING]"},      // missing section
      {"[THREADING]", "[THREADINGS]", "[THREADING]"},  // missing section
      {"[TIEUP]", "[TIE]", "[TIEUP]"},                 // treadling without tie-up
      {"[TREADLING]", "[TREADLINGS]", "[TREADLING]"},  // neither treadling nor liftplan
      {"3=3\n4=4\n[TIEUP]", "3=5\n4=4\n[TIEUP]", "[THREADING] 3"},    // shaft out of range
      {"4=4,1\n", "4=4,9\n", "[TIEUP] 4"},                            // tie-up shaft out of range
      {"[TREADLING]\n1=1\n", "[TREADLING]\n1=7\n", "[TREADLING] 1"},  // treadle out of range
      {"Threads=4\nUnits=Millimeters", "Threads=four\nUnits=Millimeters", "[WARP] THREADS"},
      {"Spacing=0.25", "Spacing=-0.25", "[WARP] SPACING"},
      {"Spacing=0.25", "Spacing=0.2.5", "[WARP] SPACING"},
      {"Units=Millimeters", "Units=Furlongs", "[WARP] UNITS"},
      {"[THREADING]\n1=1\n2=2\n", "[THREADING]\n1=1\n1=2\n", "[THREADING] 1"},  // duplicate
      {"[THREADING]\n1=1\n2=2\n", "[THREADING]\n1=1\n", "[THREADING] 2"},       // missing index
      {"[THREADING]\n1=1\n", "[THREADING]\n0=1\n", "[THREADING] 0"},            // bad index
      {"Rising Shed=yes", "Rising Shed=perhaps", "[WEAVING] RISING SHED"},
      {"Threads=4\nUnits=Millimeters", "Threads=1000000\nUnits=Millimeters", "[WARP] THREADS"},
      {"[WEFT]\nThreads=4", "[WEFT]\nThreads=20000", "[WARP] THREADS"},  // 4 x 20000 is fine...
      {"Shafts=4", "Shafts=100000", "[WEAVING] SHAFTS"},
      {"[WIF]", "[WIF", "line 1"},
      {"Version=1.1", "Version 1.1", "line 2"},
      {"[WEAVING]", "[WARP]", "section appears twice"},
  };
  for (const Case& c : cases) {
    const std::string text = replace(kSmall, c.from, c.to);
    const std::string e = wif_error(text);
    if (c.to == "[WEFT]\nThreads=20000") {
      // ...a valid size (the draft then lacks indices 5.., an error of its own).
      EXPECT_NE(e.find("[TREADLING] 5"), std::string::npos) << e;
      continue;
    }
    EXPECT_NE(e.find("draft.wif"), std::string::npos) << c.to << ": " << e;
    EXPECT_NE(e.find(c.expect), std::string::npos) << c.to << ": " << e;
  }
  // A warp x picks matrix beyond 2e7 crossings is refused before anything is sized by it.
  const std::string huge =
      replace(replace(kSmall, "Threads=4\nUnits=Millimeters", "Threads=20000\nUnits=Millimeters"),
              "[WEFT]\nThreads=4", "[WEFT]\nThreads=20000");
  const std::string e = wif_error(huge);
  EXPECT_NE(e.find("exceeds the limit"), std::string::npos) << e;
  // Files: unreadable and missing.
  EXPECT_THROW(read_wif(kWif / "no-such.wif"), Error);
}

TEST(Wif, FloatingThreadsAreReported) {
  // Warp 4 on shaft 4, which no treadle lifts: it never interlaces (always under).
  const std::string text =
      replace(replace(kSmall, "3=3,4\n4=4,1\n", "3=3\n4=1\n"), "2=2,3\n", "2=2,3\n");
  const WifDraft d = parse_wif(text, "f.wif");
  EXPECT_EQ(d.interlacing().floating_warps(), std::vector<int>{3});
  // The sample builds and says so.
  const fs::path dir = fs::temp_directory_path() / "weft_test_wif_floating";
  fs::create_directories(dir);
  std::ofstream(dir / "f.wif") << text;
  WeaveOptions o;
  o.wif = (dir / "f.wif").string();
  const WovenSample s = make_woven_sample(o);
  EXPECT_EQ(s.summary.floating_warps, std::vector<int>{3});
  EXPECT_TRUE(s.summary.floating_wefts.empty());
  fs::remove_all(dir);
}

// A mutated draft parses and interlaces (one value per warp and weft crossing), or is refused
// with a weft::Error naming its file; counted in 'parsed' or 'refused'.
static void parse_mutant(const std::string& text, int& parsed, int& refused) {
  try {
    const WifDraft d = parse_wif(text, "mutant.wif");
    EXPECT_EQ(d.interlacing().warp_over.size(), d.warp.size() * d.weft.size());
    ++parsed;
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("mutant.wif"), std::string::npos) << e.what();
    ++refused;
  }
}

TEST(Wif, MutatedDraftsAreErrorsOrDraftsNeverCrashes) {
  // Deterministic mutations of a valid draft (characters replaced, lines dropped or repeated):
  // each parses or throws weft::Error; anything else (another exception, a crash) fails.
  const std::string alphabet = "0123456789=,;[]-. abcxyzTHREADSShaftsUnits\n";
  Rng rng(7);
  int parsed = 0, refused = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    std::string text = kSmall;
    const int edits = 1 + static_cast<int>(rng.uniform() * 4);
    for (int e = 0; e < edits; ++e) {
      const size_t pos = static_cast<size_t>(rng.uniform() * text.size());
      const double kind = rng.uniform();
      if (kind < 0.6) {
        text[pos] = alphabet[static_cast<size_t>(rng.uniform() * alphabet.size())];
      } else {
        const size_t a = text.rfind('\n', pos), b = text.find('\n', pos);
        const size_t from = a == std::string::npos ? 0 : a + 1;
        const size_t to = b == std::string::npos ? text.size() : b + 1;
        const std::string line = text.substr(from, to - from);
        if (kind < 0.8)
          text.erase(from, to - from);
        else
          text.insert(from, line);
      }
    }
    parse_mutant(text, parsed, refused);
  }
  EXPECT_GT(parsed, 0);
  EXPECT_GT(refused, 0);
}

// A section of many keys is scanned for duplicates in linear time: 65 536 distinct keys (the
// per-section limit, kWifMaxSectionKeys) took minutes with a pairwise scan; one more key is refused
// with the section and key named, and so is a duplicate at the end of a long section.
TEST(Wif, ManyKeysAreLinearAndBounded) {
  std::string keys;  // K2 .. K65536; K1 is added below, as is one key too many
  for (size_t k = 2; k <= kWifMaxSectionKeys; ++k) keys += "K" + std::to_string(k) + "=1\n";
  const std::string full = kSmall + "[PRIVATE]\nK1=1\n" + keys;
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_EQ(parse_wif(full, "many.wif").warp.size(), 4u);
  EXPECT_LT(seconds_since(t0), 2.0);
  const std::string e = wif_error(kSmall + "[PRIVATE]\nK0=1\nK1=1\n" + keys);
  EXPECT_NE(e.find("[PRIVATE] K" + std::to_string(kWifMaxSectionKeys) + "'"), std::string::npos)
      << e;
  EXPECT_NE(e.find("keys in the section"), std::string::npos) << e;
  const std::string twice = wif_error(kSmall + "[PRIVATE]\nK65536=2\n" + keys);
  EXPECT_NE(twice.find("[PRIVATE] K65536': key appears twice"), std::string::npos) << twice;
  // Sections are bounded too (each is a map entry).
  std::string sections;
  for (size_t k = 0; k <= kWifMaxSections; ++k) sections += "[S" + std::to_string(k) + "]\n";
  EXPECT_NE(wif_error(sections + kSmall).find("more than 1024 sections"), std::string::npos);
}

// A NUL byte (a binary file renamed .wif), a thread thinner than a fiber and a draft where no
// thread interlaces are refused, naming the file and the field.
TEST(Wif, BinaryThinAndUninterlacedDraftsAreRefused) {
  std::string nul = kSmall;
  nul[kSmall.find("Shafts")] = '\0';
  EXPECT_NE(wif_error(nul).find("draft.wif: field 'line 5': a NUL byte"), std::string::npos)
      << wif_error(nul);
  // 1e-9 cm = 1e-5 um; the per-thread override is checked the same way.
  using Case = std::tuple<std::string, std::string, std::string>;
  for (const auto& [from, to, field] :
       {Case{"Spacing=0.25", "Spacing=1e-9", "[WARP] SPACING"},
        Case{"Units=Inches\nSpacing=0.01", "Units=Centimeters\nSpacing=1e-9", "[WEFT] SPACING"},
        Case{"Thickness=0.008", "Thickness=0.00001", "[WEFT] THICKNESS"},
        Case{"[THREADING]", "[WEFT SPACING]\n2=0.00000001\n[THREADING]", "[WEFT SPACING] 2"}}) {
    const std::string e = wif_error(replace(kSmall, from, to));
    EXPECT_NE(e.find("draft.wif: field '" + field + "'"), std::string::npos) << to << ": " << e;
    EXPECT_NE(e.find("thinner than one fiber"), std::string::npos) << to << ": " << e;
  }
  // 1 um (kWifMinThreadMm) is still a thread.
  EXPECT_NO_THROW(parse_wif(replace(kSmall, "Spacing=0.25", "Spacing=0.001"), "a.wif"));
  // A tie-up that lifts nothing (every warp under every pick), one that lifts every shaft on
  // every pick (every warp over), and a lift plan that lifts nothing.
  const std::string tie = "1=1,2\n2=2,3\n3=3,4\n4=4,1\n";
  const std::string none = replace(kSmall, tie, "1=\n2=\n3=\n4=\n");
  const std::string all = replace(kSmall, tie, "1=1,2,3,4\n2=1,2,3,4\n3=1,2,3,4\n4=1,2,3,4\n");
  const std::string lift_none =
      kSmall.substr(0, kSmall.find("[TIEUP]")) + "[LIFTPLAN]\n1=\n2=\n3=\n4=\n";
  for (const auto& [text, field, side] :
       {Case{none, "[TIEUP]", "under"}, Case{all, "[TIEUP]", "over"},
        Case{lift_none, "[LIFTPLAN]", "under"}}) {
    const std::string e =
        weft::testing::error_of([&] { parse_wif(text, "draft.wif").interlacing(); });
    EXPECT_NE(e.find("draft.wif: field '" + field + "': no thread interlaces"), std::string::npos)
        << e;
    EXPECT_NE(e.find("every warp lies " + side), std::string::npos) << e;
  }
}

// Random byte edits (any byte, NUL and non-ASCII included) of the small draft and of the bundled
// 8452.wif, seeded: every mutant parses and interlaces, or is refused with a weft::Error naming it.
TEST(Wif, ByteMutationsAreErrorsOrDraftsNeverCrashes) {
  Rng rng(20261203);
  int parsed = 0, refused = 0;
  for (const std::string& valid : {kSmall, weft::testing::slurp(kWif / "8452.wif")})
    for (int trial = 0; trial < 1000; ++trial) {
      const std::string text = weft::testing::mutated(valid, rng);
      parse_mutant(text, parsed, refused);
    }
  EXPECT_GT(parsed, 0);
  EXPECT_GT(refused, 0);
}
