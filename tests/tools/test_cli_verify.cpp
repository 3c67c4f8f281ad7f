// weft verify as a user meets it: a draft run writes the whole report folder; a bad measured
// table is refused naming the file and the column, exit code 2, nothing written.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "test_util.h"

namespace fs = std::filesystem;
using weft::testing::fresh_test_dir;

namespace {

struct VerifyRun {
  int exit_code = -1;
  std::string out, err;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

VerifyRun run_weft(const std::string& args, const fs::path& dir) {
  // A python3 that fails, first on PATH: the plots must not depend on which python3 that finds.
  const fs::path bin = dir / "fakebin";
  fs::create_directories(bin);
  std::ofstream(bin / "python3") << "#!/bin/sh\nexit 1\n";
  fs::permissions(bin / "python3", fs::perms::owner_all);
  const std::string cmd = "PATH='" + bin.string() + "':$PATH '" + std::string(WEFT_EXE) + "' " +
                          args + " >'" + (dir / "stdout").string() + "' 2>'" +
                          (dir / "stderr").string() + "'";
  const int status = std::system(cmd.c_str());
  VerifyRun r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(dir / "stdout");
  r.err = slurp(dir / "stderr");
  return r;
}

}  // namespace

TEST(CliVerify, BadMeasuredTableNamesFileAndColumnAndWritesNothing) {
  const fs::path dir = fresh_test_dir();
  const fs::path csv = dir / "bad.csv";
  std::ofstream(csv) << "theta_i_deg,theta_o_deg,nbrdf_beta_R,nbrdf_beta_G\n0,0,1,1\n";
  const fs::path out = dir / "report";
  const VerifyRun r = run_weft(
      "verify --quiet --quality draft --measured '" + csv.string() + "' -o '" + out.string() + "'",
      dir);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find(csv.string()), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("nbrdf_beta_B"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  // A value that is not a number: the line and the column.
  std::ofstream(csv) << "theta_i_deg,theta_o_deg,nbrdf_beta_R,nbrdf_beta_G,nbrdf_beta_B\n"
                        "0,0,1,1,1\n0,5,1,oops,1\n";
  const VerifyRun r2 =
      run_weft("verify --quiet --measured '" + csv.string() + "' -o '" + out.string() + "'", dir);
  EXPECT_EQ(r2.exit_code, 2);
  EXPECT_NE(r2.err.find("line 3 nbrdf_beta_G"), std::string::npos) << r2.err;
  EXPECT_FALSE(fs::exists(out));
  // A baked table cannot give the classic model its colour.
  const VerifyRun r3 = run_weft("verify --quiet --fiber x.exr -o '" + out.string() + "'", dir);
  EXPECT_EQ(r3.exit_code, 2);
  EXPECT_NE(r3.err.find("--fiber"), std::string::npos) << r3.err;
}

TEST(CliVerify, DraftWritesTheWholeReport) {
  const fs::path dir = fresh_test_dir();
  const fs::path out = dir / "report";
  const VerifyRun r =
      run_weft("verify --quiet --quality draft --threads 2 -o '" + out.string() + "'", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* f : {"inplane.csv", "metrics.json", "index.html", "inplane-normalized.png",
                        "inplane-normalized.svg", "inplane-absolute.png", "inplane-absolute.svg"})
    EXPECT_TRUE(fs::exists(out / f)) << f;
  const auto j = nlohmann::json::parse(slurp(out / "metrics.json"));
  for (const char* k : {"computed_rms_log", "classic_rms_log", "computed_rms_log_absolute",
                        "classic_rms_log_absolute"})
    EXPECT_TRUE(j.at(k).is_number()) << k;
  EXPECT_EQ(j.at("settings").at("quality"), "draft");
  // The bundled measurement's nine incidences, each scored.
  EXPECT_EQ(j.at("models").at("classic").at("per_incidence").size(), 9u);
  const std::string html = slurp(out / "index.html");
  EXPECT_NE(html.find("data:image/png;base64,"), std::string::npos);
  EXPECT_NE(html.find("real fabric (paper, Table 1)"), std::string::npos);
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_EQ(e.path().filename().string().rfind(".tmp-", 0), std::string::npos) << e.path();
  // A second run into a folder that holds something else is refused, and the folder kept.
  const fs::path other = dir / "other";
  fs::create_directories(other);
  std::ofstream(other / "notes.txt") << "mine";
  const VerifyRun r2 = run_weft("verify --quiet --quality draft -o '" + other.string() + "'", dir);
  EXPECT_EQ(r2.exit_code, 2);
  EXPECT_NE(r2.err.find("refusing"), std::string::npos) << r2.err;
  EXPECT_TRUE(fs::exists(other / "notes.txt"));
}
