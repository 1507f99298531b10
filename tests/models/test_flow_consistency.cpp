// SPDX-License-Identifier: Apache-2.0
// The forward-backward check (include/inertialnet/models/flow_consistency.hpp): a consistent
// field is kept whole; a patch whose backward flow disagrees is marked unknown, and only it. The
// edge band: exactly the vectors within the band of an edge are marked, and DIS's band is its
// finest patch.
#include "inertialnet/models/flow_consistency.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <iterator>
#include <string>

#include "inertialnet/models/dis_flow.hpp"
#include "inertialnet/runtime/error.hpp"

namespace inertialnet {
namespace {

// A uniform shift (u, v) and its exact inverse.
FlowField uniform(int w, int h, float u, float v) {
  FlowField f(w, h);
  std::fill(f.u.begin(), f.u.end(), u);
  std::fill(f.v.begin(), f.v.end(), v);
  return f;
}

TEST(FlowConsistency, KeepsAConsistentFieldAndMarksOnlyTheDisagreeingPatch) {
  const int w = 40, h = 30;
  FlowField forward = uniform(w, h, 2.5f, -1.25f);
  FlowField backward = uniform(w, h, -2.5f, 1.25f);
  FlowField copy = forward;
  EXPECT_EQ(mark_inconsistent_flow(copy, backward, 0.5), 0);
  EXPECT_EQ(copy.u, forward.u);
  EXPECT_EQ(copy.v, forward.v);

  // The backward flow is wrong by 3 px in a block: the forward vectors landing in it (one
  // column and row fewer at its near edges, where the bilinear lookup mixes in a good cell)
  // are marked; none elsewhere.
  for (int y = 10; y < 20; ++y)
    for (int x = 20; x < 30; ++x) backward.u[static_cast<std::size_t>(y) * w + x] += 3.0f;
  const int marked = mark_inconsistent_flow(forward, backward, 1.0);
  EXPECT_GT(marked, 0);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      const double qx = x + 2.5, qy = y - 1.25;
      const bool lands_inside = qx >= 20 && qx <= 29 && qy >= 10 && qy <= 19;
      const bool lands_outside = qx < 19 || qx > 30 || qy < 9 || qy > 20;
      if (lands_inside && qx <= w - 1 && qy >= 0) {
        EXPECT_TRUE(is_unknown_flow(forward.u[i], forward.v[i])) << x << "," << y;
      }
      if (lands_outside) {
        EXPECT_FALSE(is_unknown_flow(forward.u[i], forward.v[i])) << x << "," << y;
      }
    }
  }
}

TEST(FlowConsistency, LeavesVectorsThatLeaveTheImageAndRejectsBadArguments) {
  FlowField forward = uniform(20, 20, 30.0f, 0.0f);  // every vector leaves the frame
  FlowField backward = uniform(20, 20, 5.0f, 5.0f);
  EXPECT_EQ(mark_inconsistent_flow(forward, backward, 1.0), 0);
  FlowField other = uniform(21, 20, 0.0f, 0.0f);
  EXPECT_THROW(mark_inconsistent_flow(forward, other, 1.0), Error);
  EXPECT_THROW(mark_inconsistent_flow(forward, backward, 0.0), Error);
}

// The setting had no upper bound: 1e300 switched the check off silently. Bounded at 1000 px
// (at 752 columns), the value quoted as given and the setting named as the caller names it.
TEST(FlowConsistency, RefusesACheckSettingAboveTheBoundQuotingIt) {
  EXPECT_NO_THROW(require_flow_check_setting(0.0));
  EXPECT_NO_THROW(require_flow_check_setting(1000.0));
  for (const double bad : {1e300, 1000.5, -1.0}) {
    try {
      require_flow_check_setting(bad, "flow_check");
      ADD_FAILURE() << bad << " was taken";
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::InvalidInput);
      EXPECT_NE(std::string(e.what()).find("flow_check should be from 0 (off) to 1000 pixels"), std::string::npos)
          << e.what();
    }
  }
  try {
    require_flow_check_setting(1e300);
    ADD_FAILURE() << "1e300 was taken";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("the flow check threshold should be"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("got 1e+300"), std::string::npos) << e.what();
  }
}

// An odd-sized field with a few vectors already unknown: a band of b marks every vector whose
// column is below b or above w − 1 − b, or whose row is likewise, and nothing else; the count is
// of the vectors it turned unknown, not of those that were already.
TEST(FlowEdgeBand, MarksExactlyTheBandAndCountsTheVectorsItTurnedUnknown) {
  const int w = 23, h = 17;
  for (const int band : {0, 1, 3, 8, 9, 40}) {
    const auto in_band = [&](int x, int y) { return x < band || x > w - 1 - band || y < band || y > h - 1 - band; };
    FlowField f = uniform(w, h, 0.75f, -2.0f);
    const std::size_t pre[] = {0, 5 * w + 11, 16 * w + 22};  // a corner, the middle, the far corner
    for (const std::size_t i : pre) f.u[i] = f.v[i] = kUnknownFlowValue;
    int expected = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * w + x;
        if (in_band(x, y) && std::find(std::begin(pre), std::end(pre), i) == std::end(pre)) ++expected;
      }
    FlowField marked = f;
    EXPECT_EQ(mark_flow_edge_band(marked, band), expected) << "band " << band;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * w + x;
        if (in_band(x, y)) {
          EXPECT_TRUE(is_unknown_flow(marked.u[i], marked.v[i])) << band << ": " << x << "," << y;
        } else {
          EXPECT_EQ(marked.u[i], f.u[i]) << band << ": " << x << "," << y;
          EXPECT_EQ(marked.v[i], f.v[i]) << band << ": " << x << "," << y;
        }
      }
  }
  FlowField f = uniform(5, 4, 1.0f, 1.0f);
  try {
    mark_flow_edge_band(f, -1);
    ADD_FAILURE() << "a band of -1 was taken";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::InvalidInput);
    EXPECT_NE(std::string(e.what()).find("got -1"), std::string::npos) << e.what();
  }
}

// dis-fine's band is the side of its 8×8 patches, capped at an eighth of the shorter side; the
// MEDIUM preset has none yet (its σ model was fitted without one: dis_flow.hpp).
TEST(FlowEdgeBand, DisFineBandIsItsPatchCappedForSmallFramesAndMediumHasNone) {
  const DisFlow fine(DisVariant::Fine), medium(DisVariant::Medium);
  EXPECT_EQ(fine.edge_band_px(752, 480), 8);
  EXPECT_EQ(fine.edge_band_px(188, 120), 8);
  EXPECT_EQ(fine.edge_band_px(64, 48), 6);
  EXPECT_EQ(fine.edge_band_px(16, 16), 2);
  EXPECT_EQ(medium.edge_band_px(752, 480), 0);
  EXPECT_EQ(medium.edge_band_px(188, 120), 0);
}

}  // namespace
}  // namespace inertialnet
