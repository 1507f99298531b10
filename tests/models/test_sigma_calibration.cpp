// SPDX-License-Identifier: Apache-2.0
// A head's σ calibration (include/inertialnet/models/sigma_calibration.hpp) and the fusion that
// uses it (include/inertialnet/pipeline/rate_fusion.hpp): the fit recovers a planted σ model,
// geometric factor and error correlation; the JSON round-trips; bad metadata values are refused
// naming the file, the key and the value (exit 2 in the CLI); the head's σ applies the
// calibration; and on correlated synthetic errors the generalised least-squares fusion beats both
// heads on every axis where the independent inverse-variance rule does not.
#include <array>
#include <cmath>
#include <filesystem>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "inertialnet/io/safetensors.hpp"
#include "inertialnet/io/safetensors_writer.hpp"
#include "inertialnet/models/head_uncertainty.hpp"
#include "inertialnet/models/sigma_calibration.hpp"
#include "inertialnet/pipeline/rate_fusion.hpp"
#include "inertialnet/runtime/error.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

// Samples with σ_learned = hypot(scale·s, floor) per axis, a geometric σ that is `factor` times
// too small, and errors of correlation rho between the two normalised errors.
std::vector<SigmaFitSample> planted(std::size_t n, const std::array<double, 3>& scale,
                                    const std::array<double, 3>& floor, const std::array<double, 3>& factor,
                                    const std::array<double, 3>& rho, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> spread(0.0, 0.05), geometric_sigma(0.005, 0.03);
  std::vector<SigmaFitSample> out(n);
  for (auto& s : out) {
    s.geometric = true;
    for (std::size_t a = 0; a < 3; ++a) {
      s.spread[a] = spread(rng);
      s.geometric_sigma[a] = geometric_sigma(rng);
      const double z1 = normal(rng), z2 = rho[a] * z1 + std::sqrt(1 - rho[a] * rho[a]) * normal(rng);
      s.learned_error[a] = std::hypot(scale[a] * s.spread[a], floor[a]) * z1;
      s.geometric_error[a] = factor[a] * s.geometric_sigma[a] * z2;
    }
  }
  return out;
}

TEST(SigmaCalibration, FitRecoversAPlantedSigmaModelFactorAndCorrelation) {
  const std::array<double, 3> scale{1.0, 2.5, 0.5}, floor{0.02, 0.01, 0.04}, factor{0.5, 1.0, 2.0},
      rho{0.0, 0.4, -0.3};
  const SigmaCalibration c = fit_sigma_calibration(planted(40000, scale, floor, factor, rho, 7));
  ASSERT_TRUE(c.has_geometric);
  EXPECT_EQ(c.pairs, 40000u);
  for (std::size_t a = 0; a < 3; ++a) {
    SCOPED_TRACE(a);
    EXPECT_NEAR(c.scale[a], scale[a], 0.06 * scale[a]);
    EXPECT_NEAR(c.floor_rad_s[a], floor[a], 0.04 * floor[a]);
    EXPECT_NEAR(c.geometric_scale[a], factor[a], 0.02 * factor[a]);
    EXPECT_NEAR(c.correlation[a], rho[a], 0.02);
  }
}

TEST(SigmaCalibration, ConstantSigmaWhenTheSpreadDoesNotFollowTheError) {
  // Errors of σ 0.03 whatever the spread: no scale, the floor is the errors' RMS.
  std::vector<SigmaFitSample> samples = planted(20000, {0, 0, 0}, {0.03, 0.03, 0.03}, {1, 1, 1}, {0, 0, 0}, 3);
  for (auto& s : samples) s.geometric = false;
  const SigmaCalibration c = fit_sigma_calibration(samples);
  EXPECT_FALSE(c.has_geometric);
  for (std::size_t a = 0; a < 3; ++a) {
    // The largest spread (0.05) hardly moves σ off the floor.
    EXPECT_NEAR(std::hypot(c.scale[a] * 0.05, c.floor_rad_s[a]), 0.03, 0.0006);
    EXPECT_NEAR(c.floor_rad_s[a], 0.03, 0.0006);
  }
  EXPECT_THROW(fit_sigma_calibration(std::vector<SigmaFitSample>(kSigmaFitMinimumPairs - 1)), Error);
}

