// docs/fiber-spec.md cannot go stale: its table of fields lists exactly the keys the parser
// accepts (asked of the parser itself: an unknown key in each object of the full template makes
// parse_fiber_spec list the keys it knows there), its templates are the installed files and
// parse, and it lists every bundled preset and dye.
#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include "test_util.h"
#include "weft/core/error.h"
#include "weft/fiber/dye.h"
#include "weft/fiber/fiber_spec.h"

using namespace weft;
using weft::testing::slurp;

namespace {

const std::filesystem::path kSource = WEFT_SOURCE_DIR;

std::string doc() {
  return slurp(kSource / "docs/fiber-spec.md");
}

// The first column of the table under "## Fields": each row's key in backticks.
std::set<std::string> documented_keys() {
  std::istringstream in(doc());
  std::set<std::string> keys;
  std::string line;
  bool fields = false;
  const std::regex row(R"(^\| `([^`]+)` \|)");
  while (std::getline(in, line)) {
    if (line.rfind("## ", 0) == 0) fields = line == "## Fields";
    std::smatch m;
    if (fields && std::regex_search(line, m, row)) keys.insert(m[1]);
  }
  return keys;
}

// The keys the parser knows in the object at 'ptr' of 'spec': an unknown key put there makes its
// reader's finish() list them ("known here: a, b, c").
std::vector<std::string> known_keys(nlohmann::json spec, const nlohmann::json::json_pointer& ptr) {
  spec[ptr]["zz_not_a_key"] = 1;
  std::string what;
  try {
    parse_fiber_spec(spec.dump(), "full.json");
  } catch (const Error& e) {
    what = e.what();
  }
  std::smatch m;
  EXPECT_TRUE(std::regex_search(what, m, std::regex(R"(known here: ([^)]*)\))")))
      << ptr.to_string() << ": " << what;
  std::vector<std::string> keys;
  std::istringstream list(m.size() > 1 ? m[1].str() : "");
  for (std::string k; std::getline(list, k, ',');)
    keys.push_back(k.substr(k.find_first_not_of(' ')));
  return keys;
}

// Every key the parser accepts in any object of 'spec', as documented: "host.dyes[].dye"; the
// points form of a spectrum (an object whose one key is "points") as "SPECTRAL.points".
std::set<std::string> accepted_keys(const nlohmann::json& spec) {
  std::set<std::string> out;
  std::function<void(const nlohmann::json&, const nlohmann::json::json_pointer&, std::string)>
      walk =
          [&](const nlohmann::json& j, const nlohmann::json::json_pointer& ptr, std::string path) {
            if (j.is_object()) {
              const auto keys = known_keys(spec, ptr);
              if (keys == std::vector<std::string>{"points"}) path = "SPECTRAL";
              for (const auto& k : keys) out.insert(path.empty() ? k : path + "." + k);
              for (const auto& [k, v] : j.items())
                walk(v, ptr / k, (path.empty() ? "" : path + ".") + k);
            } else if (j.is_array()) {
              for (size_t i = 0; i < j.size(); ++i) walk(j[i], ptr / i, path + "[]");
            }
          };
  walk(spec, nlohmann::json::json_pointer(), "");
  return out;
}

// The ```json block under the heading 'heading'.
std::string json_block_under(const std::string& heading) {
  const std::string d = doc();
  const size_t h = d.find("\n" + heading + "\n");
  EXPECT_NE(h, std::string::npos) << heading;
  const size_t begin = d.find("```json\n", h);
  const size_t end = d.find("\n```", begin + 8);
  if (h == std::string::npos || begin == std::string::npos || end == std::string::npos) return "";
  return d.substr(begin + 8, end - begin - 8);
}

}  // namespace

TEST(FiberSpecDoc, TableListsExactlyTheKeysTheParserAccepts) {
  const auto full = nlohmann::json::parse(slurp(kSource / "fiber/templates/full.json"));
  const std::set<std::string> accepted = accepted_keys(full);
  // The parser's keys of the full template's objects, by hand (fiber_spec.h): a floor, so that an
  // empty harvest cannot pass.
  for (const char* k : {"name", "notes", "boundary", "host.absorption_per_mm", "host.dyes[].dye",
                        "species[].size.radius_um", "species[].size.sigma", "SPECTRAL.points"})
    EXPECT_TRUE(accepted.count(k)) << k;
  const std::set<std::string> documented = documented_keys();
  for (const auto& k : accepted) EXPECT_TRUE(documented.count(k)) << "not in the doc: " << k;
  for (const auto& k : documented) EXPECT_TRUE(accepted.count(k)) << "not a key: " << k;
}

TEST(FiberSpecDoc, TemplatesAreTheFilesAndParse) {
  for (const auto& [heading, file] : {std::pair{"### Minimal template", "minimal.json"},
                                      std::pair{"### Full template", "full.json"}}) {
    const std::string text = slurp(kSource / "fiber/templates" / file);
    EXPECT_EQ(nlohmann::json::parse(json_block_under(heading)), nlohmann::json::parse(text))
        << file;
    EXPECT_NO_THROW(parse_fiber_spec(text, file)) << file;
  }
  // The full template holds a recipe and both size forms: every branch of the parser.
  const FiberSpec full = parse_fiber_spec(slurp(kSource / "fiber/templates/full.json"), "full");
  EXPECT_EQ(full.dyes.size(), 2u);
  ASSERT_EQ(full.species.size(), 2u);
  EXPECT_NE(full.species[0].size.kind, full.species[1].size.kind);
}

TEST(FiberSpecDoc, ListsEveryPresetAndDye) {
  const std::string d = doc();
  for (const auto& name : fiber_preset_names())
    EXPECT_NE(d.find("- `" + name + "`: "), std::string::npos) << name;
  for (const auto& name : bundled_dye_names())
    EXPECT_NE(d.find("- `" + name + "`: "), std::string::npos) << name;
}
