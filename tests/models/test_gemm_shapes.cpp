// SPDX-License-Identifier: Apache-2.0
// The GEMM shapes `tune` times come from the model's own graph: every conv, deconv and linear
// layer is in exactly one shape, with the sizes of docs/model_spec.md.
#include <algorithm>
#include <set>

#include "inertialnet/models/gemm_shapes.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

const GemmShape* shape_of(const std::vector<GemmShape>& shapes, const std::string& layer) {
  for (const auto& s : shapes) {
    if (std::find(s.layers.begin(), s.layers.end(), layer) != s.layers.end()) return &s;
  }
  return nullptr;
}

TEST(GemmShapes, FollowTheGraphOfFlowNetC) {
  const auto shapes = model_gemm_shapes(ModelKind::FlowNet2C, 128, 64);
  // Every layer with weights is in a shape (the siamese layers of FlowNetC twice: they run twice).
  std::set<std::string> layers;
  for (const auto& s : shapes) layers.insert(s.layers.begin(), s.layers.end());
  std::set<std::string> weighted;
  for (const auto& spec : model_parameters(ModelKind::FlowNet2C)) {
    if (!spec.is_bias) weighted.insert(spec.name.substr(0, spec.name.size() - std::string(".weight").size()));
  }
  EXPECT_EQ(layers, weighted);

  // conv1: 7×7 stride 2 from 3 channels to 64, on 128×64 → 64×32 pixels.
  const GemmShape* conv1 = shape_of(shapes, "conv1.0");
  ASSERT_NE(conv1, nullptr);
  EXPECT_EQ(conv1->m, 64u);
  EXPECT_EQ(conv1->n, 64u * 32u);
  EXPECT_EQ(conv1->k, 3u * 7 * 7);
  // deconv5: 1024 → 512 channels, 4×4, from the 2×1 map of conv6_1: A is Wᵀ [512·16, 1024].
  const GemmShape* deconv5 = shape_of(shapes, "deconv5.0");
  ASSERT_NE(deconv5, nullptr);
  EXPECT_EQ(deconv5->m, 512u * 16);
  EXPECT_EQ(deconv5->n, 2u * 1);
  EXPECT_EQ(deconv5->k, 1024u);
  // Frames are rounded up to multiples of 64, as the network runs them.
  EXPECT_EQ(shape_of(model_gemm_shapes(ModelKind::FlowNet2C, 100, 60), "conv1.0")->n, 64u * 32u);
}

TEST(GemmShapes, HeaviestFirst) {
  const auto all = model_gemm_shapes(ModelKind::FlowNet2, 256, 192);
  const auto top = heaviest_gemm_shapes(all, 3);
  ASSERT_EQ(top.size(), 3u);
  EXPECT_GE(top[0].total_flops(), top[1].total_flops());
  EXPECT_GE(top[1].total_flops(), top[2].total_flops());
  for (const auto& s : all) EXPECT_LE(s.total_flops(), top[0].total_flops());
  EXPECT_EQ(heaviest_gemm_shapes(all, 0).size(), all.size());
  testing::expect_invalid_input([] { model_gemm_shapes(ModelKind::InertialNetHead, 64, 64); }, "head");
}

}  // namespace
}  // namespace inertialnet
