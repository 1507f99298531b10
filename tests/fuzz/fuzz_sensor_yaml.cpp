// SPDX-License-Identifier: Apache-2.0
// mav0/cam0/sensor.yaml (through OpenCV's FileStorage), then the camera model built from it,
// whose lens check undistorts and distorts a grid of pixels.
#include "fuzz_support.hpp"
#include "inertialnet/io/camera.hpp"
#include "inertialnet/io/euroc.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = inertialnet::fuzz::as_file(data, size, "sensor.yaml");
  inertialnet::fuzz::expect_only_inertialnet_errors([&] {
    const inertialnet::CameraCalibration calibration = inertialnet::read_camera_yaml(path);
    // The resolution is bounded by the reader, not by memory: keep the fuzzer's runs short.
    if (static_cast<double>(calibration.width) * calibration.height <= 1e6) {
      inertialnet::CameraIntrinsics::from_calibration(calibration);
    }
  });
  return 0;
}
