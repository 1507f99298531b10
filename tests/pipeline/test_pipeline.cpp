// SPDX-License-Identifier: Apache-2.0
// The scheduler against the plain sequential loop it replaces: identical rates, in order, with
// one device and with two (CTest runs this suite with POCL_DEVICES="pthread pthread"), each
// frame decoded once, and clean stops on cancellation and on a bad frame.
#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <mutex>

#include "inertialnet/models/flownet.hpp"
#include "inertialnet/models/inertialnet_head.hpp"
#include "inertialnet/models/synthetic_weights.hpp"
#include "inertialnet/pipeline/pipeline.hpp"
#include "inertialnet/pipeline/predict.hpp"
#include "inertialnet/pipeline/rates_processor.hpp"
#include "inertialnet/io/rates_csv.hpp"
#include "inertialnet/synth/synthetic_sequence.hpp"
#include "support/testing.hpp"

namespace inertialnet {
namespace {

namespace fs = std::filesystem;
constexpr int kWidth = 96, kHeight = 64, kFrames = 20;

// A 20-frame synthetic sequence and synthetic FlowNet2-C + head weights, made once.
struct Fixture {
  fs::path root = testing::temporary_directory("pipeline");
  fs::path sequence = root / "seq";
  std::vector<std::string> weight_files{(root / "c.safetensors").string(), (root / "head.safetensors").string()};
  Fixture() {
    SynthOptions options;
    options.frames = kFrames;
    options.width = kWidth;
    options.height = kHeight;
    options.seed = 7;
    write_synthetic_sequence(sequence, options);
    write_synthetic_weights(weight_files[0], ModelKind::FlowNet2C, 1);
    HeadConfig head;
    head.input_width = kWidth;
    head.input_height = kHeight;
    write_synthetic_weights(weight_files[1], ModelKind::InertialNetHead, 1, head);
  }
};
Fixture& fixture() {
  static Fixture f;
  return f;
}

// Counts decodes, to show that each frame is decoded once although it serves two pairs.
class CountingSource : public FrameSource {
 public:
  explicit CountingSource(std::unique_ptr<FrameSource> inner) : inner_(std::move(inner)), counts_(inner_->size()) {}
  std::size_t size() const override { return inner_->size(); }
  std::int64_t timestamp_ns(std::size_t i) const override { return inner_->timestamp_ns(i); }
  HostImage decode(std::size_t i) override {
    ++counts_.at(i);
    return inner_->decode(i);
  }
  std::string description() const override { return inner_->description(); }
  const std::vector<std::atomic<int>>& counts() const { return counts_; }

