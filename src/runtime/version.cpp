// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/runtime/version.hpp"

#include <clblast.h>
// Only the version macros: the runtime layer itself does not use OpenCV.
#include <opencv2/core/version.hpp>

#include "runtime/source_identity.hpp"

namespace inertialnet {

BuildVersions build_versions() {
  BuildVersions v;
  v.inertialnet = INERTIALNET_VERSION;  // the project's version, from CMake
  v.clblast = std::to_string(CLBLAST_VERSION_MAJOR) + "." + std::to_string(CLBLAST_VERSION_MINOR) + "." +
              std::to_string(CLBLAST_VERSION_PATCH);
  v.opencv = CV_VERSION;
  v.source = detail::source_identity();
  return v;
}

}  // namespace inertialnet
