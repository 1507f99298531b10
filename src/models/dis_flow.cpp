#include "inertialnet/models/dis_flow.hpp"

#include <cstdint>
#include <opencv2/core.hpp>
#include <opencv2/video/tracking.hpp>

namespace inertialnet {

namespace {

// 8-bit luminance (BT.601) of a planar RGB frame; a replicated gray frame comes back exactly.
cv::Mat gray8(const HostImage& image) {
  cv::Mat gray(image.height, image.width, CV_8UC1);
  const std::size_t plane = image.plane_size();
  for (int y = 0; y < image.height; ++y) {
    auto* row = gray.ptr<std::uint8_t>(y);
    for (int x = 0; x < image.width; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(image.width) + static_cast<std::size_t>(x);
      const float v = 0.299f * image.data[i] + 0.587f * image.data[plane + i] + 0.114f * image.data[2 * plane + i];
      row[x] = cv::saturate_cast<std::uint8_t>(v);
    }
  }
  return gray;
}

}  // namespace

struct DisFlow::State {
  cv::Ptr<cv::DISOpticalFlow> dis = cv::DISOpticalFlow::create(cv::DISOpticalFlow::PRESET_MEDIUM);
};

DisFlow::DisFlow() : state_(std::make_unique<State>()) {}

DisFlow::~DisFlow() = default;

std::vector<float> DisFlow::compute(const HostImage& first, const HostImage& second) {
  // T-API: UMat lets OpenCV run DIS through its own OpenCL path where it has one.
  cv::UMat a, b, uv;
  gray8(first).copyTo(a);
  gray8(second).copyTo(b);
  state_->dis->calc(a, b, uv);
  cv::Mat planes[2];
  cv::split(uv.getMat(cv::ACCESS_READ), planes);
  std::vector<float> data(2 * first.plane_size());
  std::copy(planes[0].begin<float>(), planes[0].end<float>(), data.begin());
  std::copy(planes[1].begin<float>(), planes[1].end<float>(), data.begin() + static_cast<std::ptrdiff_t>(data.size() / 2));
  return data;
}

}  // namespace inertialnet
