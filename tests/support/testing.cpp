// SPDX-License-Identifier: Apache-2.0
#include "support/testing.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <sstream>
#include <string_view>

#include "inertialnet/runtime/program_cache.hpp"

namespace inertialnet::testing {

Device& test_device() {
  static std::unique_ptr<Device> device = [] {
    const char* spec = std::getenv("INERTIALNET_TEST_DEVICE");
    const auto info = select_device(device_spec_or_environment(spec ? spec : ""), discover_devices());
    return std::make_unique<Device>(info);
  }();
  return *device;
}

Queue& test_queue() { return test_device().queue(); }

std::string kernel_build_log(const std::string& family, const std::string& options) {
  Device& device = test_device();
  const std::string_view source = embedded_kernel_source(family);
  const char* text = source.data();
  const std::size_t length = source.size();
  cl_int status = CL_SUCCESS;
  cl_program program = clCreateProgramWithSource(device.context(), 1, &text, &length, &status);
  if (status != CL_SUCCESS) {
    ADD_FAILURE() << family << ": clCreateProgramWithSource returned " << status;
    return "";
  }
  const cl_device_id id = device.id();
  // As the library builds it (ProgramCache::build_options: the OpenCL C version, fp16), so a
  // warning the user would see is one the test sees.
  const std::string full = device.programs().build_options(options);
  const cl_int built = clBuildProgram(program, 1, &id, full.c_str(), nullptr, nullptr);
  const std::string log = program_build_log(program, id);
  clReleaseProgram(program);
  EXPECT_EQ(built, CL_SUCCESS) << family << " " << full << ":\n" << log;
  return log;
}

bool device_holds_program(const std::string& name) {
  const std::vector<HeldProgram> held = test_device().programs().held_programs();
  return std::any_of(held.begin(), held.end(), [&](const HeldProgram& p) { return p.name == name; });
}

std::vector<std::string> expect_held_kernels_compile_without_warnings() {
  const std::vector<std::string> embedded = embedded_kernel_families();
  std::vector<std::string> families;
  for (const HeldProgram& held : test_device().programs().held_programs()) {
    if (std::find(embedded.begin(), embedded.end(), held.name) == embedded.end()) continue;  // a test's own source
    const std::string log = kernel_build_log(held.name, held.defines);
    EXPECT_EQ(log.find("warning"), std::string::npos) << held.name << " " << held.defines << ":\n" << log;
    if (std::find(families.begin(), families.end(), held.name) == families.end()) families.push_back(held.name);
  }
  return families;
}

ScopedPackedTuning::ScopedPackedTuning(const std::map<std::string, int>& packed) : saved_(test_device().tuning()) {
  DeviceTuning tuning = saved_;
  for (const auto& [name, value] : packed) tuning.packed[name] = value;
  test_device().set_tuning(tuning);
}

ScopedPackedTuning::~ScopedPackedTuning() { test_device().set_tuning(saved_); }

std::vector<float> random_vector(std::size_t count, std::uint32_t seed, float lo, float hi) {
  std::mt19937 generator(seed);
  std::uniform_real_distribution<float> distribution(lo, hi);
  std::vector<float> values(count);
  for (auto& v : values) v = distribution(generator);
  return values;
}

namespace {

// The largest errors of the comparisons each test suite passed through all_close(), printed when the program ends, so
// a CI log shows how close every op came to its reference, not only that it passed.
struct LargestErrors : ::testing::Environment {
  std::map<std::string, Difference> by_suite;
  void TearDown() override {
    for (const auto& [suite, d] : by_suite) {
      std::printf("[ largest  ] %s: relative error %.3g, absolute %.3g\n", suite.c_str(), d.max_rel, d.max_abs);
    }
  }
};

LargestErrors& largest_errors() {
  static LargestErrors* errors = [] {
    auto* e = new LargestErrors;  // owned by googletest
    ::testing::AddGlobalTestEnvironment(e);
    return e;
  }();
  return *errors;
}
[[maybe_unused]] const bool registered = (largest_errors(), true);

void record(const Difference& d) {
  const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
  if (!test) return;
  Difference& worst = largest_errors().by_suite[test->test_suite_name()];
  worst.max_rel = std::max(worst.max_rel, d.max_rel);
  worst.max_abs = std::max(worst.max_abs, d.max_abs);
}

}  // namespace

Difference compare(const std::vector<float>& actual, const std::vector<float>& expected, double floor) {
  Difference d;
  for (std::size_t i = 0; i < actual.size() && i < expected.size(); ++i) {
    const double abs = std::fabs(static_cast<double>(actual[i]) - expected[i]);
    const double rel = abs / (std::fabs(static_cast<double>(expected[i])) + floor);
    if (std::isnan(abs) || rel > d.max_rel) {
      d.max_rel = std::isnan(abs) ? INFINITY : rel;
      d.worst_index = i;
    }
    if (abs > d.max_abs) d.max_abs = abs;
  }
  return d;
}

::testing::AssertionResult all_close(const std::vector<float>& actual, const std::vector<float>& expected,
                                     double relative_tolerance, double floor) {
  if (actual.size() != expected.size()) {
    return ::testing::AssertionFailure() << "sizes differ: " << actual.size() << " vs " << expected.size();
  }
  const Difference d = compare(actual, expected, floor);
  if (d.max_rel <= relative_tolerance) {
    record(d);  // only comparisons that hold: a test may also show that a wrong result differs
    return ::testing::AssertionSuccess() << "max relative error " << d.max_rel << ", max abs " << d.max_abs;
  }
  return ::testing::AssertionFailure() << "max relative error " << d.max_rel << " > " << relative_tolerance
                                       << " at index " << d.worst_index << ": got " << actual[d.worst_index]
                                       << ", expected " << expected[d.worst_index] << " (max abs " << d.max_abs << ")";
}

std::string invalid_input_message(const std::function<void()>& call) {
  try {
    call();
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::InvalidInput) << e.what();
    return e.what();
  }
  ADD_FAILURE() << "accepted; expected an invalid_input error";
  return {};
}