 private:
  std::unique_ptr<FrameSource> inner_;
  std::vector<std::atomic<int>> counts_;
};

using Rates = std::vector<std::array<double, 3>>;

Rates sequential(Device& device, const WeightSet& weights) {
  auto source = open_frame_source(fixture().sequence);
  FlowNet net(device, ModelKind::FlowNet2C, weights);
  InertialNetHead head(device, weights);
  Queue& q = device.queue();
  Rates rates;
  HostImage previous = source->decode(0);
  for (std::size_t k = 1; k < source->size(); ++k) {
    HostImage current = source->decode(k);
    const Shape shape{1, 3, kHeight, kWidth};
    const Tensor flow = net.compute(q, Tensor::from_host(q, shape, previous.data), Tensor::from_host(q, shape, current.data));
    const auto w = head.compute(q, flow).to_host(q);
    rates.push_back({w[0], w[1], w[2]});
    previous = std::move(current);
  }
  return rates;
}

struct PipelineRun {
  Rates rates;
  std::vector<std::int64_t> t1;
  PipelineStats stats;
};

PipelineRun pipelined(const std::vector<Device*>& devices, FrameSource& source, PipelineOptions options = {}) {
  std::vector<std::unique_ptr<WeightSet>> sets;
  std::map<const Device*, const WeightSet*> weights;
  for (Device* d : devices) {
    sets.push_back(std::make_unique<WeightSet>(WeightSet::load(*d, fixture().weight_files)));
    weights[d] = sets.back().get();
  }
  RatesProcessorOptions processor;
  processor.flow_model = ModelKind::FlowNet2C;
  PipelineRun run;
  run.stats = run_pipeline(
      source, devices, rates_processor(weights, processor),
      [&](const PairResult& r) {
        EXPECT_EQ(r.index, run.rates.size() + 1) << "results out of order";
        run.rates.push_back(r.rates.at(0).w);
        run.t1.push_back(r.t1_ns);
      },
      options);
  return run;
}

TEST(Pipeline, OneDeviceMatchesTheSequentialLoopExactly) {
  Device& device = testing::test_device();
  const WeightSet weights = WeightSet::load(device, fixture().weight_files);
  const Rates expected = sequential(device, weights);
  ASSERT_EQ(expected.size(), static_cast<std::size_t>(kFrames - 1));

  CountingSource source(open_frame_source(fixture().sequence));
  const PipelineRun run = pipelined({&device}, source);
  EXPECT_EQ(run.rates, expected);  // same kernels, same data: bit for bit
  EXPECT_EQ(run.stats.pairs, static_cast<std::size_t>(kFrames - 1));
  EXPECT_FALSE(run.stats.cancelled);
  for (std::size_t i = 0; i < source.counts().size(); ++i) EXPECT_EQ(source.counts()[i].load(), 1) << "frame " << i;
  for (std::size_t k = 0; k < run.t1.size(); ++k) EXPECT_EQ(run.t1[k], source.timestamp_ns(k + 1));
}

TEST(Pipeline, TwoDevicesShareTheWorkAndAgree) {
  std::vector<std::unique_ptr<Device>> owned;
  std::vector<Device*> devices;
  for (const auto& info : select_devices("all", discover_devices())) {
    if (!info.is_pocl()) continue;
    owned.push_back(std::make_unique<Device>(info));
    devices.push_back(owned.back().get());
  }
  ASSERT_GE(devices.size(), 2u) << "CTest runs this suite with POCL_DEVICES=\"pthread pthread\"";
  const WeightSet weights = WeightSet::load(*devices[0], fixture().weight_files);
  const Rates expected = sequential(*devices[0], weights);

  auto source = open_frame_source(fixture().sequence);
  const PipelineRun run = pipelined(devices, *source);
  EXPECT_EQ(run.rates, expected);
  EXPECT_EQ(run.stats.pairs_per_device.size(), devices.size()) << "a device got no pair";
}

// What keeps a long run's memory flat, without timing it: a lane's pool of temporaries takes
// its last new buffer by the second pair (the first also prepares the weights) and reuses them
// for every pair after; the stats report the pools at the end (predict --stats prints them).
TEST(Pipeline, TemporariesStopGrowingAfterTheSecondPair) {
  Device& device = testing::test_device();
  PipelineOptions one_lane;
  one_lane.lanes_per_device = 1;  // each lane has a pool of its own: one lane, one pool
  one_lane.max_pairs = 2;
  auto first = open_frame_source(fixture().sequence);
  const PipelineStats two = pipelined({&device}, *first, one_lane).stats;
  one_lane.max_pairs = 0;
  auto second = open_frame_source(fixture().sequence);
  const PipelineStats all = pipelined({&device}, *second, one_lane).stats;
  ASSERT_EQ(all.pairs, static_cast<std::size_t>(kFrames - 1));

  EXPECT_GT(two.temporaries.allocations, 0u);
  EXPECT_EQ(all.temporaries.allocations, two.temporaries.allocations);
  EXPECT_EQ(all.temporaries.peak_bytes_in_use, two.temporaries.peak_bytes_in_use);
  // Held (the network keeps its last inputs bound until the next pair) or idle: the same buffers.
  EXPECT_EQ(all.temporaries.bytes_in_use + all.temporaries.bytes_cached,
            two.temporaries.bytes_in_use + two.temporaries.bytes_cached);
  EXPECT_GT(all.temporaries.reuses, two.temporaries.reuses);
  ASSERT_EQ(all.device_buffers.count(device.info().summary()), 1u);
  EXPECT_GT(all.device_buffers.at(device.info().summary()).bytes_in_use, 0u);  // prepared weights, arena
}

TEST(Pipeline, CancellationLeavesAValidPartialCsv) {
  Device& device = testing::test_device();
  const WeightSet weights = WeightSet::load(device, fixture().weight_files);
  const fs::path csv = fixture().root / "partial.csv";
  std::atomic<bool> cancel{false};
  {
    RatesCsvWriter writer(csv, rates_layout({""}));  // one estimator: its rates, status and σ
    auto source = open_frame_source(fixture().sequence);
    RatesProcessorOptions processor;
    processor.flow_model = ModelKind::FlowNet2C;
    PipelineOptions options;
    options.cancel = &cancel;
    const PipelineStats stats = run_pipeline(
        *source, {&device}, rates_processor({{&device, &weights}}, processor),
        [&](const PairResult& r) {
          writer.write(rates_row(r));
          if (writer.rows() == 3) cancel = true;  // as SIGINT would
        },
        options);
    EXPECT_TRUE(stats.cancelled);
    EXPECT_GE(stats.pairs, 3u);
    EXPECT_LT(stats.pairs, static_cast<std::size_t>(kFrames - 1));
  }
  // Not closed: the rows so far are in the journal, a valid CSV; the target was never written.
  EXPECT_FALSE(fs::exists(csv));
  const RatesTable table = read_rates_csv(partial_rates_path(csv));
  EXPECT_GE(table.size(), 3u);
  EXPECT_LT(table.size(), static_cast<std::size_t>(kFrames - 1));
}

// A frame that cannot be decoded costs its two pairs, never the run: they come out in order with
// the status decode_error and the decoder's message (naming the file), and every other pair is
// answered as before.
TEST(Pipeline, ABadFrameCostsItsTwoPairsOnly) {
  // Copy the sequence and cut one image in half.
  const fs::path broken = fixture().root / "broken";
  fs::copy(fixture().sequence, broken, fs::copy_options::recursive | fs::copy_options::overwrite_existing);
  std::vector<fs::path> images;
  for (const auto& e : fs::directory_iterator(broken / "mav0" / "cam0" / "data")) images.push_back(e.path());
  std::sort(images.begin(), images.end());
  const fs::path victim = images.at(10);
  fs::resize_file(victim, fs::file_size(victim) / 2);

  Device& device = testing::test_device();
  auto source = open_frame_source(broken);
  const WeightSet weights = WeightSet::load(device, fixture().weight_files);
  RatesProcessorOptions processor;
  processor.flow_model = ModelKind::FlowNet2C;
  std::vector<PairResult> results;
  run_pipeline(*source, {&device}, rates_processor({{&device, &weights}}, processor),
               [&](const PairResult& r) { results.push_back(r); });
  ASSERT_EQ(results.size(), static_cast<std::size_t>(kFrames - 1));
  for (const PairResult& r : results) {
    const EstimatorRates& answer = r.rates.at(0);
    if (r.index == 10 || r.index == 11) {
      EXPECT_EQ(answer.status, PairStatus::DecodeError) << "pair " << r.index;
      EXPECT_NE(answer.reason.find(victim.filename().string()), std::string::npos) << answer.reason;
      EXPECT_NE(answer.reason.find("truncated"), std::string::npos) << answer.reason;
      EXPECT_NE(answer.reason.find("frame 10"), std::string::npos) << answer.reason;
      EXPECT_TRUE(std::isnan(answer.w[0]));
    } else {
      EXPECT_EQ(answer.status, PairStatus::Ok) << "pair " << r.index << ": " << answer.reason;
      EXPECT_TRUE(std::isfinite(answer.w[0]));
    }
  }
}

// One lane per CPU device (the lanes would share its cores); two as soon as a GPU is among them.
TEST(Pipeline, DefaultLanesAreOneOnCpusOnly) {
  DeviceInfo cpu, gpu;
  cpu.type = DeviceType::CPU;
  gpu.type = DeviceType::GPU;
  EXPECT_EQ(default_lanes_per_device({cpu}), 1);
  EXPECT_EQ(default_lanes_per_device({cpu, cpu}), 1);
  EXPECT_EQ(default_lanes_per_device({gpu}), 2);
  EXPECT_EQ(default_lanes_per_device({cpu, gpu}), 2);
}

}  // namespace
}  // namespace inertialnet
