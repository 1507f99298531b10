// SPDX-License-Identifier: Apache-2.0
// Device selection on real PoCL devices. CTest runs this suite with POCL_DEVICES="pthread
// pthread", so PoCL exposes two CPU devices on one platform and every selector form can be
// exercised against real handles.
#include <cstdlib>

#include "support/testing.hpp"

namespace inertialnet {
namespace {

std::vector<DeviceInfo> pocl_devices() {
  std::vector<DeviceInfo> pocl;
  for (const auto& d : discover_devices()) {
    if (d.is_pocl()) pocl.push_back(d);
  }
  return pocl;
}

TEST(PoclSelection, TwoDevicesAreExposed) {
  ASSERT_STREQ(std::getenv("POCL_DEVICES"), "pthread pthread") << "run this suite through ctest";
  const auto pocl = pocl_devices();
  ASSERT_EQ(pocl.size(), 2u);
  EXPECT_EQ(pocl[0].platform_index, pocl[1].platform_index);
  EXPECT_EQ(pocl[0].device_index, 0);
  EXPECT_EQ(pocl[1].device_index, 1);
}

TEST(PoclSelection, EveryFormSelectsARealDevice) {
  const auto all = discover_devices();
  const auto pocl = pocl_devices();
  ASSERT_EQ(pocl.size(), 2u);
  const DeviceInfo& second = pocl[1];

  EXPECT_EQ(select_device(std::to_string(second.index), all).device_id, second.device_id);
  EXPECT_EQ(select_device(second.address(), all).device_id, second.device_id);
  EXPECT_EQ(select_device(std::to_string(pocl[0].index), all).device_id, pocl[0].device_id);
  EXPECT_EQ(select_devices("all", all).size(), all.size());
  EXPECT_EQ(select_device("pocl", all).device_id, pocl[0].device_id);  // same name twice: the first
  EXPECT_EQ(select_device("cpu", all).type, DeviceType::CPU);
  EXPECT_EQ(select_devices(pocl[0].address() + "," + second.address(), all).size(), 2u);
}

TEST(PoclSelection, BothDevicesRunKernels) {
  for (const auto& info : pocl_devices()) {
    Device device(info);
    Tensor t = Tensor::empty(device, {33});
    Kernel& fill = device.queue().kernel("elementwise", "fill");
    fill.set_args(t, 33, static_cast<float>(info.device_index + 1));
    device.queue().launch(fill, 33, 8);
    EXPECT_EQ(t.to_host(device.queue()), std::vector<float>(33, static_cast<float>(info.device_index + 1)));
  }
}

}  // namespace
}  // namespace inertialnet
