// docs/ARCHITECTURE.md names only what the project has: every back-quoted file or folder path
// exists in the source tree, and every back-quoted function-like name (snake_case, or ending in
// "()") is a word of some source or CMake file. A rename that leaves the doc behind fails here.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <regex>
#include <string>
#include <vector>

#include "test_util.h"

namespace fs = std::filesystem;

// A named namespace: the unity build puts this file in one batch with others (ARCHITECTURE.md).
namespace weft::architecture_doc_test {

const fs::path kSource = WEFT_SOURCE_DIR;

// The doc's inline code spans, fenced blocks (the data-flow drawing) left out.
std::vector<std::string> code_spans(std::string text) {
  const std::string fence = "```";
  for (size_t at = text.find(fence); at != std::string::npos; at = text.find(fence, at)) {
    const size_t end = text.find(fence, at + fence.size());
    text.erase(at, end == std::string::npos ? std::string::npos : end + fence.size() - at);
  }
  std::vector<std::string> spans;
  const std::regex span("`([^`]+)`");
  for (std::sregex_iterator it(text.begin(), text.end(), span), end; it != end; ++it)
    spans.push_back((*it)[1].str());
  return spans;
}

// A repo path: a folder ("core/") or a file with a known extension, with no spaces or
// placeholders ("tools/cmd_<name>.cpp" stands for many).
bool is_path(const std::string& s) {
  static const std::regex file(R"([\w./-]+/[\w.-]+\.(h|cpp|md|py|sh|json|csv|wif))");
  static const std::regex folder(R"([\w./-]+/)");
  return std::regex_match(s, file) || std::regex_match(s, folder);
}

// The path as the doc means it: from the repo root, from docs/, or a library's public header
// named from its include folder ("core/progress.h" is core/include/weft/core/progress.h).
bool path_exists(const std::string& s) {
  const std::string library = s.substr(0, s.find('/'));
  return fs::exists(kSource / s) || fs::exists(kSource / "docs" / s) ||
         fs::exists(kSource / library / "include/weft" / s);
}

// The identifier of a function-like span: "bake_fiber_table" or "finish()"; "" for any other.
std::string function_name(const std::string& s) {
  static const std::regex call(R"(([A-Za-z_]\w*)\(\))");
  static const std::regex snake("[a-z][a-z0-9]*(_[a-z0-9]+)+");
  std::smatch m;
  if (std::regex_match(s, m, call)) return m[1].str();
  return std::regex_match(s, snake) ? s : "";
}

bool is_code_file(const fs::path& p) {
  const std::string ext = p.extension().string();
  return ext == ".h" || ext == ".cpp" || ext == ".cmake" || p.filename() == "CMakeLists.txt";
}

// The text of every C++ and CMake file of the source tree, build trees and hidden folders
// (.git) left out.
std::vector<std::string> code_texts() {
  std::vector<std::string> texts;
  for (auto it =
           fs::recursive_directory_iterator(kSource, fs::directory_options::skip_permission_denied);
       it != fs::recursive_directory_iterator(); ++it) {
    const fs::path& p = it->path();
    if (it->is_directory() &&
        (p.filename().string().starts_with(".") || fs::exists(p / "CMakeCache.txt"))) {
      it.disable_recursion_pending();
    } else if (it->is_regular_file() && is_code_file(p)) {
      texts.push_back(weft::testing::slurp(p));
    }
  }
  return texts;
}

bool is_word_char(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
}

// 'word' stands in 'text' whole, not as part of a longer identifier.
bool has_word(const std::string& text, const std::string& word) {
  for (size_t at = text.find(word); at != std::string::npos; at = text.find(word, at + 1)) {
    const size_t after = at + word.size();
    if ((at == 0 || !is_word_char(text[at - 1])) &&
        (after == text.size() || !is_word_char(text[after])))
      return true;
  }
  return false;
}

TEST(ArchitectureDoc, NamesOnlyPathsAndFunctionsTheProjectHas) {
  const std::string doc = weft::testing::slurp(kSource / "docs/ARCHITECTURE.md");
  ASSERT_FALSE(doc.empty());
  const std::vector<std::string> texts = code_texts();
  ASSERT_GT(texts.size(), 100u);
  int paths = 0, names = 0;
  for (const std::string& s : code_spans(doc)) {
    if (is_path(s)) {
      EXPECT_TRUE(path_exists(s)) << "`" << s << "` is not in the source tree";
      ++paths;
    } else if (const std::string name = function_name(s); !name.empty()) {
      const bool found = std::any_of(texts.begin(), texts.end(),
                                     [&](const std::string& t) { return has_word(t, name); });
      EXPECT_TRUE(found) << "`" << s << "` is in no .h, .cpp or CMake file";
      ++names;
    }
  }
  // The doc cites dozens of each: fewer means the spans were not found, not that all is well.
  EXPECT_GT(paths, 30);
  EXPECT_GT(names, 20);
}

// The checks themselves: a name that is nowhere and a path that is not there are caught.
TEST(ArchitectureDoc, ChecksCatchWhatIsNotThere) {
  EXPECT_EQ(code_spans("a `x_y` b\n```\n`not_this`\n```\n`core/` c"),
            (std::vector<std::string>{"x_y", "core/"}));
  EXPECT_TRUE(is_path("core/progress.h"));
  EXPECT_TRUE(is_path("fabric/"));
  EXPECT_FALSE(is_path("tools/cmd_<name>.cpp"));
  EXPECT_FALSE(is_path("scripts/fuzz.sh --seconds S"));
  EXPECT_TRUE(path_exists("core/progress.h"));
  EXPECT_TRUE(path_exists("fiber/fiber_spec.h"));
  EXPECT_TRUE(path_exists("tests/test_util.h"));
  EXPECT_TRUE(path_exists("fabric/"));
  EXPECT_FALSE(path_exists("core/no_such_header.h"));
  EXPECT_EQ(function_name("bake_fiber_table"), "bake_fiber_table");
  EXPECT_EQ(function_name("finish()"), "finish");
  EXPECT_EQ(function_name("RenderScene"), "");
  EXPECT_TRUE(has_word("x = bake_fiber_table(a);", "bake_fiber_table"));
  EXPECT_FALSE(has_word("bake_fiber_table_v2(a);", "bake_fiber_table"));
}

}  // namespace weft::architecture_doc_test
