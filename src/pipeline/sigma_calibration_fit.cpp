// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/pipeline/sigma_calibration_fit.hpp"

#include <cmath>
#include <map>

#include "inertialnet/eval/evaluate.hpp"
#include "inertialnet/io/rates_csv.hpp"
#include "inertialnet/io/safetensors.hpp"
#include "inertialnet/io/safetensors_writer.hpp"
#include "inertialnet/runtime/error.hpp"

namespace inertialnet {

namespace fs = std::filesystem;

namespace {

// The estimator's errors against gyro − bias (eval --target mean) and its σ columns, by timestamp.
struct Measured {
  std::map<std::int64_t, std::array<double, 3>> error, sigma;
};

Measured measure(const fs::path& csv, const fs::path& sequence, const std::string& suffix) {
  EvalOptions options;
  options.head_suffix = suffix;
  // Both heads measure the rotation between the two frames (the learned head trained with --target
  // mean, train's default): the gyro's mean over the interval, as eval --target mean. The rates
  // file calls the learned head a network, for which eval's own choice would be the spline at t_k.
  options.sync.target = SyncTarget::Mean;
  const EvalReport report = evaluate(csv, sequence, options);
  if (!report.corrected) {
    throw invalid_input(sequence.string() + ": the σ calibration needs the gyro bias (ground truth or a static start); "
                        "eval finds none");
  }
  const RatesTable table = read_rates_csv(csv);
  std::array<std::vector<double>, 3> sigma;
  const char* const names[3] = {"sigma_wx", "sigma_wy", "sigma_wz"};
  for (std::size_t a = 0; a < 3; ++a) sigma[a] = table.column(names[a] + suffix);
  std::map<std::int64_t, std::size_t> row_of;
  for (std::size_t i = 0; i < table.size(); ++i) row_of[table.t_ns[i]] = i;
  Measured m;
  for (std::size_t i = 0; i < report.t_ns.size(); ++i) {
    const auto row = row_of.find(report.t_ns[i]);
    if (row == row_of.end()) continue;
    std::array<double, 3> e{}, s{};
    for (std::size_t a = 0; a < 3; ++a) {
      e[a] = report.predicted[i][a] - report.truth_corrected[i][a];
      s[a] = sigma[a][row->second];
    }
    m.error[report.t_ns[i]] = e;
    m.sigma[report.t_ns[i]] = s;
  }
  return m;
}

}  // namespace

std::vector<SigmaFitSample> sigma_fit_samples(const PredictSettings& base, const std::vector<fs::path>& sequences,
                                              const fs::path& scratch) {
  std::error_code ec;
  fs::create_directories(scratch, ec);
  if (ec) throw invalid_input("cannot create the folder " + scratch.string() + ": " + ec.message());
  std::vector<SigmaFitSample> samples;
  std::size_t index = 0;
  for (const fs::path& sequence : sequences) {
    PredictSettings s = base;
    s.sequence = sequence;
    s.head = "both";
    s.fuse = true;
    s.smooth = "off";
    // The raw spread as σ: scale 1, no floor, no calibration (the fit makes them).
    HeadSigmaOptions raw;
    raw.scale = 1.0;
    raw.floor_rad_s = 0.0;
    s.head_sigma_override = raw;
    Prediction prediction(s);
    const fs::path csv = scratch / ("sigma_fit_" + std::to_string(index++) + ".csv");
    {
      RatesCsvWriter writer(csv, prediction.layout(), prediction.csv_metadata());
      prediction.run([&](const PairResult& r) { writer.write(rates_row(r)); });
      writer.close();
    }
    const Measured learned = measure(csv, sequence, "");
    const Measured geometric = measure(csv, sequence, "_geometric");
    for (const auto& [t, error] : learned.error) {
      SigmaFitSample sample;
      sample.learned_error = error;
      sample.spread = learned.sigma.at(t);
      const auto g = geometric.error.find(t);
      if (g != geometric.error.end()) {
        sample.geometric = true;
        sample.geometric_error = g->second;
        sample.geometric_sigma = geometric.sigma.at(t);
      }
      samples.push_back(sample);
    }
  }
  return samples;
}

void write_sigma_calibration(const std::string& path, const SigmaCalibration& calibration) {
  calibration.validate();
  std::vector<HostTensor> tensors;
  std::map<std::string, std::string> metadata;
  {
    const SafetensorsFile file(path);
    metadata = file.metadata();
    for (const std::string& name : file.names()) {
      HostTensor t;
      t.name = name;
      t.shape = file.shape(name);
      t.data = file.to_float32(name);
      tensors.push_back(std::move(t));
    }
  }  // unmapped before the file is replaced
  metadata[kMetadataSigmaCalibration] = sigma_calibration_to_json(calibration);
  write_safetensors(path, tensors, metadata);
}

}  // namespace inertialnet
