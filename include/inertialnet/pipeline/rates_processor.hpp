// SPDX-License-Identifier: Apache-2.0
// The pair processors the pipeline runs: what turns two frames into angular rates.
//
// Flow comes from FlowNet2 (or a lighter family member, on the device), from OpenCV's DIS
// optical flow (classical, weight-free; through OpenCV's T-API, so on OpenCL where OpenCV can), or
// from OpenCV's pyramidal Lucas–Kanade tracker at the geometric head's sample points only
// (weight-free, sparse; include/inertialnet/models/lk_flow.hpp).
// Rates come from the InertialNet head (learned) and/or the geometric head (weight-free,
// include/inertialnet/models/geometric_head.hpp), named "inertialnet" and "geometric".
#pragma once

#include <map>
#include <optional>

#include "inertialnet/io/camera.hpp"
#include "inertialnet/models/dis_flow.hpp"
#include "inertialnet/models/geometric_head.hpp"
#include "inertialnet/models/head_input.hpp"
#include "inertialnet/models/head_uncertainty.hpp"
#include "inertialnet/models/parameters.hpp"
#include "inertialnet/models/weights.hpp"
#include "inertialnet/pipeline/pipeline.hpp"
#include "inertialnet/pipeline/rate_fusion.hpp"
#include "inertialnet/core/vec3.hpp"

namespace inertialnet {

// LK: sparse, for the geometric head alone (the InertialNet head needs a dense field). DIS and
// DISFine are OpenCV's DIS at two settings (models/dis_flow.hpp, DisVariant): one method each, so
// that a head trained on one is never fed the other.
enum class FlowMethod { FlowNet, DIS, LK, DISFine };
std::string to_string(FlowMethod method);           // "flownet2", "dis", "lk", "dis-fine"
FlowMethod parse_flow_method(const std::string& text);  // invalid_input listing the choices
// Whether the method is DIS at either of its settings, and which.
bool is_dis(FlowMethod method);
DisVariant dis_variant(FlowMethod method);  // DisVariant::Medium for a method that is not DIS

struct RatesProcessorOptions {
  FlowMethod flow = FlowMethod::FlowNet;
  ModelKind flow_model = ModelKind::FlowNet2;  // with FlowMethod::FlowNet
  bool inertialnet_head = true;
  bool geometric_head = false;
  GeometricHeadOptions geometric;
  std::optional<CameraIntrinsics> camera;  // required by the geometric head
  // The geometric head measures ω in the camera frame; with the camera-to-body rotation given
  // (EuRoC's cam0 T_BS), its rates are reported in the body (IMU) frame like the gyro and the
  // InertialNet head, ω_B = R_BS·ω_C.
  std::optional<Mat3> camera_to_body;
  // Download the flow into PairResult::flow (--save-flow); with LK it is known at the tracked grid
  // points only (after the forward-backward check), unknown elsewhere.
  bool keep_flow = false;
  // DIS and LK: also compute the backward flow and leave out (mark unknown) each vector whose
  // round trip misses by more than this many pixels at 752 columns (scaled with the width);
  // 0: no check (include/inertialnet/models/flow_consistency.hpp). 0.5 px was better than no
  // check in every synthetic condition measured (it leaves out 2–4 % of the vectors) and takes
  // the close-range rolling-shutter case at 752×480 from 0.67 1.20 0.92 to 0.41 0.29 0.29
  // deg/s, for a second DIS pass; tighter was better still on synthetic frames but leaves out
  // up to a fifth of the field (docs/real_cameras.md, "Forward-backward flow check"). LK tracks
  // each of its points back (include/inertialnet/models/lk_flow.hpp) with the same setting; with
  // LK the geometric head's sample stride is lk_grid_stride(width), not geometric.stride.
  double flow_check_px = 0.5;
  // The InertialNet head's input convention (models/head_input.hpp, from its metadata): its flow is
  // turned into the head's input by the same head_input() as in training — resized to the head's
  // size whatever the frames' size, and with the normalized convention divided by the pair's
  // interval and the focal lengths of `camera` (then required).
  HeadInput head_input = HeadInput::Paper;
  // Whether the head answers in the camera frame (its metadata, head_input.hpp): its rates (and its
  // σ) are then turned into the body frame by camera_to_body when that is known, as the geometric
  // head's; else they stay in the camera frame.
  bool head_camera_frame = false;
  // A geometric rate whose σ along its least certain direction (the calibrated covariance's
  // largest eigenvalue; at least every per-axis EstimatorRates::sigma, and the same in any frame)
  // exceeds this many rad/s is not reported: the pair gets PairStatus::Uncertain (predict
  // --max-sigma, in deg/s; docs/real_cameras.md, "Confidence per pair"). 0: no limit.
  double max_sigma_rad_s = kDefaultMaxSigmaRadS;
  static constexpr double kDefaultMaxSigmaRadS = 0.174532925199;  // 10 deg/s
  // Issue 23 (predict --fuse): with both heads, the InertialNet head gets its own σ
  // (head_uncertainty.hpp) and a third estimator "fused" follows the two (rate_fusion.hpp). Both
  // heads must answer in the same frame: the geometric one needs camera_to_body.
  bool fuse = false;
  HeadSigmaOptions head_sigma;
  // The geometric σ factor and the heads' error correlation of the head's σ calibration
  // (sigma_calibration.hpp; defaults: plain inverse-variance weights).
  FusionWeights fusion;
  // The InertialNet head's weights hold this many heads (models/head_ensemble.hpp; from the
  // metadata "inertialnet.ensemble"): the reported rates are their mean, and with `fuse` the
  // learned σ comes from their spread (head_sigma's calibration or scale and floor applied to
  // it) instead of Monte-Carlo dropout.
  int ensemble_members = 1;
};

// Each lane gets its own queue and model instances. `weights` holds one set per device, loaded
// beforehand (needed by FlowNet and the InertialNet head; may be empty otherwise); they must
// outlive the pipeline. Throws invalid_input for contradictory options (no head, a geometric
// head without a camera, FlowNet without weights, LK flow for the InertialNet head, fusion without both
// heads and camera_to_body).
ProcessorFactory rates_processor(const std::map<const Device*, const WeightSet*>& weights,
                                 const RatesProcessorOptions& options);

}  // namespace inertialnet
