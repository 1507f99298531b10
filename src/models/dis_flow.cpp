// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/models/dis_flow.hpp"

#include <algorithm>
#include <string>

#include <opencv2/core.hpp>
#include <opencv2/video/tracking.hpp>

#include "inertialnet/models/flow_consistency.hpp"
#include "inertialnet/runtime/error.hpp"
#include "models/luminance.hpp"

namespace inertialnet {

namespace {

std::string size_of(const HostImage& image) { return std::to_string(image.width) + "x" + std::to_string(image.height); }

}  // namespace

struct DisFlow::State {
  cv::Ptr<cv::DISOpticalFlow> dis = cv::DISOpticalFlow::create(cv::DISOpticalFlow::PRESET_MEDIUM);
};

DisFlow::DisFlow(DisVariant variant) : state_(std::make_unique<State>()) {
  if (variant == DisVariant::Fine) state_->dis->setFinestScale(0);
}
DisFlow::~DisFlow() = default;

FlowField DisFlow::compute(const HostImage& first, const HostImage& second) {
  if (first.width != second.width || first.height != second.height) {
    throw invalid_input("the frames differ in size: the first is " + size_of(first) + ", the second " +
                        size_of(second) + "; DIS optical flow needs two frames of one size.");
  }
  if (first.width < kDisMinimumSide || first.height < kDisMinimumSide) {
    throw invalid_input("the frames are " + size_of(first) + "; DIS optical flow needs frames of at least " +
                        std::to_string(kDisMinimumSide) + "x" + std::to_string(kDisMinimumSide) + " pixels.");
  }
  if (first.data.size() != 3 * first.plane_size() || second.data.size() != 3 * second.plane_size()) {
    throw invalid_input("a " + size_of(first) + " frame needs " + std::to_string(3 * first.plane_size()) +
                        " values (three planes).");
  }
  // T-API: UMat lets OpenCV run DIS through its own OpenCL path where it has one.
  cv::UMat a, b, uv;
  detail::luminance8(first).copyTo(a);
  detail::luminance8(second).copyTo(b);
  state_->dis->calc(a, b, uv);
  cv::Mat planes[2];
  cv::split(uv.getMat(cv::ACCESS_READ), planes);
  FlowField flow(first.width, first.height);
  std::copy(planes[0].begin<float>(), planes[0].end<float>(), flow.u.begin());
  std::copy(planes[1].begin<float>(), planes[1].end<float>(), flow.v.begin());
  return flow;
}

int DisFlow::check(FlowField& forward, const HostImage& first, const HostImage& second, double px_at_752_columns) {
  require_flow_check_setting(px_at_752_columns);
  if (px_at_752_columns == 0) return 0;
  const FlowField backward = compute(second, first);
  return mark_inconsistent_flow(forward, backward, flow_check_threshold_px(px_at_752_columns, forward.width));
}

int DisFlow::edge_band_px(int width, int height) const {
  if (state_->dis->getFinestScale() != 0) return 0;  // Medium: not yet (dis_flow.hpp)
  return std::max(0, std::min(state_->dis->getPatchSize(), std::min(width, height) / 8));
}

}  // namespace inertialnet
