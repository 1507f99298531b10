// SPDX-License-Identifier: Apache-2.0
// The --device grammar, without hardware: parsing and resolution over made-up device lists.
#include <gtest/gtest.h>

#include "inertialnet/runtime/device_selection.hpp"
#include "inertialnet/runtime/error.hpp"
#include "runtime/clblast_tuning.hpp"

namespace inertialnet {
namespace {

DeviceInfo make(int index, int platform, int device, DeviceType type, std::string name, std::string platform_name,
                std::string platform_vendor = {}) {
  DeviceInfo d;
  d.platform_vendor = std::move(platform_vendor);
  d.index = index;
  d.platform_index = platform;
  d.device_index = device;
  d.type = type;
  d.name = std::move(name);
  d.platform_name = std::move(platform_name);
  return d;
}

// Two PoCL CPU devices of one name, then an NVIDIA GPU and an Intel GPU on other platforms.
std::vector<DeviceInfo> machine() {
  return {make(0, 0, 0, DeviceType::CPU, "pthread-skylake", "Portable Computing Language", "The pocl project"),
          make(1, 0, 1, DeviceType::CPU, "pthread-skylake", "Portable Computing Language", "The pocl project"),
          make(2, 1, 0, DeviceType::GPU, "NVIDIA H100", "NVIDIA CUDA"),
          make(3, 2, 0, DeviceType::GPU, "Intel(R) Arc(TM) A770", "Intel(R) OpenCL Graphics")};
}

std::vector<int> indices(const std::vector<DeviceInfo>& devices) {
  std::vector<int> out;
  for (const auto& d : devices) out.push_back(d.index);
  return out;
}

TEST(DeviceSpecParse, RecognisesEveryForm) {
  using Kind = DeviceSpec::Kind;
  EXPECT_EQ(parse_device_specs("").at(0).kind, Kind::Default);
  EXPECT_EQ(parse_device_specs("all").at(0).kind, Kind::All);
  EXPECT_EQ(parse_device_specs("ALL").at(0).kind, Kind::All);
  const auto index = parse_device_specs("12").at(0);
  EXPECT_EQ(index.kind, Kind::Index);
  EXPECT_EQ(index.index, 12);
  const auto pd = parse_device_specs("1:3").at(0);
  EXPECT_EQ(pd.kind, Kind::PlatformDevice);
  EXPECT_EQ(pd.platform, 1);
  EXPECT_EQ(pd.device, 3);
  const auto type = parse_device_specs("GPU").at(0);
  EXPECT_EQ(type.kind, Kind::Type);
  EXPECT_EQ(type.type, DeviceType::GPU);
  EXPECT_EQ(parse_device_specs("accelerator").at(0).type, DeviceType::Accelerator);
  EXPECT_EQ(parse_device_specs("cpu").at(0).type, DeviceType::CPU);
  const auto name = parse_device_specs("NVidia").at(0);
  EXPECT_EQ(name.kind, Kind::Name);
  EXPECT_EQ(name.name, "nvidia");
  EXPECT_EQ(parse_device_specs(" 0 , gpu ").size(), 2u);
}

TEST(DeviceSpecParse, RejectsMalformedSpecs) {
  for (const char* bad : {"1:", ":1", "a:b", "-1", "1,,2", "0:1:2", "7x"}) {
    EXPECT_THROW(parse_device_specs(bad), Error) << bad;
    try {
      parse_device_specs(bad);
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::InvalidInput) << bad;
    }
  }
}

TEST(DeviceSelect, DefaultPrefersTheFirstGpuThenTheFirstCpu) {
  EXPECT_EQ(indices(select_devices("", machine())), std::vector<int>{2});
  auto cpus_only = machine();
  cpus_only.resize(2);
  EXPECT_EQ(indices(select_devices("", cpus_only)), std::vector<int>{0});
}

TEST(DeviceSelect, EachFormSelectsTheRightDevice) {
  const auto devices = machine();
  EXPECT_EQ(indices(select_devices("1", devices)), std::vector<int>{1});
  EXPECT_EQ(indices(select_devices("0:1", devices)), std::vector<int>{1});
  EXPECT_EQ(indices(select_devices("2:0", devices)), std::vector<int>{3});
  EXPECT_EQ(indices(select_devices("cpu", devices)), std::vector<int>{0});
  EXPECT_EQ(indices(select_devices("gpu", devices)), std::vector<int>{2});
  EXPECT_EQ(indices(select_devices("nvidia", devices)), std::vector<int>{2});
  EXPECT_EQ(indices(select_devices("ARC", devices)), std::vector<int>{3});
  // Two devices of one name: the first, not an ambiguity.
  EXPECT_EQ(indices(select_devices("pocl", devices)), std::vector<int>{0});
  EXPECT_EQ(indices(select_devices("portable", devices)), std::vector<int>{0});
  EXPECT_EQ(indices(select_devices("all", devices)), (std::vector<int>{0, 1, 2, 3}));
  EXPECT_EQ(indices(select_devices("3,0:0,3", devices)), (std::vector<int>{3, 0}));
}

TEST(DeviceSelect, UnknownSpecsListTheDevices) {
  const auto devices = machine();
  for (const char* spec : {"nosuch", "9", "5:0", "accelerator"}) {
    try {
      select_devices(spec, devices);
      FAIL() << spec << " selected something";
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::InvalidInput);
      const std::string message = e.what();
      EXPECT_NE(message.find("NVIDIA H100"), std::string::npos) << message;
      EXPECT_NE(message.find("pthread-skylake"), std::string::npos) << message;
      EXPECT_NE(message.find("Available devices"), std::string::npos) << message;
    }
  }
}

