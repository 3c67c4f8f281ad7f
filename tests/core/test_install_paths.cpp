// find_installed_file (core/install_paths.h): the source tree first, then nothing, with the places
// looked at.
#include <gtest/gtest.h>

#include <fstream>

#include "test_util.h"
#include "weft/core/install_paths.h"

using namespace weft;
using weft::testing::fresh_test_dir;

TEST(InstallPaths, FindsAFileInTheSourceTree) {
  const auto dir = fresh_test_dir();
  std::filesystem::create_directories(dir / "measured" / "a");
  std::ofstream(dir / "measured" / "a" / "w.txt") << "x";
  std::string tried = "unchanged";
  const auto p = find_installed_file(dir.string(), "materials", "measured/a/w.txt", &tried);
  EXPECT_EQ(p, dir / "measured" / "a" / "w.txt");
  EXPECT_EQ(tried, "unchanged");  // only filled on failure
}

TEST(InstallPaths, MissingFileIsEmptyAndListsWhereItLooked) {
  const auto dir = fresh_test_dir();
  std::filesystem::create_directories(dir / "b.txt");  // a folder, not a file
  std::string tried;
  EXPECT_TRUE(find_installed_file(dir.string(), "tools", "b.txt", &tried).empty());
  EXPECT_NE(tried.find((dir / "b.txt").string()), std::string::npos) << tried;
  EXPECT_NE(tried.find("share/weft/tools/b.txt"), std::string::npos) << tried;
  // No source tree: only the installed place is looked at.
  EXPECT_TRUE(find_installed_file("", "tools", "b.txt", &tried).empty());
  EXPECT_EQ(tried.find(dir.string()), std::string::npos) << tried;
}
