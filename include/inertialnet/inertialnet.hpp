// SPDX-License-Identifier: Apache-2.0
// The whole public API: every public header of every layer, lowest layer first.
#pragma once

// core
#include "inertialnet/core/constants.hpp"
#include "inertialnet/core/random.hpp"
#include "inertialnet/core/tensor_spec.hpp"
#include "inertialnet/core/vec3.hpp"

// runtime
#include "inertialnet/runtime/buffer_pool.hpp"
#include "inertialnet/runtime/cache_directory.hpp"
#include "inertialnet/runtime/cl_handle.hpp"
#include "inertialnet/runtime/device.hpp"
#include "inertialnet/runtime/device_info.hpp"
#include "inertialnet/runtime/device_selection.hpp"
#include "inertialnet/runtime/error.hpp"
#include "inertialnet/runtime/kernel_defines.hpp"
#include "inertialnet/runtime/layer_profiler.hpp"
#include "inertialnet/runtime/log.hpp"
#include "inertialnet/runtime/opencl.hpp"
#include "inertialnet/runtime/program_cache.hpp"
#include "inertialnet/runtime/queue.hpp"
#include "inertialnet/runtime/tensor.hpp"
#include "inertialnet/runtime/version.hpp"

// ops
#include "inertialnet/ops/activation.hpp"
#include "inertialnet/ops/activation_backward.hpp"
#include "inertialnet/ops/bias_activation.hpp"
#include "inertialnet/ops/bias_gradient.hpp"
#include "inertialnet/ops/channel_norm.hpp"
#include "inertialnet/ops/concat.hpp"
#include "inertialnet/ops/conv2d.hpp"
#include "inertialnet/ops/conv2d_backward.hpp"
#include "inertialnet/ops/conv_transpose2d.hpp"
#include "inertialnet/ops/correlation.hpp"
#include "inertialnet/ops/dropout.hpp"
#include "inertialnet/ops/dropout_backward.hpp"
#include "inertialnet/ops/elementwise.hpp"
#include "inertialnet/ops/gemm/gemm.hpp"
#include "inertialnet/ops/gemm/backend.hpp"
#include "inertialnet/ops/gemm/packed_gemm.hpp"
#include "inertialnet/ops/gemm/plan.hpp"
#include "inertialnet/ops/linear.hpp"
#include "inertialnet/ops/linear_backward.hpp"
#include "inertialnet/ops/motion_field.hpp"
#include "inertialnet/ops/mse_loss.hpp"
#include "inertialnet/ops/normalize.hpp"
#include "inertialnet/ops/optimizer_step.hpp"
#include "inertialnet/ops/pool.hpp"
#include "inertialnet/ops/pool_backward.hpp"
#include "inertialnet/ops/upsample.hpp"
#include "inertialnet/ops/warp.hpp"

// models
#include "inertialnet/models/dis_flow.hpp"
#include "inertialnet/models/flow_consistency.hpp"
#include "inertialnet/models/flownet.hpp"
#include "inertialnet/models/dis_flow.hpp"
#include "inertialnet/models/geometric_head.hpp"
#include "inertialnet/models/head_backprop.hpp"
#include "inertialnet/models/head_ensemble.hpp"
#include "inertialnet/models/inertialnet_head.hpp"
#include "inertialnet/models/parameters.hpp"
#include "inertialnet/models/synthetic_weights.hpp"
#include "inertialnet/models/weights.hpp"

// io
#include "inertialnet/io/camera.hpp"
#include "inertialnet/io/camera_imu.hpp"
#include "inertialnet/io/euroc.hpp"
#include "inertialnet/io/flow_io.hpp"
#include "inertialnet/io/frame_source.hpp"
#include "inertialnet/io/image_io.hpp"
#include "inertialnet/io/imu_sequence.hpp"
#include "inertialnet/io/rates_csv.hpp"
#include "inertialnet/io/safetensors.hpp"
#include "inertialnet/io/safetensors_writer.hpp"
#include "inertialnet/io/weight_fit.hpp"

// synth
#include "inertialnet/synth/synthetic_sequence.hpp"

// eval
#include "inertialnet/eval/evaluate.hpp"
#include "inertialnet/eval/imu_sync.hpp"
#include "inertialnet/eval/metrics.hpp"
#include "inertialnet/eval/plots.hpp"
#include "inertialnet/eval/spline.hpp"
#include "inertialnet/eval/time_offset.hpp"

// pipeline
#include "inertialnet/pipeline/pipeline.hpp"
#include "inertialnet/pipeline/predict.hpp"
#include "inertialnet/pipeline/rates_processor.hpp"

// train
#include "inertialnet/train/flip_augmentation.hpp"
#include "inertialnet/train/trainer.hpp"
#include "inertialnet/train/training_log.hpp"
#include "inertialnet/train/training_set.hpp"
