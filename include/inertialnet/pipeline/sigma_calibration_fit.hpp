// SPDX-License-Identifier: Apache-2.0
// Fitting a trained head's σ calibration on validation sequences and storing it in the head's
// metadata (issue 23, fusion; the calibration itself: models/sigma_calibration.hpp).
//
// Each sequence is predicted as `predict SEQ -w HEAD --head both --fuse --smooth off` would, with
// the learned head's raw Monte-Carlo dropout spread in place of its σ, and evaluated as
// `eval --target mean` does (gyro − bias over each pair's interval, in the body frame). Every pair
// the learned head answered is a sample; where the geometric head answered too (its status ok,
// --max-sigma as given) it adds the geometric error and σ. The sequences therefore need what
// --fuse needs: the camera-to-body rotation (EuRoC's T_BS, or a calibration with extrinsics), and
// a gyro with its bias known (ground truth or a static start).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "inertialnet/models/sigma_calibration.hpp"
#include "inertialnet/pipeline/predict.hpp"

namespace inertialnet {

// `base` carries the weights (the head first), the device and the other predict settings;
// sequence, head, fuse, smooth and the σ model are set here. `scratch` is a folder for the
// intermediate rates files (created; left in place).
std::vector<SigmaFitSample> sigma_fit_samples(const PredictSettings& base,
                                              const std::vector<std::filesystem::path>& sequences,
                                              const std::filesystem::path& scratch);

// Rewrites the head file `path` with the calibration in its metadata (kMetadataSigmaCalibration,
// replacing one there), every tensor and every other metadata entry unchanged; atomically.
void write_sigma_calibration(const std::string& path, const SigmaCalibration& calibration);

}  // namespace inertialnet
