// SPDX-License-Identifier: Apache-2.0
// The motion-field reductions (ops/motion_field) against the plain C++ reference
// (tests/reference/motion_field), on exact flow of a known motion with every kind of sample.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "inertialnet/io/camera.hpp"
#include "inertialnet/ops/motion_field.hpp"
#include "inertialnet/runtime/error.hpp"
#include "reference/motion_field.hpp"
#include "support/motion_fields.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

using namespace testing;  // the motion fields of tests/support/motion_fields.hpp

// A flow with every kind of sample: a general motion with outliers, unknown vectors (NaN and
// Middlebury's 1e10) and vectors that leave the image.
FlowField awkward_flow(const CameraIntrinsics& k, const std::vector<float>& map) {
  Motion m;
  m.omega = kRates[0];
  m.velocity = kVelocities[0];
  FlowField f = render(k, map, m);
  for (std::size_t i = 0; i < f.pixel_count(); i += 97) f.u[i] = std::nanf("");
  for (std::size_t i = 13; i < f.pixel_count(); i += 89) f.v[i] = kUnknownFlowValue;
  for (int v = 0; v < k.height; v += 7) f.u_at(k.width - 2, v) = 5.0f;  // ends outside
  for (int u = 0; u < k.width; u += 5) f.v_at(u, 1) = -3.0f;
  return f;
}

// Relative difference against a scale: |a − b| / (|b| + floor).
double rel(double a, double b, double floor) { return std::fabs(a - b) / (std::fabs(b) + floor); }

TEST(MotionFieldMoments, MatchTheReferenceInEveryModeAndLoss) {
  Queue& queue = testing::test_queue();
  const CameraIntrinsics k = quarter_euroc();
  const std::vector<float> map = normalized_coordinate_map(k);
  const Tensor map_tensor = upload_map(queue, k, map);
  const FlowField flow = awkward_flow(k, map);
  // The flow as channels 1–2 of a 4-channel tensor, so the kernel must honour the offset.
  std::vector<float> wide(4 * flow.pixel_count(), 7.0f);
  std::copy(flow.u.begin(), flow.u.end(), wide.begin() + static_cast<std::ptrdiff_t>(flow.pixel_count()));
  std::copy(flow.v.begin(), flow.v.end(), wide.begin() + 2 * static_cast<std::ptrdiff_t>(flow.pixel_count()));
  const Tensor all = Tensor::from_host(queue, {1, 4, k.height, k.width}, wide);
  const Tensor slice = all.channels(1, 2);

  for (MotionFieldMode mode : {MotionFieldMode::Rotation, MotionFieldMode::General}) {
    for (RobustLoss loss : {RobustLoss::LeastSquares, RobustLoss::Huber, RobustLoss::Cauchy, RobustLoss::Tukey}) {
      for (int stride : {1, 3}) {
        for (bool with_t : {false, true}) {
          if (with_t && mode == MotionFieldMode::Rotation) continue;
          SCOPED_TRACE("mode " + std::to_string(static_cast<int>(mode)) + ", loss " + to_string(loss) + ", stride " +
                       std::to_string(stride) + (with_t ? ", T given" : ", T = 0"));
          MotionFieldParams p;
          p.mode = mode;
          p.loss = loss;
          p.omega = {-0.3, 0.5, 0.2};
          p.translation = with_t ? Vec3{0.2, -0.1, 0.9} : Vec3{0, 0, 0};
          p.dt = 0.05;
          p.scale = 0.08;            // ≈0.5 px in normalised image velocity
          p.inlier_threshold = 0.3;  // ≈2 px
          p.stride = stride;
          const MotionFieldMoments from_flow = motion_field_moments(queue, slice, map_tensor, p);
          const MotionFieldMoments want = reference::motion_field_moments(flow, map, p);
          // The same sums from the ends looked up once (motion_field_ends): the same samples in
          // the same order, so the same floats; and both against the reference below.
          const MotionFieldMoments of_ends =
              motion_field_moments_of_ends(queue, motion_field_ends(queue, slice, map_tensor, stride), p);
          EXPECT_EQ(of_ends.usable, from_flow.usable);
          EXPECT_NEAR(of_ends.weight_sum, from_flow.weight_sum, 1e-9 * std::fabs(from_flow.weight_sum));
          for (int i = 0; i < 78; ++i) EXPECT_NEAR(of_ends.gram[i], from_flow.gram[i], 1e-9 * std::fabs(from_flow.gram[i])) << i;
          for (int i = 0; i < 6; ++i) EXPECT_NEAR(of_ends.normal[i], from_flow.normal[i], 1e-9 * std::fabs(from_flow.normal[i])) << i;
          for (const MotionFieldMoments& got : {from_flow, of_ends}) {
          // Counts are exact; the sample set must be the same one.
          EXPECT_EQ(got.usable, want.usable);
          EXPECT_GT(want.usable, 0.9 * SampleGrid::of(k.width, k.height, stride).count());
          EXPECT_LT(want.usable, SampleGrid::of(k.width, k.height, stride).count());
          // Float sums of ≈20k terms against double: ≈1e-5 relative; the inlier count may differ
          // by the few samples within float rounding of the threshold.
          EXPECT_NEAR(got.inliers, want.inliers, 2 + 1e-4 * want.inliers);
          const double scale = want.weight_sum;  // the size of a typical sum
          EXPECT_LT(rel(got.weight_sum, want.weight_sum, 1), 1e-4);
          EXPECT_LT(rel(got.weighted_sq_residual, want.weighted_sq_residual, 1e-3 * scale), 1e-4);
          EXPECT_LT(rel(got.loss_sum, want.loss_sum, 1e-3 * scale), 1e-4);
          if (mode == MotionFieldMode::Rotation) {
            for (int i = 0; i < 6; ++i) EXPECT_LT(rel(got.normal[i], want.normal[i], 1e-3 * scale), 1e-4) << i;
            for (int i = 0; i < 3; ++i) EXPECT_LT(rel(got.rhs[i], want.rhs[i], 1e-3 * scale), 1e-4) << i;
          } else {
            // The Gram matrix holds products of velocities weighted by up to 1/0.01: compared
            // against its largest entry (cancellation in float across ≈20k terms).
            double largest = 0;
            for (double g : want.gram) largest = std::max(largest, std::fabs(g));
            for (int i = 0; i < 78; ++i) EXPECT_LT(std::fabs(got.gram[i] - want.gram[i]) / largest, 2e-5) << i;
            for (int i = 0; i < 6; ++i) EXPECT_LT(rel(got.metric[i], want.metric[i], 1e-3 * scale), 1e-4) << i;
            if (with_t) {
              EXPECT_LT(rel(got.parallel_sq, want.parallel_sq, 1e-3 * scale), 1e-3);
              EXPECT_NEAR(got.parallel_sum, want.parallel_sum, 1e-3 * std::sqrt(want.parallel_sq * want.inliers) + 1e-6);
            }
          }
          }
        }
      }
    }
  }
}

