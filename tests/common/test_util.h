#pragma once

// Helpers for the common-layer tests: a private temporary directory per test, a measurement
// whose values expose any lossy round trip, and capture of the InputError a call throws.

#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Core>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "mbid/common/error.h"
#include "mbid/common/measurement.h"

namespace mbid::testing {

// A fresh directory under the system temp dir, removed with everything in it.
class TempDir {
 public:
  TempDir() {
    static std::atomic<int> counter{0};  // distinct names for several TempDirs in one test
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string test = info == nullptr ? "test" : std::string(info->name());
    // A parameterized test's name is "Name/Param": one folder, not a folder left in another.
    std::replace(test.begin(), test.end(), '/', '_');
    path_ = std::filesystem::temp_directory_path() /
            ("mbid_common_" + test + "_" + std::to_string(::getpid()) + "_" +
             std::to_string(counter++));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  std::string File(const std::string& name) const { return (path_ / name).string(); }
  // Names of all entries, to prove that a failed write left nothing (not even a temporary).
  std::vector<std::string> Entries() const {
    std::vector<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(path_)) {
      names.push_back(entry.path().filename().string());
    }
    return names;
  }

 private:
  std::filesystem::path path_;
};

inline void WriteText(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  ASSERT_TRUE(out.good()) << path;
}

// A measurement with three channels in non-alphabetical order, distinct units, a non-zero start
// and values that are not short decimals.
inline Measurement MakeMeasurement(int samples) {
  Measurement m;
  m.channels = {"psi", "phi", "alpha"};  // not sorted: the file must keep this order
  m.units = {"rad", "rad", "m"};         // one differs: units are per channel
  m.start_time_s = 0.125;                // non-zero start must survive
  m.sample_interval_s = 0.01;            // 100 Hz as in the reference scenario; inexact in binary
  m.source = "simulation";
  m.values.resize(samples, 3);  // 3 channels as named above
  for (int j = 0; j < samples; ++j) {
    for (int c = 0; c < 3; ++c) {  // 3 channels as named above
      // A decaying sinusoid divided by 3 so that most values need all 17 digits.
      m.values(j, c) = std::sin(0.1 * (j + 1) * (c + 1)) * std::exp(-0.01 * j) / 3.0;
    }
  }
  return m;
}

// Bit-for-bit equality (EXPECT_EQ on doubles would accept -0.0 == 0.0).
inline bool SameBits(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() &&
         std::memcmp(a.data(), b.data(), sizeof(double) * static_cast<size_t>(a.size())) == 0;
}

inline bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

// The InputError thrown by `call`; a test failure if it throws anything else or nothing.
inline InputError CatchInputError(const std::function<void()>& call) {
  try {
    call();
  } catch (const InputError& e) {
    return e;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected InputError, got another exception: " << e.what();
    return InputError("", "", "", "");
  }
  ADD_FAILURE() << "expected InputError, nothing was thrown";
  return InputError("", "", "", "");
}

}  // namespace mbid::testing
