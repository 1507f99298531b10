// SPDX-License-Identifier: Apache-2.0
// `inertialnet export RATES.csv --format gyroflow|euroc-imu|tum -o OUT`: the rates in the formats
// of the tools users open next (io/rates_export.hpp): a Gyroflow gyro log, a EuRoC imu0-style
// "virtual gyro", a TUM orientation trajectory for evo.
#include <memory>

#include "commands.hpp"
#include "common.hpp"
#include "console.hpp"
#include "inertialnet/io/rates_export.hpp"

namespace inertialnet::cli {

namespace {
struct ExportCliOptions {
  std::string rates, format, output, head;
  bool allow_camera_frame = false;
};
}  // namespace

Command register_export(CLI::App& app, const GlobalOptions&) {
  auto o = std::make_shared<ExportCliOptions>();
  app.add_option("rates", o->rates, "rates CSV written by predict")->required()->check(CLI::ExistingFile);
  app.add_option("--format", o->format,
                 "gcsv or gyroflow (Gyroflow's .gcsv gyro log), euroc-imu (imu0/data.csv layout, gyro only) or tum (orientation "
                 "trajectory integrated from the rates, for evo)")
      ->required()
      ->transform(choice("format", {"gcsv", "gyroflow", "euroc-imu", "tum"}));
  app.add_option("-o,--output", o->output, "file to write (replaced whole or left as it was; folders created as needed)")
      ->required();
  app.add_option("--head", o->head, "export columns wx<_HEAD>…, e.g. --head geometric");
  app.add_flag("--allow-camera-frame", o->allow_camera_frame,
               "euroc-imu: write rates whose frame is not body (EuRoC's columns are the IMU frame) as they are");
  return [o]() {
    // -o never replaces the rates it reads; checked before any work.
    check_distinct_outputs({{o->output, "-o"}}, {o->rates});
    prepare_output_file(o->output, "-o");
    RatesExportOptions options;
    if (!o->head.empty()) options.head_suffix = "_" + o->head;
    options.allow_camera_frame = o->allow_camera_frame;
    const RatesExportFormat format = rates_export_format_from_string(o->format);
    const RatesExportSummary summary = export_rates(o->rates, o->output, format, options);
    for (const std::string& note : summary.notes) info(note);
    info("wrote " + std::to_string(summary.rows_written) + " rows (" + to_string(format) + ") to " + o->output);
    return 0;
  };
}

}  // namespace inertialnet::cli