// Issue 20, item 9: an index of any length is an index ("1234567" was "not a device index"), and
// the message says how many devices there are; a pasted 300-character spec is not echoed whole.
TEST(DeviceSelect, ALargeIndexIsAMissingDeviceAndLongSpecsAreCut) {
  for (const char* spec : {"1234567", "99999999999999999999", "0:1234567"}) {
    try {
      select_devices(spec, machine());
      FAIL() << spec << " selected something";
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::InvalidInput);
      const std::string message = e.what();
      EXPECT_NE(message.find(std::string("There is no device ") + (spec[1] == ':' ? "" : "with index ") + spec),
                std::string::npos)
          << message;
      EXPECT_NE(message.find("there are 4 devices, 0 to 3"), std::string::npos) << message;
    }
  }
  const std::string long_spec(300, '7');
  try {
    select_devices(long_spec + "x", machine());
    FAIL() << "a 301-character spec selected something";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.find(std::string(41, '7')), std::string::npos) << message;
    EXPECT_NE(message.find(std::string(40, '7') + "\xE2\x80\xA6"), std::string::npos) << message;
  }
}

TEST(DeviceSelect, NameMatchingDifferentDevicesIsAmbiguous) {
  // "i" occurs in every name here; "a" in NVIDIA and in Arc.
  try {
    select_devices("nvidia,a", machine());
    FAIL() << "ambiguous spec accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("ambiguous"), std::string::npos) << e.what();
  }
}

TEST(DeviceSelect, SingleDeviceCommandsRefuseSeveral) {
  EXPECT_EQ(select_device("1", machine()).index, 1);
  EXPECT_THROW(select_device("all", machine()), Error);
  EXPECT_THROW(select_device("0,1", machine()), Error);
}

TEST(DeviceSelect, NoDevicesAtAll) {
  try {
    select_devices("", {});
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("pocl-opencl-icd"), std::string::npos) << e.what();
  }
}

TEST(DeviceSelect, EnvironmentStandsInForTheFlag) {
  ::setenv(kDeviceEnvironmentVariable, "gpu", 1);
  EXPECT_EQ(device_spec_or_environment(""), "gpu");
  EXPECT_EQ(device_spec_or_environment("1"), "1");
  ::unsetenv(kDeviceEnvironmentVariable);
  EXPECT_EQ(device_spec_or_environment(""), "");
}

TEST(ClblastTuning, EntriesMatchOnlyTheDevicesTheyWereMeasuredFor) {
  const DeviceInfo avx512 = make(0, 0, 0, DeviceType::CPU, "pthread-skylake-avx512-Intel(R) Xeon(R) Processor",
                                 "Portable Computing Language", "The pocl project");
  const auto matches = detail::clblast_overrides_for(avx512);
  ASSERT_EQ(matches.size(), 1u);
  EXPECT_STREQ(matches[0]->kernel, "Xgemm");
  EXPECT_EQ(matches[0]->parameters.size(), 16u);  // CLBlast refuses partial Xgemm sets
  EXPECT_TRUE(detail::clblast_overrides_for(make(0, 0, 0, DeviceType::CPU, "pthread-haswell", "Portable Computing Language")).empty());
  EXPECT_TRUE(detail::clblast_overrides_for(make(0, 1, 0, DeviceType::GPU, "NVIDIA H100", "NVIDIA CUDA")).empty());
}

TEST(ErrorNames, OpenClAndClblastCodesHaveNames) {
  EXPECT_EQ(cl_error_name(CL_OUT_OF_RESOURCES), "CL_OUT_OF_RESOURCES");
  EXPECT_EQ(cl_error_name(-54), "CL_INVALID_WORK_GROUP_SIZE");
  EXPECT_EQ(cl_error_name(-9999), "CL_UNKNOWN_ERROR(-9999)");
  EXPECT_EQ(clblast_status_name(-1016), "kInvalidLeadDimA");
  EXPECT_EQ(clblast_status_name(-5), "CL_OUT_OF_RESOURCES");
  try {
    check_cl(CL_INVALID_KERNEL_ARGS, "clEnqueueNDRangeKernel", ClSite{"my device", "warp/warp_bilinear"});
    FAIL();
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_EQ(e.kind(), ErrorKind::Runtime);
    EXPECT_EQ(e.exit_code(), 1);
    for (const char* part : {"clEnqueueNDRangeKernel", "CL_INVALID_KERNEL_ARGS", "my device", "warp/warp_bilinear"}) {
      EXPECT_NE(message.find(part), std::string::npos) << message;
    }
  }
}

}  // namespace
}  // namespace inertialnet
