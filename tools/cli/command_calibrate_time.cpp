// `inertialnet calibrate-time SEQ [RATES.csv]`: the camera–IMU time offset of a EuRoC-layout
// sequence, estimated by aligning predicted rates with its gyro (include/inertialnet/eval/
// time_offset.hpp). Without a rates file the weight-free path (DIS flow + geometric head)
// predicts them first.
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "console.hpp"
#include "inertialnet/eval/evaluate.hpp"
#include "inertialnet/io/euroc.hpp"
#include "inertialnet/io/rates_csv.hpp"
#include "inertialnet/pipeline/predict.hpp"
#include "inertialnet/runtime/error.hpp"

namespace inertialnet::cli {

namespace {
struct CalibrateTimeOptions {
  std::string sequence, rates, head;
  double range = 0.2;
};

// Weight-free rates of every frame pair, set up as `inertialnet predict SEQ` sets them up (the
// library's Prediction: DIS flow + geometric head, in the body frame when cam0 gives T_BS).
RatesTable predict_weight_free(const std::string& sequence, const EurocSequence& seq, const GlobalOptions& global) {
  if (!seq.camera) throw invalid_input("calibrate-time: " + sequence + " has no cam0/sensor.yaml to predict with.");
  PredictSettings settings;
  settings.sequence = sequence;
  settings.device = global.device;
  settings.no_cache = global.no_cache;
  Prediction prediction(settings);
  RatesTable table;
  table.metadata = prediction.csv_metadata();
  info("no rates file given: predicting " + std::to_string(prediction.pairs()) + " pairs with " + prediction.method());
  prediction.run([&](const PairResult& r) {
    const auto& w = r.rates.front().second;
    table.t_ns.push_back(r.t1_ns);
    table.w.push_back({w[0], w[1], w[2]});
  });
  return table;
}
}  // namespace

Command register_calibrate_time(CLI::App& app, const GlobalOptions& global) {
  auto o = std::make_shared<CalibrateTimeOptions>();
  app.add_option("sequence", o->sequence, "EuRoC-layout sequence with mav0/imu0")->required()->check(CLI::ExistingDirectory);
  app.add_option("rates", o->rates, "rates CSV written by predict (default: predict weight-free now)")
      ->check(CLI::ExistingFile);
  app.add_option("--range", o->range, "search +-this many seconds")->capture_default_str();
  app.add_option("--head", o->head, "use columns wx<_HEAD>…, e.g. --head geometric");
  return [o, &global]() {
    EvalOptions options;
    options.choose_target = true;
    options.estimate_time_offset = true;
    options.time_offset_search.range_s = o->range;
    if (!o->head.empty()) options.head_suffix = "_" + o->head;
    EurocReadOptions read;
    read.check_images = false;
    const EurocSequence seq = read_euroc(o->sequence, read);
    const RatesTable rates = o->rates.empty() ? predict_weight_free(o->sequence, seq, global) : read_rates_csv(o->rates);
    const EvalReport report = evaluate(rates, seq, options);
    const TimeOffsetEstimate& e = *report.time_offset_estimate;
    std::cout << e.summary() << "\n";
    std::printf("time_offset_s %.6f\nstd_error_s %.6f\nconfidence %s\n", e.offset_s, e.std_error_s, e.confidence().c_str());
    std::cout << "apply it with: inertialnet eval RATES.csv " << o->sequence << " --time-offset " << e.offset_s << "\n";
    for (const auto& w : report.warnings) warning(w);
    return 0;
  };
}

}  // namespace inertialnet::cli
