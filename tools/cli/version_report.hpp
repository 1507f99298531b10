// SPDX-License-Identifier: Apache-2.0
// `inertialnet --version`: this library's version, the CLBlast and OpenCV it was built with, and
// every OpenCL platform with its version and each device's driver version (what a bug report needs).
#pragma once

#include <string>

namespace inertialnet::cli {

std::string version_report();

}  // namespace inertialnet::cli
