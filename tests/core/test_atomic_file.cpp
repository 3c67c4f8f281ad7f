// write_atomically: an output file appears whole or not at all, and no temporary is left behind.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "test_util.h"
#include "weft/core/atomic_file.h"

using namespace weft;
using weft::testing::error_of;
using weft::testing::fresh_test_dir;
namespace fs = std::filesystem;

namespace {

using weft::testing::slurp;

// The names in 'dir', to check that nothing but the expected files is there.
std::vector<std::string> entries(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace

TEST(AtomicFile, FailingWriterLeavesNoFileAndNoTemporary) {
  const fs::path dir = fresh_test_dir();
  const fs::path out = dir / "image.exr";
  fs::path seen_tmp;
  EXPECT_THROW(write_atomically(out,
                                [&](const fs::path& tmp) {
                                  seen_tmp = tmp;
                                  std::ofstream(tmp) << "half written";
                                  throw std::runtime_error("disk full");
                                }),
               std::runtime_error);
  // The writer was given a sibling of the output, not the output itself.
  EXPECT_EQ(seen_tmp.parent_path(), dir);
  EXPECT_NE(seen_tmp, out);
  EXPECT_TRUE(entries(dir).empty());
}

TEST(AtomicFile, FailureKeepsTheOldFile) {
  const fs::path dir = fresh_test_dir();
  const fs::path out = dir / "table.exr";
  std::ofstream(out) << "old";
  EXPECT_THROW(write_atomically(out,
                                [](const fs::path& tmp) {
                                  std::ofstream(tmp) << "new but broken";
                                  throw Error("broken");
                                }),
               Error);
  EXPECT_EQ(slurp(out), "old");
  EXPECT_EQ(entries(dir), std::vector<std::string>{"table.exr"});
}

TEST(AtomicFile, SuccessReplacesTheFileWhole) {
  const fs::path dir = fresh_test_dir();
  const fs::path out = dir / "image.png";
  std::ofstream(out) << "a much longer old content that must not survive in part";
  write_atomically(out, [&](const fs::path& tmp) {
    // Writers such as OpenImageIO choose the format by the extension: the temporary keeps it.
    EXPECT_EQ(tmp.extension(), ".png");
    EXPECT_FALSE(fs::exists(tmp));
    std::ofstream(tmp) << "new";
    // Until the writer returns, the old file is still in place.
    EXPECT_EQ(slurp(out), "a much longer old content that must not survive in part");
  });
  EXPECT_EQ(slurp(out), "new");
  EXPECT_EQ(entries(dir), std::vector<std::string>{"image.png"});
}

TEST(AtomicFile, TextVariantWritesTheBytesAsGiven) {
  const fs::path dir = fresh_test_dir();
  const fs::path out = dir / "summary.json";
  const std::string text("line 1\r\nline 2\n\0binary tail", 27);
  write_text_atomically(out, text);
  EXPECT_EQ(slurp(out), text);
  write_text_atomically(out, "short");
  EXPECT_EQ(slurp(out), "short");
  EXPECT_EQ(entries(dir), std::vector<std::string>{"summary.json"});
}

TEST(AtomicFile, MissingDirectoryIsAnErrorNamingThePath) {
  const fs::path dir = fresh_test_dir();
  const fs::path out = dir / "missing" / "out.txt";
  bool called = false;
  const std::string msg =
      error_of([&] { write_atomically(out, [&](const fs::path&) { called = true; }); });
  EXPECT_NE(msg.find(out.string()), std::string::npos) << msg;
  EXPECT_NE(msg.find("directory"), std::string::npos) << msg;
  EXPECT_FALSE(called);  // fails before any work
  EXPECT_NE(error_of([&] { write_text_atomically(out, "x"); }), "");
  EXPECT_TRUE(entries(dir).empty());
}

// Several outputs (a render's EXR, preview and mask): a failing second writer leaves neither the
// first output nor any temporary, and an old file at the first path untouched.
TEST(AtomicFile, SeveralOutputsAreWrittenAllOrNone) {
  const fs::path dir = fresh_test_dir();
  const fs::path a = dir / "image.exr", b = dir / "preview.png";
  std::ofstream(a) << "old";
  auto text = [](const std::string& s) {
    return [s](const fs::path& tmp) { std::ofstream(tmp) << s; };
  };
  EXPECT_THROW(write_all_atomically(
                   {{a, text("new")}, {b, [](const fs::path&) { throw std::runtime_error("x"); }}}),
               std::runtime_error);
  EXPECT_EQ(slurp(a), "old");
  EXPECT_EQ(entries(dir), std::vector<std::string>{"image.exr"});
  write_all_atomically({{a, text("new")}, {b, text("png")}});
  EXPECT_EQ(slurp(a), "new");
  EXPECT_EQ(slurp(b), "png");
  EXPECT_EQ((entries(dir)), (std::vector<std::string>{"image.exr", "preview.png"}));
}

// A writer killed mid-write (SIGKILL: no handler, no unwinding) leaves its temporary; the next
// write to the same destination removes it, because its process is gone. Temporaries of a live
// process and of another host (a shared file system) are left alone.
TEST(AtomicFile, TemporaryOfAKilledWriterIsRemovedByTheNextWrite) {
  const fs::path dir = fresh_test_dir();
  const fs::path out = dir / "table.exr";
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    // Only async-signal-safe work would be strictly allowed after fork in a threaded process; the
    // writer below allocates, so the child ends by SIGKILL and never returns into gtest.
    write_atomically(out, [](const fs::path& tmp) {
      std::ofstream(tmp) << "half written";
      ::raise(SIGKILL);
    });
    ::_exit(0);  // not reached
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL);
  const auto left = entries(dir);
  ASSERT_EQ(left.size(), 1u);
  EXPECT_EQ(left[0].rfind(".tmp-table-", 0), 0u) << left[0];
  EXPECT_NE(left[0].find("@" + std::to_string(child) + "-"), std::string::npos) << left[0];

  // Stand-ins for a live writer (this process) and a writer on another host.
  const std::string live = temporary_sibling(out).filename().string();  // this host and pid
  std::ofstream(dir / live) << "live";
  const std::string other_host =
      ".tmp-table-another-host.example@" + std::to_string(child) + "-0-partial.exr";
  std::ofstream(dir / other_host) << "elsewhere";

  write_text_atomically(out, "whole");
  EXPECT_EQ(slurp(out), "whole");
  std::vector<std::string> kept{live, other_host, "table.exr"};
  std::sort(kept.begin(), kept.end());
  EXPECT_EQ(entries(dir), kept);
  // Another destination's temporaries are not touched either.
  EXPECT_EQ(remove_stale_temporaries(dir / "other.exr"), 0u);
}