TEST(SigmaCalibration, JsonRoundTripsAndBadValuesAreRefusedByName) {
  SigmaCalibration c;
  c.scale = {1.5, 2.0, 0.0};
  c.floor_rad_s = {0.01, 0.02, 0.03};
  c.geometric_scale = {0.5, 1.0, 1.5};
  c.correlation = {0.1, -0.2, 0.3};
  c.has_geometric = true;
  c.pairs = 100;
  c.pairs_both = 90;
  const SigmaCalibration back = sigma_calibration_from_json(sigma_calibration_to_json(c));
  EXPECT_EQ(back.scale, c.scale);
  EXPECT_EQ(back.floor_rad_s, c.floor_rad_s);
  EXPECT_EQ(back.geometric_scale, c.geometric_scale);
  EXPECT_EQ(back.correlation, c.correlation);
  EXPECT_EQ(back.pairs_both, 90u);
  const std::string tail = R"(,"pairs":5,"version":1})";
  for (const std::string& bad : {
           std::string(R"({"scale":[1,-1,1],"floor_rad_s":[0.1,0.1,0.1])") + tail,   // negative scale
           std::string(R"({"scale":[1,1,1],"floor_rad_s":[0.1,0,0.1])") + tail,      // zero floor
           std::string(R"({"scale":[1,1,1],"floor_rad_s":[0.1,0.1,"NaN"])") + tail,  // not a number
           std::string(R"({"scale":[1,1,1],"floor_rad_s":[0.1,0.1,1e999])") + tail,  // infinite
           std::string(R"({"scale":[1,1,1],"floor_rad_s":[0.1,0.1,0.1],"correlation":[0,0,1],)"
                       R"("geometric_scale":[1,1,1],"pairs_both":3)") + tail,        // |ρ| = 1
           std::string(R"({"scale":[1,1,1],"floor_rad_s":[0.1,0.1,0.1],"pairs":5,"version":2})"),
           std::string(R"({"scale":[1,1],"floor_rad_s":[0.1,0.1,0.1])") + tail,
           std::string("not json")}) {
    SCOPED_TRACE(bad);
    EXPECT_THROW(sigma_calibration_from_json(bad), Error);
  }
}

TEST(SigmaCalibration, BadMetadataInAHeadFileIsInvalidInputNamingFileKeyAndValue) {
  const auto path = (std::filesystem::temp_directory_path() / "inertialnet_test_sigma_calibration_bad.safetensors").string();
  HostTensor t;
  t.name = "head.fc2.bias";
  t.shape = {3};
  t.data = {0, 0, 0};
  const std::vector<HostTensor> tensors{t};
  write_safetensors(path, tensors,
                    {{kMetadataSigmaCalibration, R"({"floor_rad_s":[0.1,-0.5,0.1],"pairs":5,"scale":[1,1,1],"version":1})"}});
  try {
    read_sigma_calibration({path});
    FAIL() << "a negative floor was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::InvalidInput);  // exit 2 in the CLI
    const std::string what = e.what();
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_NE(what.find(kMetadataSigmaCalibration), std::string::npos) << what;
    EXPECT_NE(what.find("floor_rad_s[1] (y) is -0.5"), std::string::npos) << what;
  }
  // A file without the key: no calibration (today's built-in σ model).
  write_safetensors(path, tensors, std::map<std::string, std::string>{});
  EXPECT_FALSE(read_sigma_calibration({path}).has_value());
  std::filesystem::remove(path);
}

