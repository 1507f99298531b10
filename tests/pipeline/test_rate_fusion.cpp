// SPDX-License-Identifier: Apache-2.0
// The fusion rule of predict --fuse (include/inertialnet/pipeline/rate_fusion.hpp): inverse-
// variance weights per axis with both heads, one head's answer and σ with one, no answer with
// neither.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "inertialnet/pipeline/rate_fusion.hpp"

namespace inertialnet {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

EstimatorRates ok(const char* name, std::array<double, 3> w, std::array<double, 3> sigma) {
  EstimatorRates r;
  r.name = name;
  r.w = w;
  r.sigma = sigma;
  return r;
}

EstimatorRates not_ok(const char* name, PairStatus status, const char* reason, double sigma = kNan) {
  EstimatorRates r;
  r.name = name;
  r.status = status;
  r.reason = reason;
  r.w = {kNan, kNan, kNan};
  r.sigma = {sigma, sigma, sigma};
  return r;
}

TEST(RateFusion, BothOkWeighsEachAxisByItsInverseVariance) {
  // x: σ 1 and 1 → the mean; y: σ 1 and 3 → weights 9:1; z: the learned head far less sure.
  const EstimatorRates learned = ok("inertialnet", {1.0, 2.0, 10.0}, {0.1, 0.1, 1.0});
  const EstimatorRates geometric = ok("geometric", {3.0, 12.0, 0.0}, {0.1, 0.3, 0.01});
  const EstimatorRates f = fuse_rates(learned, geometric);
  EXPECT_EQ(f.name, "fused");
  EXPECT_EQ(f.status, PairStatus::Ok);
  EXPECT_NEAR(f.w[0], 2.0, 1e-12);
  EXPECT_NEAR(f.sigma[0], 0.1 / std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(f.w[1], (9 * 2.0 + 1 * 12.0) / 10, 1e-12);
  EXPECT_NEAR(f.sigma[1], 1 / std::sqrt(100.0 + 100.0 / 9), 1e-12);
  EXPECT_NEAR(f.w[2], (1 * 10.0 + 10000 * 0.0) / 10001, 1e-12);
  for (std::size_t a = 0; a < 3; ++a) {
    EXPECT_LE(f.sigma[a], std::min(learned.sigma[a], geometric.sigma[a])) << a;
  }
}

TEST(RateFusion, OneHeadOkGivesItsAnswerAndSigma) {
  const EstimatorRates learned = ok("inertialnet", {0.5, -0.25, 0.125}, {0.02, 0.03, 0.04});
  // The geometric head too uncertain to report (σ kept, rates NaN): the learned head alone.
  const EstimatorRates uncertain = not_ok("geometric", PairStatus::Uncertain, "σ above --max-sigma", 0.5);
  EstimatorRates f = fuse_rates(learned, uncertain);
  EXPECT_EQ(f.status, PairStatus::Ok);
  EXPECT_EQ(f.w, learned.w);
  EXPECT_EQ(f.sigma, learned.sigma);
  // The other way round: no texture for the network's flow is no texture for either, but a
  // learned head whose output was not finite leaves the geometric answer.
  const EstimatorRates geometric = ok("geometric", {0.1, 0.2, 0.3}, {0.01, 0.01, 0.02});
  f = fuse_rates(not_ok("inertialnet", PairStatus::NonFinite, "NaN"), geometric);
  EXPECT_EQ(f.status, PairStatus::Ok);
  EXPECT_EQ(f.w, geometric.w);
  EXPECT_EQ(f.sigma, geometric.sigma);
}

TEST(RateFusion, AnOkHeadWithoutSigmaCannotBeWeighed) {
  const EstimatorRates no_sigma = ok("inertialnet", {9.0, 9.0, 9.0}, {kNan, kNan, kNan});
  const EstimatorRates geometric = ok("geometric", {0.1, 0.2, 0.3}, {0.01, 0.01, 0.02});
  EXPECT_EQ(fuse_rates(no_sigma, geometric).w, geometric.w);
  const EstimatorRates f = fuse_rates(no_sigma, ok("geometric", {0.1, 0.2, 0.3}, {kNan, 0.01, 0.01}));
  EXPECT_EQ(f.status, PairStatus::Uncertain);
  EXPECT_NE(f.reason.find("its σ is not known"), std::string::npos) << f.reason;
}

TEST(RateFusion, NeitherOkIsNoAnswerWithBothReasons) {
  const EstimatorRates f = fuse_rates(not_ok("inertialnet", PairStatus::NonFinite, "NaN output"),
                                      not_ok("geometric", PairStatus::TooFewVectors, "only 5 flow vectors"));
  EXPECT_EQ(f.status, PairStatus::TooFewVectors);  // the geometric head's: it says more about the pair
  EXPECT_FALSE(f.ok());
  for (std::size_t a = 0; a < 3; ++a) {
    EXPECT_TRUE(std::isnan(f.w[a]));
    EXPECT_TRUE(std::isnan(f.sigma[a]));
  }
  EXPECT_NE(f.reason.find("NaN output"), std::string::npos) << f.reason;
  EXPECT_NE(f.reason.find("only 5 flow vectors"), std::string::npos) << f.reason;
}

}  // namespace
}  // namespace inertialnet
