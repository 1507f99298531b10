#include "support/testing.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <sstream>

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

std::vector<float> random_vector(std::size_t count, std::uint32_t seed, float lo, float hi) {
  std::mt19937 generator(seed);
  std::uniform_real_distribution<float> distribution(lo, hi);
  std::vector<float> values(count);
  for (auto& v : values) v = distribution(generator);
  return values;
}

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
    return ::testing::AssertionSuccess() << "max relative error " << d.max_rel << ", max abs " << d.max_abs;
  }
  return ::testing::AssertionFailure() << "max relative error " << d.max_rel << " > " << relative_tolerance
                                       << " at index " << d.worst_index << ": got " << actual[d.worst_index]
                                       << ", expected " << expected[d.worst_index] << " (max abs " << d.max_abs << ")";
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

}  // namespace inertialnet::testing
