// SPDX-License-Identifier: Apache-2.0
// `inertialnet train`: trains the InertialNet head on flows of EuRoC sequences against their gyro
// (include/inertialnet/train/trainer.hpp), on the selected OpenCL device. Writes the best head by
// validation RMSE (-o), the last one (<stem>.last.safetensors) and a resumable state
// (<stem>.state.safetensors) after every epoch; Ctrl-C stops after the current mini-batch with
// both checkpoints valid (exit 1). Every output is checked, and the resume state read, before any
// flow is computed: a mistake costs seconds, not the hours of FlowNet2 flows.
#include <algorithm>
#include <atomic>
#include <cctype>
#include <charconv>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "console.hpp"
#include "interrupt.hpp"
#include "common.hpp"
#include "progress.hpp"
#include "input_options.hpp"
#include "inertialnet/eval/plots.hpp"
#include "inertialnet/io/camera_imu.hpp"
#include "inertialnet/eval/time_offset.hpp"
#include "inertialnet/models/head_ensemble.hpp"
#include "inertialnet/models/head_input.hpp"
#include "inertialnet/models/weights.hpp"
#include "inertialnet/runtime/error.hpp"
#include "inertialnet/runtime/program_cache.hpp"
#include "inertialnet/train/recipe.hpp"
#include "inertialnet/train/trainer.hpp"
#include "inertialnet/train/training_log.hpp"
#include "inertialnet/train/training_set.hpp"

