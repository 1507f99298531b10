// SPDX-License-Identifier: Apache-2.0
// The one place that includes the OpenCL C API, so that every translation unit agrees on the
// API level. 1.2 entry points exist on every platform we target (PoCL, NVIDIA, AMD, Intel);
// the device's own OpenCL C version still decides the kernels' -cl-std.
#pragma once

#ifndef CL_TARGET_OPENCL_VERSION
#define CL_TARGET_OPENCL_VERSION 120
#endif
#ifndef CL_USE_DEPRECATED_OPENCL_1_2_APIS
#define CL_USE_DEPRECATED_OPENCL_1_2_APIS
#endif
#include <CL/cl.h>
