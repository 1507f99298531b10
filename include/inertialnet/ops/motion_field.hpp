// SPDX-License-Identifier: Apache-2.0
// The motion-field reductions (kernels_cl/motion_field.cl): the two passes over a dense flow
// field that the geometric head's solvers need (include/inertialnet/models/geometric_head.hpp).
//
// Both visit a strided grid of flow vectors. For one grid sample with flow vector (du, dv) at
// pixel (u, v): the normalised coordinates of its two ends p1 = map(u, v) and
// p2 = map(u + du, v + dv) (bilinear in the camera's coordinate map,
// inertialnet/io/camera.hpp), midpoint (x, y) = (p1 + p2)/2, image velocity b = (p2 − p1)/dt.
// A sample is usable when the flow is known (is_unknown_flow() false) and (u + du, v + dv) lies
// within the image ([0, W−1] × [0, H−1]).
//
// The moments. The residual at the current ω is r = b − A(x, y)·ω, with A's columns a1, a2, a3
// (ẋ, ẏ per unit ωx, ωy, ωz; docs/data_conventions.md). ψ(e) is the loss's weight: 1 (least
// squares), min(1, σ/e) (Huber), 1/(1 + (e/σ)²) (Cauchy), (1 − (e/(4.685·σ))²)² below 4.685·σ
// and 0 above (Tukey's biweight; 4.685 gives 95 % efficiency under Gaussian noise of
// deviation σ).
//
// Rotation mode: e = |r|, weight w = ψ(e); normal = Σ w·AᵀA, rhs = Σ w·Aᵀb (so ω = normal⁻¹·rhs).
//
// General mode: with n(T) = M·T, M = [[0, 1, −y], [−1, 0, x]] (n ⊥ the translational flow
// direction d = (n_y, −n_x)), the ρ-free residual of an increment Δω is
//   s = n̂ᵀ(r − A·Δω),  and  nᵀ(r − A·Δω) = Tᵀ(c_r − Σ_j Δω_j·c_j)  with c = Mᵀ·(column),
// i.e. s·|n| is bilinear in (T, Δω). The kernel accumulates the Gram matrix of
// v = (c1, c2, c3, c_r) ∈ R¹² so that the host can evaluate the cost of ANY T (and solve for
// Δω) without another pass over the flow:
//   Σ w·(s·|n|)² = (u ⊗ T)ᵀ·gram·(u ⊗ T),  u = (−Δω, 1),  (u ⊗ T)_{3k+a} = u_k·T_a.
// With the current T ≠ 0: e = |n̂ᵀr|, w = ψ(e)/max(|n|², 0.01) (so the quadratic form is the
// normalised cost near the current T, with the few pixels next to the focus of expansion
// capped); samples with |n|² < 1e-12 are usable but weightless. With T = 0 (the first pass):
// e = |r|, w = ψ(e).
// metric = Σ w·MᵀM, so that Σ w·|n(T)|² = Tᵀ·metric·T normalises the cost of a candidate T.
//
// Reductions: each work-item sums its few samples in float, each work-group adds its
// work-items in a tree, and the host adds the ≤ 64 work-group partials in double, so no float
// sum runs long enough to need compensated summation.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "inertialnet/core/vec3.hpp"
#include "inertialnet/runtime/queue.hpp"
#include "inertialnet/runtime/tensor.hpp"

namespace inertialnet {

enum class RobustLoss { LeastSquares = 0, Huber = 1, Cauchy = 2, Tukey = 3 };
std::string to_string(RobustLoss loss);  // "least-squares", "huber", "cauchy", "tukey"

enum class MotionFieldMode { Rotation = 0, General = 1 };

struct MotionFieldParams {
  MotionFieldMode mode = MotionFieldMode::Rotation;
  RobustLoss loss = RobustLoss::LeastSquares;
  Vec3 omega{};           // current estimate, rad/s
  Vec3 translation{};     // current translation direction (General mode), any scale; 0: none
  double dt = 0;          // seconds
  double scale = 1;       // σ, normalised image velocity (1/s)
  double inlier_threshold = 1;  // same units
  int stride = 4;
};

struct MotionFieldMoments {
  // Rotation mode.
  std::array<double, 6> normal{};  // 00 01 02 11 12 22
  Vec3 rhs{};
  // General mode.
  std::array<double, 78> gram{};   // upper triangle of the 12×12 Gram matrix, row by row
  std::array<double, 6> metric{};  // 00 01 02 11 12 22
  // Both modes.
  double weight_sum = 0;           // Σ ψ(e)
  double weighted_sq_residual = 0; // Σ ψ(e)·e²
  double inliers = 0;              // count of usable samples with e < inlier_threshold
  double inlier_sq_residual = 0;   // Σ e² over those
  double usable = 0;               // count of usable samples
  double loss_sum = 0;             // Σ ρ(e), the loss whose derivative over e is ψ(e)·e:
                                   // e²/2, Huber's, (σ²/2)·ln(1 + (e/σ)²), Tukey's (c²/6)·(1 − (1 − (e/c)²)³)
  // General mode with T ≠ 0, over the inliers: the residual along the translational flow
  // direction, par = d̂ᵀr (ρ·|d| for a static point; > 0 when T's sign gives positive depth).
  double parallel_sum = 0;
  double parallel_sq = 0;
};

// Grid geometry shared by the kernels, the host and the reference: samples at
// (first + i·stride, first + j·stride), first = stride/2.
struct SampleGrid {
  int first = 0, columns = 0, rows = 0;
  static SampleGrid of(int width, int height, int stride);
  int count() const { return columns * rows; }
};

// One sampled correspondence in normalised coordinates: the ray through (x1, y1, 1) at t−1 and
// through (x2, y2, 1) at t.
struct NormalizedCorrespondence {
  float x1, y1, x2, y2;
};

// One reduction pass over `flow` [1, 2, H, W] (u then v, pixels; a channel slice of a larger
// tensor is fine) with `map` the camera's normalised-coordinate map [1, 2, H, W]. Only the
// work-group partial sums come back to the host. Throws invalid_input for undefined or
// mismatched tensors, a non-positive dt or a stride below 1.
MotionFieldMoments motion_field_moments(Queue& queue, const Tensor& flow, const Tensor& map,
                                        const MotionFieldParams& params);

// The ends of every grid sample of `flow`, looked up once: a device tensor [samples, 4] of
// (x1, y1, x2, y2) in grid order, NaN in all four for an unusable sample. For the many passes of
// one flow (the geometric head's solvers run 20–50): motion_field_moments_of_ends then reads
// these instead of the flow and the map.
Tensor motion_field_ends(Queue& queue, const Tensor& flow, const Tensor& map, int stride);

// motion_field_moments over the ends motion_field_ends wrote (params.stride is not used: the
// ends are of the stride they were made with). The same sums, in the same order, as
// motion_field_moments on that flow. Throws invalid_input for an undefined tensor or one not
// [N, 4], and a non-positive dt.
MotionFieldMoments motion_field_moments_of_ends(Queue& queue, const Tensor& ends, const MotionFieldParams& params);

// The usable grid samples of `flow` as normalised correspondences, in grid order (row-major);
// only the sampled correspondences come back to the host.
std::vector<NormalizedCorrespondence> motion_field_correspondences(Queue& queue, const Tensor& flow, const Tensor& map,
                                                                   int stride);

}  // namespace inertialnet
