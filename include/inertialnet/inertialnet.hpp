// The whole public API.
#pragma once

#include "inertialnet/buffer_pool.hpp"
#include "inertialnet/device.hpp"
#include "inertialnet/device_info.hpp"
#include "inertialnet/device_selection.hpp"
#include "inertialnet/error.hpp"
#include "inertialnet/ops/gemm.hpp"
#include "inertialnet/program_cache.hpp"
#include "inertialnet/queue.hpp"
#include "inertialnet/tensor.hpp"
