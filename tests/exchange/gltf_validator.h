#pragma once
// The Khronos glTF validator (npm package gltf-validator, pinned in tests/exchange/node and
// installed by scripts/install-gltf-validator.sh) run on a file by tests/exchange/node/validate.js.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "test_util.h"

namespace weft::testing {

// The validator's report on 'file' ({errors, warnings, infos, hints, messages}); null when node or
// the validator is missing, with the reason in 'why'.
inline nlohmann::json khronos_report(const std::filesystem::path& file, std::string* why) {
  const std::filesystem::path script =
      std::filesystem::path(WEFT_SOURCE_DIR) / "tests/exchange/node/validate.js";
  if (std::system("node --version >/dev/null 2>&1") != 0) {
    *why = "node not found on the PATH (install nodejs, then scripts/install-gltf-validator.sh)";
    return {};
  }
  const auto out = file.parent_path() / (file.filename().string() + ".report.json");
  const auto err = file.parent_path() / (file.filename().string() + ".report.err");
  const int rc = std::system(("node '" + script.string() + "' '" + file.string() + "' >'" +
                              out.string() + "' 2>'" + err.string() + "'")
                                 .c_str());
  if (WIFEXITED(rc) && WEXITSTATUS(rc) == 77) {
    *why = slurp(err);
    return {};
  }
  EXPECT_EQ(rc, 0) << slurp(err);
  return nlohmann::json::parse(slurp(out));
}

}  // namespace weft::testing
