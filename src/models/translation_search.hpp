// SPDX-License-Identifier: Apache-2.0
// The general model's search for the translation direction T (the motion-field solver's stage 2,
// src/models/motion_field_solver.cpp): the quadratic form one General-mode reduction pass
// yields, and the searches over the half sphere of directions that minimise it. Private to the
// geometric head.
#pragma once

#include <array>
#include <vector>

#include <Eigen/Dense>

#include "inertialnet/ops/motion_field.hpp"

namespace inertialnet::detail {

// How far one pass may move T (rad, ≈6°); see refine_translation().
constexpr double kTrustRadius = 0.1;

// The symmetric 3×3 matrix of an upper triangle stored 00 01 02 11 12 22.
Eigen::Matrix3d symmetric(const std::array<double, 6>& u);

// Throws invalid_input unless the 3×3 system is well posed (its eigenvalues span less than 1e12).
void check_conditioning(const Eigen::Matrix3d& n);

// The General-mode quadratic form of one pass: for a candidate T, the normalised cost
// min over Δω of Σ w·(s·|n|)² / Σ w·|n|², and the Δω that attains it.
class GeneralQuadratic {
 public:
  explicit GeneralQuadratic(const MotionFieldMoments& m);

  // The normalised cost of T (infinity where it is undefined), and the Δω that attains it.
  double cost(const Eigen::Vector3d& t, Eigen::Vector3d* delta_omega = nullptr) const;

  // Throws invalid_input unless T determines Δω.
  void check(const Eigen::Vector3d& t) const { check_conditioning(h33(t)); }

  // How significant the step Δω is: its squared Mahalanobis length under the covariance of
  // the estimate, (normalised cost)·H₃₃⁻¹. Below 0.01 the step is a tenth of a standard error.
  double significance(const Eigen::Vector3d& t, const Eigen::Vector3d& dw) const;

  // The covariance of ω at the solution T (unit), from this pass's Gram matrix (the pass at the
  // final ω, T and σ): Gauss-Newton over (Δω, ΔT in T's tangent plane), T's two degrees of
  // freedom marginalised out (the Schur complement), scaled by the residual variance
  // Σψ·s² / (Σψ − 5) with Σψ = `weight_sum`. Raw: it treats the flow vectors as independent
  // (motion_field_solver.cpp inflates it). A zero matrix when it is not defined.
  Eigen::Matrix3d omega_covariance(const Eigen::Vector3d& t, double weight_sum) const;

 private:
  Eigen::Matrix3d h33(const Eigen::Vector3d& t) const;

  Eigen::Matrix<double, 12, 12> gram_;
  Eigen::Matrix3d metric_;
};

// Local pattern search for the best T in the tangent plane of `start`, within `radius` (rad).
Eigen::Vector3d refine_translation(const GeneralQuadratic& q, const Eigen::Vector3d& start, double radius);

// `count` directions spread evenly over the upper half sphere (a Fibonacci lattice; T and −T
// give the same constraint).
std::vector<Eigen::Vector3d> half_sphere_lattice(int count);

// The best T of the whole half sphere: the best point of a lattice, refined.
Eigen::Vector3d global_translation(const GeneralQuadratic& q);

}  // namespace inertialnet::detail