// read_sigma_calibration from the weight files opened once (as predict --fuse reads them) answers
// as it does by path: the first file's calibration, none without one, and a malformed one refused
// with the same message naming the file and the key.
TEST(SigmaCalibration, ReadFromOpenFilesAnswersAsByPath) {
  const std::filesystem::path root = testing::temporary_directory("sigma_calibration_files");
  const std::string plain = (root / "plain.safetensors").string(), head = (root / "head.safetensors").string();
  const std::string bad = (root / "bad.safetensors").string();
  const std::vector<HostTensor> tensors{{{"head.fc2.bias", {3}}, {0.0f, 0.0f, 0.0f}}};
  write_safetensors(plain, tensors, std::map<std::string, std::string>{});
  write_safetensors(head, tensors,
                    {{kMetadataSigmaCalibration, R"({"floor_rad_s":[0.1,0.2,0.3],"pairs":5,"scale":[1,2,3],"version":1})"}});
  write_safetensors(bad, tensors,
                    {{kMetadataSigmaCalibration, R"({"floor_rad_s":[0.1,-0.5,0.1],"pairs":5,"scale":[1,1,1],"version":1})"}});
  const auto found = read_sigma_calibration(open_safetensors({plain, head}));
  ASSERT_TRUE(found.has_value());
  EXPECT_EQ(found->scale, (std::array<double, 3>{1, 2, 3}));
  EXPECT_EQ(found->floor_rad_s, (std::array<double, 3>{0.1, 0.2, 0.3}));
  EXPECT_EQ(found->pairs, 5u);
  EXPECT_FALSE(read_sigma_calibration(open_safetensors({plain})).has_value());
  const std::string message = testing::invalid_input_message([&] { read_sigma_calibration(open_safetensors({bad})); });
  EXPECT_TRUE(testing::contains(message, bad) && testing::contains(message, kMetadataSigmaCalibration)) << message;
  EXPECT_EQ(message, testing::invalid_input_message([&] { read_sigma_calibration({bad}); }));
}

TEST(SigmaCalibration, HeadSigmaOptionsRefuseAnInvalidCalibration) {
  HeadSigmaOptions options;
  options.calibration = SigmaCalibration{};  // floor 0: not a σ model
  EXPECT_THROW(options.validate(), Error);
  options.calibration->floor_rad_s = {0.01, 0.02, 0.03};
  options.calibration->scale = {1, 2, 3};
  EXPECT_NO_THROW(options.validate());
  const std::array<double, 3> s = options.calibration->sigma({0.0, 0.01, 0.01});
  EXPECT_DOUBLE_EQ(s[0], 0.01);
  EXPECT_DOUBLE_EQ(s[1], std::hypot(0.02, 0.02));
  EXPECT_DOUBLE_EQ(s[2], std::hypot(0.03, 0.03));
}

// Two heads whose errors share a part (both see the same flow): on 20000 synthetic pairs the
// GLS rule with the fitted ρ beats both heads on every axis, and the inverse-variance rule (ρ
// taken as 0) by more than 5 % where the correlation is strong.
TEST(SigmaCalibration, CorrelatedFusionBeatsBothHeadsOnEveryAxis) {
  const std::array<double, 3> rho{0.0, 0.5, 0.8};
  const std::vector<SigmaFitSample> samples =
      planted(20000, {0, 0, 0}, {0.02, 0.02, 0.02}, {1, 1, 1}, rho, 11);
  const SigmaCalibration c = fit_sigma_calibration(samples);
  FusionWeights weights;
  weights.geometric_scale = c.geometric_scale;
  weights.correlation = c.correlation;
  std::array<double, 3> se_learned{}, se_geometric{}, se_iv{}, se_gls{};
  for (const auto& s : samples) {
    EstimatorRates learned, geometric;
    learned.name = "inertialnet";
    geometric.name = "geometric";
    for (std::size_t a = 0; a < 3; ++a) {
      learned.w[a] = s.learned_error[a];  // truth 0: the rate is the error
      learned.sigma[a] = c.sigma(s.spread)[a];
      geometric.w[a] = s.geometric_error[a];
      geometric.sigma[a] = s.geometric_sigma[a];
    }
    const EstimatorRates iv = fuse_rates(learned, geometric), gls = fuse_rates(learned, geometric, weights);
    for (std::size_t a = 0; a < 3; ++a) {
      se_learned[a] += learned.w[a] * learned.w[a];
      se_geometric[a] += geometric.w[a] * geometric.w[a];
      se_iv[a] += iv.w[a] * iv.w[a];
      se_gls[a] += gls.w[a] * gls.w[a];
    }
  }
  for (std::size_t a = 0; a < 3; ++a) {
    SCOPED_TRACE(a);
    EXPECT_LT(se_gls[a], std::min(se_learned[a], se_geometric[a]));
    EXPECT_LE(se_gls[a], se_iv[a] * 1.001);
  }
  EXPECT_LT(se_gls[2], 0.95 * se_iv[2]);  // ρ 0.8: ignoring it costs more than 5 %
}

}  // namespace
}  // namespace inertialnet
