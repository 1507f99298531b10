// SPDX-License-Identifier: Apache-2.0
// The camera–IMU rotation correction, fitted on the recording: the small rotation R that best
// maps the predicted rates (already rotated into the IMU frame with the calibration's camera–IMU
// rotation) onto the gyro, ω_imu ≈ R · ω_pred + b. A calibration a few degrees off (issue 22
// found ≈ 5° on a hand-held rig) otherwise leaks a share of every axis's rate into the others.
//
// Meaning: R corrects the calibration's body-from-camera rotation, R_BS,true = R · R_BS (T_BS's
// rotation, or the inverse of --T-cam-imu's). It is reported as a rotation vector (axis · angle)
// in the IMU frame, in degrees; eval --rotation-correction applies the same vector.
//
// Estimation (Kabsch / Procrustes): with both sides centred (the constant b, a gyro bias the
// images cannot see, drops out), R = argmin Σ |R p̃_i − g̃_i|² is the rotation of the SVD of
// Σ g̃_i p̃_iᵀ, with the sign fixed so that det R = +1. It is exact, not linearised, so a start
// point is not needed.
//
// Uncertainty: linearising R ← Exp(δ)·R, the residual changes by −[R p̃_i]×·δ; the normal matrix
// H = Σ (|q_i|² I − q_i q_iᵀ), q_i = R p̃_i, measures the excitation about each axis (a rotation
// about an axis the camera never turned about is not seen in the rates), and the covariance of δ
// is σ² H⁻¹ with σ² the residual variance left (cost / (3N − 7): bias, rotation and the time
// offset fitted with it). Pair errors that are correlated in time make this optimistic; an
// excitation below `kMinExcitation` leaves the fit undetermined instead.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "inertialnet/core/vec3.hpp"

namespace inertialnet {

struct RotationFit {
  Mat3 rotation{1, 0, 0, 0, 1, 0, 0, 0, 1};  // ω_imu ≈ rotation · ω_pred
  Vec3 rotation_vector_deg{};                // Log(rotation), IMU frame
  Vec3 std_error_deg{};                      // 1σ of each component of the rotation vector
  double angle_deg = 0;                      // |rotation_vector_deg|
  double angle_std_error_deg = 0;            // 1σ of the angle: sqrt of the covariance's largest eigenvalue
  // The RMS rate (deg/s) about the least excited axis: sqrt(λ_min(H) / N). Small: a rotation
  // about that axis barely shows in the rates.
  double min_excitation_deg_s = 0;
  std::size_t pairs = 0;
  double rmse_deg_s = 0;           // per-axis RMS residual after the fit (centred)
  double rmse_before_deg_s = 0;    // the same with R = I
  bool determined = true;
  std::string undetermined_reason;
  std::string summary() const;     // one line for reports
  // The verdict: "none" (not determined); "low" (the angle's 1σ above kLowRotationStdErrorDeg);
  // "high" (below kHighRotationStdErrorDeg, so that 2σ stays within the 0.5° a calibration check
  // asks for, issue 22); else "medium". calibrate rates it no higher than the offset it was
  // fitted at (a rotation fitted at a wrong offset absorbs timing error).
  std::string confidence() const;
};

inline constexpr double kLowRotationStdErrorDeg = 1.0;
inline constexpr double kHighRotationStdErrorDeg = 0.25;

// Rates below this excitation (deg/s about the least excited axis) fix no rotation about it.
inline constexpr double kMinRotationExcitationDegS = 0.5;

// `predicted[i]`, `gyro[i]`: pair i's predicted rate (IMU frame) and its gyro target (rad/s).
// Throws invalid_input when the sizes differ or fewer than 3 pairs are given.
RotationFit fit_rotation(const std::vector<Vec3>& predicted, const std::vector<Vec3>& gyro);

// Exp(rotation vector in degrees) as a matrix, and its inverse map.
Mat3 rotation_from_vector_deg(const Vec3& rotation_vector_deg);

}  // namespace inertialnet
