// SPDX-License-Identifier: Apache-2.0
// Mathematical constants used across the layers (one definition, so no file types π again).
#pragma once

namespace inertialnet {

constexpr double kPi = 3.14159265358979323846;

}  // namespace inertialnet
