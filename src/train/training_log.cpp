// SPDX-License-Identifier: Apache-2.0
#include "inertialnet/train/training_log.hpp"

#include <charconv>
#include <fstream>
#include <sstream>

#include "inertialnet/runtime/error.hpp"
#include "runtime/atomic_file.hpp"

namespace inertialnet {

const char* TrainingLog::header() {
  return "epoch,lr,train_loss,val_loss,rmse_x_deg_s,rmse_y_deg_s,rmse_z_deg_s,zero_rmse_x_deg_s,"
         "zero_rmse_y_deg_s,zero_rmse_z_deg_s,spread_ratio_x,spread_ratio_y,spread_ratio_z,best,seconds";
}

TrainingLog::TrainingLog(std::filesystem::path path, int keep_epochs) : path_(std::move(path)) {
  text_ = std::string(header()) + "\n";
  {
    // The writer's own checks (a device, FIFO or folder refused; the folder writable), made now:
    // the temporary it creates is removed again, nothing is written under the final name.
    const AtomicFile probe(path_);
  }
  std::error_code ec;
  if (keep_epochs < 0 || !std::filesystem::exists(path_, ec)) return;
  // The probe accepted it, so it is a regular file (or a link to one): reading cannot block.
  std::ifstream in(path_);
  std::string line;
  if (!in || !std::getline(in, line)) throw invalid_input("cannot read the training log " + path_.string() + " to continue it");
  if (!line.empty() && line.back() == '\r') line.pop_back();
  if (line != header()) {
    throw invalid_input(path_.string() + " is not a training log (its first line is not train's CSV header); "
                        "refusing to continue it: name another --log or remove it");
  }
  while (std::getline(in, line)) {
    const auto comma = line.find(',');
    int epoch = 0;
    const char* end = line.data() + (comma == std::string::npos ? line.size() : comma);
    const auto [ptr, err] = std::from_chars(line.data(), end, epoch);
    if (err != std::errc() || ptr != end) continue;  // a torn or foreign line: not one of ours to keep
    if (epoch >= 1 && epoch <= keep_epochs) text_ += line + "\n";
  }
}

void TrainingLog::append(const EpochReport& r) {
  std::ostringstream row;
  row << r.epoch << ',' << r.lr << ',' << r.train_loss << ',' << r.val_loss;
  for (double v : r.val_rmse_deg_s) row << ',' << v;
  for (double v : r.zero_rmse_deg_s) row << ',' << v;
  for (double v : r.spread_ratio) row << ',' << v;
  row << ',' << (r.best ? 1 : 0) << ',' << r.seconds << '\n';
  const std::string text = text_ + row.str();
  write_file_atomically(path_, text.data(), text.size());
  text_ = text;
}

}  // namespace inertialnet