TEST(MotionFieldMoments, OfEndsRefusesATensorThatIsNotEnds) {
  Queue& queue = testing::test_queue();
  MotionFieldParams p;
  p.dt = 0.05;
  const Tensor flat = Tensor::from_host(queue, {1, 2, 4, 4}, std::vector<float>(32, 0.0f));
  EXPECT_THROW(motion_field_moments_of_ends(queue, flat, p), Error);
  const Tensor ends = Tensor::from_host(queue, {2, 4}, std::vector<float>(8, 0.1f));
  p.dt = 0;
  EXPECT_THROW(motion_field_moments_of_ends(queue, ends, p), Error);
}

TEST(MotionFieldMoments, CorrespondencesMatchTheReference) {
  Queue& queue = testing::test_queue();
  const CameraIntrinsics k = quarter_euroc();
  const std::vector<float> map = normalized_coordinate_map(k);
  const FlowField flow = awkward_flow(k, map);
  const auto got = motion_field_correspondences(queue, upload(queue, flow), upload_map(queue, k, map), 2);
  const auto want = reference::motion_field_correspondences(flow, map, 2);
  ASSERT_EQ(got.size(), want.size());
  double worst = 0;
  for (std::size_t i = 0; i < got.size(); ++i) {
    const float diffs[4] = {got[i].x1 - want[i].x1, got[i].y1 - want[i].y1, got[i].x2 - want[i].x2, got[i].y2 - want[i].y2};
    for (float d : diffs) worst = std::max(worst, static_cast<double>(std::fabs(d)));
  }
  EXPECT_LT(worst, 1e-6);  // float bilinear interpolation of values ≤ 1
}

}  // namespace
}  // namespace inertialnet
