#pragma once
// Helpers every test executable may use: the bundled example scenes, a file written and read whole,
// a fresh folder per test, the message of a weft::Error, a relative difference,
// and the mean of repeated samples with its standard error.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>

#include "weft/core/error.h"

namespace weft::testing {

// The bundled example scenes.
inline const std::filesystem::path kExamples =
    std::filesystem::path(WEFT_SOURCE_DIR) / "scenes/examples";

// An empty folder for the running test, under the build folder: <build>/test_tmp/<suite>.<test>.
// One per test, because ctest runs the tests of one executable as parallel processes.
// The whole of a file, as bytes.
// |a - b| relative to the reference b.
inline double relative_difference(double a, double b) {
  return std::abs(a - b) / std::abs(b);
}

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// 'text' written to 'p', replacing it.
inline void write_file(const std::filesystem::path& p, const std::string& text) {
  std::ofstream(p) << text;
}

inline std::filesystem::path fresh_test_dir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::filesystem::path dir = std::filesystem::path(WEFT_BINARY_DIR) / "test_tmp" /
                                    (std::string(info->test_suite_name()) + "." + info->name());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

// The message of the weft::Error that f throws, or "" when it throws none (any other exception
// propagates and fails the test).
inline std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// Mean of n samples sample(i), i = 0 .. n-1, and the standard error of that mean (from the
// sample variance).
struct SampleMean {
  double mean = 0, std_error = 0;
};
inline SampleMean sample_mean(int n, const std::function<double(int i)>& sample) {
  double sum = 0, sum2 = 0;
  for (int i = 0; i < n; ++i) {
    const double v = sample(i);
    sum += v;
    sum2 += v * v;
  }
  const double mean = sum / n;
  return {mean, std::sqrt(std::max(0.0, sum2 / n - mean * mean) / (n - 1))};
}

}  // namespace weft::testing
