// Bundled data (core/install_paths.h): the installed tree beside the executable first, then the
// source tree; a missing file is empty, with the places looked at.
#include <gtest/gtest.h>

#include <fstream>

#include "test_util.h"
#include "weft/core/install_paths.h"

using namespace weft;
using weft::testing::fresh_test_dir;

TEST(InstallPaths, TheInstallBesideTheExecutableComesBeforeTheSourceTree) {
  const auto roots = bundled_data_roots();
  ASSERT_EQ(roots.size(), 2u);
  const auto exe = std::filesystem::read_symlink("/proc/self/exe");
  EXPECT_EQ(roots[0], (exe.parent_path().parent_path() / "share" / "weft").lexically_normal());
  EXPECT_EQ(roots[1], std::filesystem::path(WEFT_SOURCE_DIR));
}

TEST(InstallPaths, FindsTheFirstRootHoldingTheFile) {
  const auto dir = fresh_test_dir();
  for (const char* root : {"a", "b"}) {
    std::filesystem::create_directories(dir / root / "measured");
    std::ofstream(dir / root / "measured" / "w.txt") << root;
  }
  std::string tried = "unchanged";
  EXPECT_EQ(find_file_under({dir / "none", dir / "b", dir / "a"}, "measured/w.txt", &tried),
            dir / "b" / "measured" / "w.txt");
  EXPECT_EQ(tried, "unchanged");  // only filled on failure
}

TEST(InstallPaths, MissingFileIsEmptyAndListsWhereItLooked) {
  const auto dir = fresh_test_dir();
  std::filesystem::create_directories(dir / "a" / "b.txt");  // a folder, not a file
  std::string tried;
  EXPECT_TRUE(find_file_under({dir / "a", dir / "c"}, "b.txt", &tried).empty());
  EXPECT_EQ(tried, (dir / "a" / "b.txt").string() + ", " + (dir / "c" / "b.txt").string());
}

TEST(InstallPaths, FindsTheBundledDataOfThisSourceTree) {
  // The test programs run from the build tree: no share/weft beside them, so the source tree.
  const auto p = find_bundled_file("verify/data/suite.json");
  EXPECT_EQ(p, std::filesystem::path(WEFT_SOURCE_DIR) / "verify/data/suite.json");
  std::string tried;
  EXPECT_TRUE(find_bundled_file("verify/data/no-such-file.json", &tried).empty());
  EXPECT_NE(tried.find("share/weft/verify/data/no-such-file.json"), std::string::npos) << tried;
}

// Last in this file: it sets the process's installed root for good.
TEST(InstallPaths, AFrontEndInAnotherProgramNamesTheInstalledRoot) {
  const auto dir = fresh_test_dir();
  std::filesystem::create_directories(dir / "share" / "weft" / "verify" / "data");
  std::ofstream(dir / "share" / "weft" / "verify" / "data" / "suite.json") << "{}";
  set_installed_data_root(dir / "lib" / ".." / "share" / "weft");
  const auto roots = bundled_data_roots();
  ASSERT_EQ(roots.size(), 2u);  // in place of the executable's, before the source tree
  EXPECT_EQ(roots[0], dir / "share" / "weft");
  EXPECT_EQ(roots[1], std::filesystem::path(WEFT_SOURCE_DIR));
  EXPECT_EQ(find_bundled_file("verify/data/suite.json"),
            dir / "share" / "weft" / "verify" / "data" / "suite.json");
}
