// SPDX-License-Identifier: Apache-2.0
// The versions of this library and of what it was built against, for `inertialnet --version`,
// bug reports and the provenance of a batch's outputs. The OpenCL platforms and drivers are
// run-time facts: see discover_devices().
#pragma once

#include <string>

namespace inertialnet {

struct BuildVersions {
  std::string inertialnet;  // this library, e.g. "0.1.0"
  std::string clblast;      // the CLBlast headers built against, e.g. "1.5.3"
  std::string opencv;       // the OpenCV headers built against, e.g. "4.6.0"
  // The SHA-256 of the sources built (src/, include/, kernels_cl/, the CMake files; 64 hex
  // digits): unlike the version, it changes with every change of behaviour, so an output that
  // records it (a batch's provenance) is current for this build only.
  std::string source;
};

BuildVersions build_versions();

}  // namespace inertialnet
