// SPDX-License-Identifier: Apache-2.0
// Helpers shared by the test suites: the device under test, random data and comparisons.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <functional>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "inertialnet/inertialnet.hpp"

namespace inertialnet::testing {

// The device the suites run on: $INERTIALNET_TEST_DEVICE, else $INERTIALNET_DEVICE, else the
// default (first GPU, else first CPU), so the same suite runs on PoCL in CI and on a GPU.
// Opened once per process.
Device& test_device();
Queue& test_queue();

// Gives the test device the packed GEMM's build options `packed` (e.g. {"MR", 1}: any value
// `inertialnet tune` may store) for the guard's lifetime; its own tuning comes back at the end.
// For the kernels whose panels follow the device's MR.
class ScopedPackedTuning {
 public:
  explicit ScopedPackedTuning(const std::map<std::string, int>& packed);
  ~ScopedPackedTuning();
  ScopedPackedTuning(const ScopedPackedTuning&) = delete;
  ScopedPackedTuning& operator=(const ScopedPackedTuning&) = delete;

 private:
  DeviceTuning saved_;
};

// The build log of the kernel family `family` (kernels_cl/<family>.cl as embedded) compiled for
// the test device with the library's options for it and `options`; a failed build is a test
// failure. For the tests that keep the
// kernels free of compiler warnings (PoCL prints them on every first compile).
std::string kernel_build_log(const std::string& family, const std::string& options);
// Whether the test device's program cache holds a program of the family (or source) `name`.
bool device_holds_program(const std::string& name);
// Rebuilds every embedded kernel family the test device's program cache holds, with the defines
// it was built with (ProgramCache::held_programs), and fails the test on a compiler warning in
// any (PoCL prints each on the user's first run); returns the families rebuilt.
std::vector<std::string> expect_held_kernels_compile_without_warnings();

// Uniform values in [lo, hi) from a fixed seed.
std::vector<float> random_vector(std::size_t count, std::uint32_t seed, float lo = -1.0f, float hi = 1.0f);

// Largest |a-b| / (|b| + floor) over the elements, and a gtest assertion on it that reports
// the worst index. `floor` keeps near-zero references from inflating the relative error.
struct Difference {
  double max_abs = 0;
  double max_rel = 0;
  std::size_t worst_index = 0;
};
Difference compare(const std::vector<float>& actual, const std::vector<float>& expected, double floor = 1e-3);
::testing::AssertionResult all_close(const std::vector<float>& actual, const std::vector<float>& expected,
                                     double relative_tolerance, double floor = 1e-3);

// Runs `call`, expects an Error of kind InvalidInput and returns its message ("" and a test
// failure when nothing or something else is thrown).
std::string invalid_input_message(const std::function<void()>& call);
// A pinhole camera of w×h pixels with its principal point at the image centre, no distortion.
inline CameraIntrinsics pinhole_camera(int w, int h, double fx, double fy) {
  CameraIntrinsics c;
  c.width = w;
  c.height = h;
  c.fx = fx;
  c.fy = fy;
  c.cx = (w - 1) / 2.0;
  c.cy = (h - 1) / 2.0;
  return c;
}

// True when `part` occurs in `text` (for checking messages).
inline bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// Runs `call` and expects an Error of kind InvalidInput whose message contains `needle`.
void expect_invalid_input(const std::function<void()>& call, const std::string& needle);

// A grey frame (the three planes equal) whose pixel (x, y) is value(x, y).
HostImage grey_frame(int width, int height, const std::function<float(double, double)>& value);

// A fresh, empty directory under the system temp dir, removed at process exit.
std::string temporary_directory(const std::string& stem);

// Sets an environment variable (nullptr: unsets it) for one scope and restores it after.
class ScopedEnvironment {
 public:
  ScopedEnvironment(const char* name, const char* value);
  ~ScopedEnvironment();
  ScopedEnvironment(const ScopedEnvironment&) = delete;
  ScopedEnvironment& operator=(const ScopedEnvironment&) = delete;

 private:
  std::string name_;
  bool had_ = false;
  std::string old_;
};

}  // namespace inertialnet::testing
