// SPDX-License-Identifier: Apache-2.0
// The versions of this library and of what it was built against, for `inertialnet --version`
// and bug reports. The OpenCL platforms and drivers are run-time facts: see discover_devices().
#pragma once

#include <string>

namespace inertialnet {

struct BuildVersions {
  std::string inertialnet;  // this library, e.g. "0.1.0"
  std::string clblast;      // the CLBlast headers built against, e.g. "1.5.3"
  std::string opencv;       // the OpenCV headers built against, e.g. "4.6.0"
};

BuildVersions build_versions();

}  // namespace inertialnet