namespace inertialnet::cli {

namespace {


struct TrainCliOptions {
  std::vector<std::string> train, val, weights;
  std::string flow = "dis", optimizer = "sgd", schedule = "constant", head_size = "752x480", target = "mean";
  std::string out, log, plot, cache, time_offset;
  std::string head_input = "normalized";  // --head-input (models/head_input.hpp)
  double augment_rotation = 0;            // --augment-rotation, deg/s
  // --dropout before fc1, training only. 0, not the paper's 0.3: dropout acts as a ridge penalty on
  // fc1 and pulls predictions towards the mean (docs/training.md, "Regression towards the mean").
  double dropout = 0;
  BagTopics bag;          // --image-topic, --imu-topic, --camera-info-topic: every ROS bag's
  std::string T_cam_imu;  // --T-cam-imu: a ROS bag's IMU-camera rotation
  int epochs = 20, batch = 10;
  float lr = 1e-6f, momentum = 0.0f, weight_decay = 0.0f;
  std::string seed = "1";
  double cache_budget_mb = -1;
  bool resume = false, no_flow_cache = false, augment_flips = false;
  // --recipe NAME (train/recipe.hpp): renders its own sequences and fixes every training setting.
  std::string recipe, recipe_scale = "full", work;
  // --ensemble K: K heads with seeds seed…seed+K−1, written as one ensemble file (models/head_ensemble.hpp).
  int ensemble = 1;
};

std::filesystem::path sibling(const std::filesystem::path& out, const std::string& suffix) {
  return out.parent_path() / (out.stem().string() + suffix);
}

std::string vec3_json(const Vec3& v) { return nlohmann::json(std::vector<double>{v[0], v[1], v[2]}).dump(); }

namespace fs = std::filesystem;

std::uint64_t parse_seed(const std::string& text) {
  std::uint64_t value = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (text.empty() || ec != std::errc() || ptr != end) {
    throw invalid_input("--seed '" + text.substr(0, 40) + (text.size() > 40 ? "…" : "") +
                        "': the seed is a whole number from 0 to 18446744073709551615");
  }
  return value;
}

// One file `train` writes, and the option that names it.
struct Output {
  fs::path path;
  std::string option;
};

// The output rules of docs/cli.md, for every file train writes, before any work: missing folders
// created; a target that exists and is not a regular file (a folder, a device node, a FIFO, a link
// to nothing) refused; no output one of the inputs (a --weights file, anything in a sequence's
// mav0 folder); no two outputs the same file.
void check_outputs(const std::vector<Output>& outputs, const std::vector<std::string>& weights,
                   const std::vector<std::string>& sequences) {
  std::vector<OutputPath> paths;
  for (const auto& out : outputs) {
    if (out.path.empty() || out.path.filename().empty()) {
      throw invalid_input(out.option + " '" + out.path.string() + "': expected a file name.");
    }
    std::error_code ec;
    const fs::file_status link = fs::symlink_status(out.path, ec);
    const fs::file_status target = fs::status(out.path, ec);
    if (fs::is_symlink(link) && target.type() == fs::file_type::not_found) {
      throw invalid_input(out.option + " " + out.path.string() + ": it is a symbolic link that leads nowhere; refusing to write through it.");
    }
    // (file_type::none: the status could not be read, e.g. no permission; the writer reports that.)
    if (target.type() != fs::file_type::not_found && target.type() != fs::file_type::none &&
        !fs::is_regular_file(target)) {
      throw invalid_input(out.option + " " + out.path.string() + ": it exists and is not a regular file (" +
                          (fs::is_directory(target) ? "a folder" : "a device, FIFO or socket") +
                          "); refusing to replace it.");
    }
    paths.push_back({out.path.string(), out.option});
  }
  for (const auto& sequence : sequences) check_outputs_outside_sequence(paths, sequence);
  check_distinct_outputs(paths, weights);
  // Only now, so that a refused output leaves no new folder behind (inside a sequence, say).
  for (const auto& out : outputs) prepare_output_file(out.path.string(), out.option);
}

}  // namespace

Command register_train(CLI::App& app, const GlobalOptions& global) {
  auto o = std::make_shared<TrainCliOptions>();
  app.add_option("--train", o->train, "training sequences (EuRoC folders or ROS bags); with --recipe, added to its own");
  app.add_option("--val", o->val, "validation sequences (EuRoC folders or ROS bags); with --recipe, added to its own");
  app.add_option("--recipe", o->recipe,
                 "general: render the recipe's synthetic sequences and train with its fixed settings (the same head "
                 "bit for bit on one device; docs/training.md)");
  // For the reproducibility test: the recipe's code path in seconds (docs/training.md).
  app.add_option("--recipe-scale", o->recipe_scale, "full, or tiny (a few seconds; for tests, not a usable head)")
      ->capture_default_str();
  app.add_option("--work", o->work, "where --recipe renders its sequences (default: <program cache>/recipes)");
  add_bag_topic_options(app, o->bag, true);
  app.add_option("--T-cam-imu", o->T_cam_imu,
                 "for ROS bags: IMU-to-camera transform, 16 numbers (4x4 row-major, Kalibr's T_cam_imu) or a YAML file "
                 "with T_cam_imu (or T_BS as cam0/sensor.yaml writes it); default: identity");
  app.add_option("--flow", o->flow,
                 "dis (weight-free), dis-fine (DIS down to the full resolution: recipe general's since v3) "
                 "or flownet2 (needs --weights)")
      ->capture_default_str();
  app.add_option("--weights", o->weights, "FlowNet2 weights, for --flow flownet2");
  app.add_option("--epochs", o->epochs, "epochs")->capture_default_str()->check(CLI::Range(1, 100000));
  app.add_option("--batch", o->batch, "mini-batch size")->capture_default_str()->check(CLI::Range(1, 100000));
  app.add_option("--lr", o->lr, "learning rate (the paper: 1e-6 with SGD)")->capture_default_str();
  app.add_option("--optimizer", o->optimizer, "sgd or adam")->capture_default_str();
  app.add_option("--momentum", o->momentum, "SGD momentum")->capture_default_str();
  app.add_option("--weight-decay", o->weight_decay, "L2 weight decay (≥ 0)")->capture_default_str();
  app.add_option("--lr-schedule", o->schedule, "constant, step (x0.1 every 10 epochs) or cosine")->capture_default_str();
  // Read as text and parsed in the command: an unsigned option would take -1 as 2^64 − 1.
  app.add_option("--seed", o->seed, "seed of the initialisation, shuffles and dropout (a whole number ≥ 0)")
      ->capture_default_str()
      ->type_name("UINT");
  app.add_option("--head-size", o->head_size, "the head's flow size WxH (flows are resized to it)")->capture_default_str();
  app.add_option("--target", o->target, "mean (the gyro over each pair's interval, what its flow measures) or spline (the paper's: at the second frame)")->capture_default_str();
  app.add_option("--time-offset", o->time_offset,
                 "camera-IMU time offset in seconds (t_imu = t_cam + offset) of every sequence: the targets are the "
                 "gyro at the shifted times (as eval --time-offset; estimate it with calibrate-time)");
  app.add_option("-o,--output", o->out, "the best head (safetensors)")->required();
  app.add_flag("--augment-flips", o->augment_flips, "mirror training flows at random, with the matching sign changes of the rates");
  app.add_option("--head-input", o->head_input,
                 "normalized (flow per second in normalised camera coordinates: any camera, frame rate and size) "
                 "or paper (pixels at the head's size, the paper's)")
      ->capture_default_str();
  // Both named at parse, with the value as given (the library's checks said "head configuration:
  // dropout is 1.000000" and "training: …", naming no option).
  app.add_option("--dropout", o->dropout, "dropout before fc1 during training (the paper's: 0.3)")
      ->capture_default_str()
      ->check(finite_non_negative_up_to(1, "(a probability)"))
      ->check(CLI::Validator(
          [](std::string& text) {
            // After the check above: a decimal number from 0 to 1, of which 1 drops every unit.
            return std::strtod(text.c_str(), nullptr) < 1 ? std::string()
                                                          : "must be below 1 (1 drops every unit), got " + text;
          },
          "PROBABILITY"));
  app.add_option("--augment-rotation", o->augment_rotation,
                 "add to each training flow the exact flow of a random rotation up to this many deg/s per axis, and "
                 "its rate to the target (0: off)")
      ->capture_default_str()
      ->check(finite_non_negative_up_to(1000, "deg/s"));  // the Trainer's bound (trainer.cpp)
  app.add_option("--ensemble", o->ensemble,
                 "train K heads with seeds --seed, --seed+1, … (each with its own <stem>.member<k> files) and write "
                 "their best heads as one ensemble at -o: predict reports their mean, --fuse uses their spread")
      ->capture_default_str()
      ->check(CLI::Range(1, kMaxEnsembleMembers));
  app.add_flag("--resume", o->resume, "continue from <stem>.state.safetensors beside -o");
  app.add_option("--log", o->log, "per-epoch CSV");
  app.add_option("--plot", o->plot, "loss curves (PNG)");
  app.add_option("--cache", o->cache, "flow cache folder (default: <program cache>/flows)");
  // Checked at parse: NaN, inf or a negative budget was taken silently (NaN and negatives read as
  // "not given", inf cast to an unsigned byte count is undefined). 1e6 MB (a terabyte) keeps the
  // byte count far inside uint64.
  app.add_option("--cache-budget", o->cache_budget_mb, "largest flow cache per sequence, MB (else not cached)")
      ->check(finite_non_negative_up_to(1e6, "MB"));
  app.add_flag("--no-flow-cache", o->no_flow_cache, "compute flows afresh and cache nothing");
  // What a recipe fixes: giving one of these beside --recipe is refused (its head would not be the
  // recipe's).
  std::vector<CLI::Option*> fixed;
  for (const char* name : {"--flow", "--weights", "--epochs", "--batch", "--lr", "--optimizer", "--momentum",
                           "--weight-decay", "--lr-schedule", "--seed", "--head-size", "--target", "--head-input",
                           "--dropout", "--augment-rotation", "--augment-flips", "--time-offset", "--ensemble"}) {
    fixed.push_back(app.get_option(name));
  }
  return [o, &global, fixed]() {
    std::unique_ptr<TrainingRecipe> recipe;
    if (o->recipe.empty()) {
      if (o->train.empty() || o->val.empty()) {
        throw invalid_input(std::string(o->train.empty() ? "--train" : "--val") +
                            " is required (or --recipe general: a head from the project's synthetic sequences)");
      }
      if (!o->work.empty() || o->recipe_scale != "full") {
        throw invalid_input(std::string(o->work.empty() ? "--recipe-scale" : "--work") + " is for --recipe");
      }
    } else {
      recipe = std::make_unique<TrainingRecipe>(training_recipe(o->recipe, o->recipe_scale));
      for (const CLI::Option* option : fixed) {
        if (option->count() > 0) {
          throw invalid_input(option->get_name() + " with --recipe " + o->recipe +
                              ": the recipe fixes it (its head is reproducible from the recipe's name and version); "
                              "leave it out, or train without --recipe");
        }
      }
      // The user's sequences, checked before minutes of rendering.
      for (const auto* list : {&o->train, &o->val}) {
        for (const auto& path : *list) {
          std::error_code ec;
          if (!fs::exists(path, ec)) {
            throw invalid_input(std::string(list == &o->train ? "--train " : "--val ") + path +
                                ": no such sequence (a EuRoC folder or a ROS bag)");
          }
        }
      }
      o->head_size = std::to_string(recipe->trainer.head.input_width) + "x" + std::to_string(recipe->trainer.head.input_height);
    }
    const auto [width, height] = parse_size(o->head_size);
    TrainerOptions options;
    options.head.input_width = width;
    options.head.input_height = height;
    options.head.dropout = o->dropout;
    options.optimizer = parse_optimizer(o->optimizer);
    options.schedule = parse_lr_schedule(o->schedule);
    options.lr = o->lr;
    options.momentum = o->momentum;
    options.weight_decay = o->weight_decay;
    options.epochs = o->epochs;
    options.batch = o->batch;
    options.seed = parse_seed(o->seed);
    options.flip_augmentation = o->augment_flips;
    options.rotation_augmentation_deg_s = o->augment_rotation;
    if (recipe) options = recipe->trainer;
    options.head.validate();

    TrainingSetOptions set_options;
    set_options.width = static_cast<int>(width);
    set_options.height = static_cast<int>(height);
    set_options.flow = parse_flow_method(o->flow);
    set_options.input = parse_head_input(o->head_input);
    set_options.target = parse_sync_target(o->target);
    if (recipe) {
      set_options.flow = recipe->flow;
      set_options.input = recipe->input;
      set_options.target = recipe->target;
    }
    if (!o->time_offset.empty()) set_options.time_offset_s = parse_seconds(o->time_offset, "--time-offset");
    set_options.bag_input.bag = o->bag;
    if (!o->T_cam_imu.empty()) set_options.bag_input.camera_imu = parse_camera_imu(o->T_cam_imu, "--T-cam-imu");
    if (set_options.flow == FlowMethod::FlowNet && o->weights.empty()) {
      throw invalid_input("--flow flownet2 needs FlowNet2 weights (--weights FILE)");
    }

    // An ensemble (--ensemble K, or the recipe's members; models/head_ensemble.hpp): K heads of
    // the same settings with seeds seed, seed+1, …, each with its own files (<stem>.member<k> for
    // every output), then their best heads in one file at -o. One member: the files as named.
    const int members = recipe ? recipe->members : o->ensemble;
    const fs::path out = o->out;
    struct MemberFiles {
      fs::path best, last, state, log, plot;
    };
    const auto member_file = [members](const fs::path& path, int k) {
      if (members == 1 || path.empty()) return path;
      return path.parent_path() / (path.stem().string() + ".member" + std::to_string(k) + path.extension().string());
    };
    std::vector<MemberFiles> files;
    for (int k = 0; k < members; ++k) {
      MemberFiles f;
      f.best = member_file(out, k);
      f.last = sibling(f.best, ".last.safetensors");
      f.state = sibling(f.best, ".state.safetensors");
      f.log = member_file(o->log, k);
      f.plot = member_file(o->plot, k);
      files.push_back(f);
    }
    // Every output, checked before anything is computed.
    std::vector<Output> outputs;
    if (members > 1) outputs.push_back({out, "-o"});
    for (int k = 0; k < members; ++k) {
      const std::string of = members > 1 ? " of ensemble member " + std::to_string(k) : std::string();
      outputs.push_back({files[k].best, members > 1 ? "the best head" + of + " (beside -o)" : "-o"});
      outputs.push_back({files[k].last, "the last head" + of + " (beside -o)"});
      outputs.push_back({files[k].state, "the training state" + of + " (beside -o)"});
      if (!o->log.empty()) outputs.push_back({files[k].log, "--log" + of});
      if (!o->plot.empty()) outputs.push_back({files[k].plot, "--plot" + of});
    }
    if (!o->plot.empty()) {
      std::string extension = fs::path(o->plot).extension().string();
      for (auto& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      if (extension != ".png") throw invalid_input("--plot " + o->plot + ": the name must end in .png.");
    }
    std::vector<std::string> sequences = o->train;
    sequences.insert(sequences.end(), o->val.begin(), o->val.end());
    check_outputs(outputs, o->weights, sequences);

    if (recipe) {
      const fs::path work = o->work.empty() ? default_cache_directory() / "recipes" : fs::path(o->work);
      const RenderedRecipe rendered =
          render_recipe(*recipe, work, [](const std::string& name, std::size_t i, std::size_t n) {
            info("rendering " + name + " (" + std::to_string(i + 1) + " of " + std::to_string(n) + ")");
          });
      info("recipe " + o->recipe + " v" + std::to_string(recipe->version) + " (" + recipe->scale + "): " +
           std::to_string(rendered.train.size()) + " training and " + std::to_string(rendered.val.size()) +
           " validation sequences in " + work.string() + " (" + std::to_string(rendered.rendered) + " rendered now)");
      std::vector<std::string> train, val;
      for (const auto& p : rendered.train) train.push_back(p.string());
      for (const auto& p : rendered.val) val.push_back(p.string());
      train.insert(train.end(), o->train.begin(), o->train.end());
      val.insert(val.end(), o->val.begin(), o->val.end());
      o->train = train;
      o->val = val;
    }

    std::unique_ptr<Device> device = open_device(global);
    // Every member's trainer, and its state with --resume, before the flows.
    std::vector<std::unique_ptr<Trainer>> trainers;
    std::vector<bool> done(static_cast<std::size_t>(members), false);
    for (int k = 0; k < members; ++k) {
      TrainerOptions member_options = options;
      member_options.seed = options.seed + static_cast<std::uint64_t>(k);
      trainers.push_back(std::make_unique<Trainer>(*device, member_options));  // refuses options no run can use
      Trainer& trainer = *trainers.back();
      const fs::path& state_path = files[k].state;
      if (!o->resume) continue;
      std::error_code ec;
      if (!fs::exists(state_path, ec)) {
        throw invalid_input("--resume: there is no training state " + state_path.string() +
                            " (train writes it beside -o after every epoch; resume with the -o of that run)");
      }
      trainer.resume(state_path);
      if (trainer.finished()) {
        info("nothing to do: " + state_path.string() + " has finished epoch " + std::to_string(trainer.epochs_done()) +
             " of --epochs " + std::to_string(options.epochs) + "; raise --epochs to train on." +
             (members > 1 ? std::string(" Its best head is kept as it is.") : std::string(" No file was written.")));
        done[static_cast<std::size_t>(k)] = true;
        continue;
      }
      info("resuming after epoch " + std::to_string(trainer.epochs_done()) + " from " + state_path.string());
    }
    // Every member finished already: nothing to train; an ensemble is written again from the members'
    // best heads (a run stopped between its last member and the ensemble file has none yet).
    const auto write_ensemble = [&] {
      std::vector<std::string> bests;
      for (const auto& f : files) bests.push_back(f.best.string());
      write_head_ensemble(out.string(), bests);
      std::printf("wrote %s (an ensemble of the %d members' best heads)\n", out.string().c_str(), members);
    };
    if (std::all_of(done.begin(), done.end(), [](bool d) { return d; })) {
      if (members > 1) write_ensemble();
      flush_standard_output();
      return 0;
    }
    // Opened (and their targets checked by the atomic writer) before the flows.
    std::vector<std::unique_ptr<TrainingLog>> logs(static_cast<std::size_t>(members));
    if (!o->log.empty()) {
      for (int k = 0; k < members; ++k) {
        if (done[static_cast<std::size_t>(k)]) continue;
        logs[k] = std::make_unique<TrainingLog>(files[k].log.string(), o->resume ? trainers[k]->epochs_done() : -1);
      }
    }

    WeightSet flownet;
    if (set_options.flow == FlowMethod::FlowNet) {
      flownet = WeightSet::load(*device, o->weights);
      warn_if_synthetic(flownet);
      set_options.flownet_weights = &flownet;
      set_options.device = device.get();
      std::string id;
      for (const auto& w : o->weights) {
        std::error_code ec;
        id += w + ":" + std::to_string(fs::file_size(w, ec)) + ":" +
              std::to_string(fs::last_write_time(w, ec).time_since_epoch().count()) + ";";
      }
      set_options.weights_id = id;
    }
    if (!o->no_flow_cache) set_options.cache_dir = o->cache.empty() ? default_cache_directory() / "flows" : fs::path(o->cache);
    if (o->cache_budget_mb >= 0) set_options.cache_budget_bytes = static_cast<std::uint64_t>(o->cache_budget_mb * 1048576.0);

    TrainingSet train_set(set_options), val_set(set_options);
    auto load = [&](TrainingSet& set, const std::vector<std::string>& roots, const char* what) {
      for (const auto& root : roots) {
        std::unique_ptr<Progress> progress;
        const std::size_t n = set.add_sequence(root, [&](const std::string& name, std::size_t pair, std::size_t pairs) {
          if (!progress) progress = std::make_unique<Progress>(std::string(what) + " flows " + name, pairs);
          progress->update(pair);
        });
        progress.reset();
        info(std::string(what) + " " + root + ": " + std::to_string(n) + " pairs");
      }
      for (const auto& note : set.notes()) info("  " + note);
    };
    load(train_set, o->train, "train");
    load(val_set, o->val, "val");

    for (int k = 0; k < members; ++k) {
      if (done[static_cast<std::size_t>(k)]) continue;
      Trainer& trainer = *trainers[static_cast<std::size_t>(k)];
      const MemberFiles& f = files[static_cast<std::size_t>(k)];
      TrainingLog* log = logs[static_cast<std::size_t>(k)].get();
      const std::uint64_t seed = options.seed + static_cast<std::uint64_t>(k);
      if (members > 1) info("ensemble member " + std::to_string(k) + " of " + std::to_string(members) + ": seed " + std::to_string(seed));
      std::vector<double> plot_epochs, plot_train, plot_val;

      auto metadata = [&](const EpochReport& r) {
        nlohmann::json j;
        j["optimizer"] = to_string(options.optimizer);
        j["lr"] = options.lr;
        j["momentum"] = options.momentum;
        j["weight_decay"] = options.weight_decay;
        j["lr_schedule"] = to_string(options.schedule);
        j["epochs"] = options.epochs;
        j["batch"] = options.batch;
        j["seed"] = seed;
        if (members > 1) j["ensemble_member"] = k;
        j["augment_flips"] = options.flip_augmentation;
        j["augment_rotation_deg_s"] = options.rotation_augmentation_deg_s;
        j["dropout"] = options.head.dropout;
        j["head_input"] = to_string(set_options.input);
        j["flow"] = to_string(set_options.flow);
        j["input_size"] = std::to_string(options.head.input_width) + "x" + std::to_string(options.head.input_height);
        j["target"] = to_string(set_options.target);
        j["time_offset_s"] = set_options.time_offset_s;
        j["frame"] = camera_frame_targets(set_options.input) ? "camera" : "body";
        if (recipe) j["recipe"] = nlohmann::json::parse(recipe_to_json(*recipe));
        j["train_sequences"] = train_set.sequences();
        j["val_sequences"] = val_set.sequences();
        j["epoch"] = r.epoch;
        j["val_rmse_deg_s"] = nlohmann::json::parse(vec3_json(r.val_rmse_deg_s));
        j["zero_rmse_deg_s"] = nlohmann::json::parse(vec3_json(r.zero_rmse_deg_s));
        j["spread_ratio"] = nlohmann::json::parse(vec3_json(r.spread_ratio));
        j["gain"] = nlohmann::json::parse(vec3_json(r.gain));
        // What predict reads to feed the head as it was trained (models/head_input.hpp).
        const std::string input = head_input_to_json(
            {set_options.input, to_string(set_options.flow), camera_frame_targets(set_options.input)});
        std::map<std::string, std::string> meta{{"inertialnet.training", j.dump()}, {kMetadataHeadInput, input}};
        if (recipe) meta["inertialnet.recipe"] = recipe_to_json(*recipe);
        return meta;
      };

      Progress* bar = nullptr;
      std::unique_ptr<Progress> epoch_bar;
      TrainerCallbacks callbacks;
      callbacks.stop = &interrupt_requested();
      callbacks.on_batch = [&](int epoch, std::size_t b, std::size_t batches, double) {
        if (b == 1) {
          epoch_bar = std::make_unique<Progress>("epoch " + std::to_string(epoch) + "/" + std::to_string(options.epochs), batches);
          bar = epoch_bar.get();
        }
        bar->update(b);
      };
      callbacks.on_epoch = [&](const EpochReport& r) {
        epoch_bar.reset();
        char line[512];
        std::snprintf(line, sizeof line,
                      "epoch %d/%d  lr %.3g  train %.5g  val %.5g  RMSE %.2f %.2f %.2f deg/s (zero %.2f %.2f %.2f)  "
                      "spread %.2f %.2f %.2f  gain %.2f %.2f %.2f  %.1f s%s",
                      r.epoch, r.epochs, r.lr, r.train_loss, r.val_loss, r.val_rmse_deg_s[0], r.val_rmse_deg_s[1],
                      r.val_rmse_deg_s[2], r.zero_rmse_deg_s[0], r.zero_rmse_deg_s[1], r.zero_rmse_deg_s[2],
                      r.spread_ratio[0], r.spread_ratio[1], r.spread_ratio[2], r.gain[0], r.gain[1], r.gain[2], r.seconds,
                      r.best ? "  best" : "");
        info(line);
        if (r.collapsed) {
          char ratio[16];
          std::snprintf(ratio, sizeof ratio, "%g", kCollapseRatio);
          warning(std::string("the predictions' spread fell below ") + ratio +
                  " of the targets' on some axis: the head is collapsing towards the mean (the paper's "
                  "\"same-value problem\"); try a larger learning rate, Adam, or more epochs");
        }
        if (log) log->append(r);
        plot_epochs.push_back(r.epoch);
        plot_train.push_back(r.train_loss);
        plot_val.push_back(r.val_loss);
        if (!o->plot.empty()) {
          plot_loss_curves(f.plot.string(), plot_epochs, {{"train", plot_train}, {"validation", plot_val}},
                           "InertialNet head training (MSE, rad^2/s^2)");
        }
      };
      bool wrote_best = false;
      auto on_best = [&](const EpochReport& r) {
        trainer.save_head(f.best, metadata(r));
        wrote_best = true;
      };
      auto on_last = [&](const EpochReport& r) {
        trainer.save_head(f.last, metadata(r));
        trainer.save_state(f.state);
      };

      const bool finished = [&] {
        const InterruptGuard guard;
        return trainer.train(train_set, val_set, callbacks, on_best, on_last);
      }();
      epoch_bar.reset();
      if (!finished) {
        // The interrupted epoch does not count; its partial updates are in the last head.
        EpochReport r = trainer.last();
        trainer.save_head(f.last, metadata(r));
        if (trainer.epochs_done() == 0) trainer.save_head(f.best, metadata(r));
        end_progress_line();
        std::cerr << "inertialnet: interrupted: " << f.last.string() << " holds the weights so far; "
                  << f.state.string() << " resumes after epoch " << trainer.epochs_done()
                  << (members > 1 ? " (rerun with --resume: every member resumes from its own state)" : "") << "\n";
        return 1;
      }
      const EpochReport& best = trainer.best();
      if (wrote_best) {
        std::printf("best epoch %d: validation RMSE %.3f %.3f %.3f deg/s (zero predictor %.3f %.3f %.3f), spread %.2f %.2f %.2f\n",
                    best.epoch, best.val_rmse_deg_s[0], best.val_rmse_deg_s[1], best.val_rmse_deg_s[2],
                    best.zero_rmse_deg_s[0], best.zero_rmse_deg_s[1], best.zero_rmse_deg_s[2], best.spread_ratio[0],
                    best.spread_ratio[1], best.spread_ratio[2]);
        std::printf("wrote %s (best), %s (last)\n", f.best.string().c_str(), f.last.string().c_str());
      } else {
        // Resumed, and no epoch of this run beat the state's best: the best file still holds that epoch's head.
        std::printf("best epoch %d (before this run): mean validation RMSE %.3f deg/s; no epoch of this run improved on it\n",
                    best.epoch, trainer.best_mean_rmse_deg_s());
        std::printf("kept %s (best), wrote %s (last)\n", f.best.string().c_str(), f.last.string().c_str());
      }
      flush_standard_output();
    }
    if (members > 1) write_ensemble();
    flush_standard_output();
    return 0;
  };
}

}  // namespace inertialnet::cli
