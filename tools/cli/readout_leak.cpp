// SPDX-License-Identifier: Apache-2.0
#include "readout_leak.hpp"

#include "inertialnet/io/flow_io.hpp"
#include "inertialnet/runtime/device.hpp"
#include "inertialnet/runtime/device_info.hpp"
#include "inertialnet/runtime/device_selection.hpp"
#include "inertialnet/runtime/error.hpp"

namespace inertialnet::cli {

namespace {

// A frame interval of 20 Hz; the solve is linear in the flow, so the leak does not depend on it.
constexpr double kDt = 0.05;
// A base rate of a few deg/s about every axis (a well-posed solve), and the change down the rows
// (rad/s per unit of s: a 30 ms readout at 1.7 rad/s²), small next to it so the solve stays linear.
constexpr double kBase[3] = {0.2, -0.15, 0.1};
constexpr double kGradient = 0.05;

// The exact rotational flow (pixels over kDt) of rate ω + gradient·s at each row, from the motion
// field of geometric_head.hpp.
FlowField rotational_flow(const CameraIntrinsics& c, const Vec3& gradient) {
  FlowField f(c.width, c.height);
  for (int yp = 0; yp < c.height; ++yp) {
    const double s = static_cast<double>(yp) / (c.height - 1) - 0.5;
    const Vec3 w{kBase[0] + gradient[0] * s, kBase[1] + gradient[1] * s, kBase[2] + gradient[2] * s};
    const double y = (yp - c.cy) / c.fy;
    for (int xp = 0; xp < c.width; ++xp) {
      const double x = (xp - c.cx) / c.fx;
      const double xdot = x * y * w[0] - (1 + x * x) * w[1] + y * w[2];
      const double ydot = (1 + y * y) * w[0] - x * y * w[1] - x * w[2];
      f.u[f.index(xp, yp)] = static_cast<float>(c.fx * xdot * kDt);
      f.v[f.index(xp, yp)] = static_cast<float>(c.fy * ydot * kDt);
    }
  }
  return f;
}

}  // namespace

Mat3 readout_leak(const CameraIntrinsics& camera, const GeometricHeadOptions& options, const std::string& device_spec) {
  CameraIntrinsics ideal = camera;
  ideal.distortion = LensDistortion::None;
  ideal.coefficients.clear();
  GeometricHeadOptions global_shutter = options;
  global_shutter.readout_time_s = 0;
  const std::vector<DeviceInfo> devices = select_devices(device_spec_or_environment(device_spec), discover_devices());
  if (devices.empty()) throw runtime_error("no OpenCL device to solve the leak's flow fields on");
  Device device(devices.front());
  const auto queue = device.create_queue();
  GeometricHead head(device, ideal, global_shutter);
  const Vec3 base = head.estimate(*queue, rotational_flow(ideal, {0, 0, 0}), kDt).omega;
  Mat3 leak{};
  for (int j = 0; j < 3; ++j) {
    Vec3 gradient{0, 0, 0};
    gradient[static_cast<std::size_t>(j)] = kGradient;
    const Vec3 w = head.estimate(*queue, rotational_flow(ideal, gradient), kDt).omega;
    for (int i = 0; i < 3; ++i) {
      leak[static_cast<std::size_t>(3 * i + j)] = (w[static_cast<std::size_t>(i)] - base[static_cast<std::size_t>(i)]) / kGradient;
    }
  }
  return leak;
}

}  // namespace inertialnet::cli