void expect_invalid_input(const std::function<void()>& call, const std::string& needle) {
  const std::string message = invalid_input_message(call);
  EXPECT_NE(message.find(needle), std::string::npos) << "expected a message mentioning \"" << needle
                                                     << "\", got: " << message;
}

HostImage grey_frame(int width, int height, const std::function<float(double, double)>& value) {
  HostImage image;
  image.width = width;
  image.height = height;
  image.data.resize(3 * image.plane_size());
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const float v = value(x, y);
      for (int c = 0; c < 3; ++c) image.data[c * image.plane_size() + static_cast<std::size_t>(y) * width + x] = v;
    }
  return image;
}

std::string temporary_directory(const std::string& stem) {
  static std::vector<std::filesystem::path> created;
  static struct Cleanup {
    ~Cleanup() {
      std::error_code error;
      for (const auto& p : created) std::filesystem::remove_all(p, error);
    }
  } cleanup;
  static int counter = 0;
  const auto path = std::filesystem::temp_directory_path() /
                    ("inertialnet-" + stem + "-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
  std::filesystem::remove_all(path);
  std::filesystem::create_directories(path);
  created.push_back(path);
  return path.string();
}

ScopedEnvironment::ScopedEnvironment(const char* name, const char* value) : name_(name) {
  const char* old = std::getenv(name);
  had_ = old != nullptr;
  if (had_) old_ = old;
  if (value) {
    ::setenv(name, value, 1);
  } else {
    ::unsetenv(name);
  }
}

ScopedEnvironment::~ScopedEnvironment() {
  if (had_) {
    ::setenv(name_.c_str(), old_.c_str(), 1);
  } else {
    ::unsetenv(name_.c_str());
  }
}

}  // namespace inertialnet::testing
