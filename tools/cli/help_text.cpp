// SPDX-License-Identifier: Apache-2.0
#include "help_text.hpp"

#include <map>

namespace inertialnet::cli {

std::string help_examples(const std::string& subcommand) {
  static const std::map<std::string, std::string> examples = {
      {"",
       "  inertialnet devices                                  # which OpenCL devices there are\n"
       "  inertialnet synth data/seq --frames 40               # a synthetic EuRoC sequence\n"
       "  inertialnet predict data/seq -o rates.csv            # weight-free: LK flow + geometric head\n"
       "  inertialnet eval rates.csv data/seq --plot rates.png # the paper's metrics and plots\n"
       "  inertialnet predict --help                           # the options of one subcommand\n"},
      {"devices",
       "  inertialnet devices\n"
       "  inertialnet devices --json\n"
       "  inertialnet devices --device gpu                     # what a spec selects\n"},
      {"flow",
       "  inertialnet flow a.png b.png -w flownet2.safetensors -o ab.flo --png ab.png\n"
       "  inertialnet flow a.png b.png -w flownet2-c.safetensors --model flownet2-c --profile\n"},
      {"predict",
       "  inertialnet predict data/seq -o out/rates.csv                        # DIS + geometric head\n"
       "  inertialnet predict data/seq -w flownet2.safetensors -w head.safetensors --head both -o rates.csv\n"
       "  inertialnet predict video.mp4 --fx 458 --rate 20 --stats\n"
       "  inertialnet predict video.mp4 --calibration camera.yaml   # Kalibr camchain, OpenCV YAML/XML, sensor.yaml\n"
       "  inertialnet predict data/seq --flow DIS --save-flow out/flows -q\n"
       "  inertialnet predict clip.mp4 --fx 900 --format gcsv -o clip.gcsv     # Gyroflow gyro log\n"
       "  inertialnet predict /dev/video0 --fx 600 | tail -f                  # live until Ctrl-C\n"},
      {"eval",
       "  inertialnet eval rates.csv data/seq\n"
       "  inertialnet eval rates.csv data/seq --plot out/rates.png --target mean\n"
       "  inertialnet eval rates.csv data/seq --json --series > report.json\n"
       "  inertialnet eval rates.csv data/seq --time-offset auto --gyro-bias auto\n"
       "  inertialnet eval rates.csv data/seq --calibration-from calib.json  # calibrate --json's offset and rotation\n"
       "  inertialnet eval rates.csv clip.mp4 --imu imu.csv --camchain camchain-imucam.yaml  # Kalibr's calibration\n"
       "  inertialnet eval rates.csv frames/ --imu imu.csv --T-cam-imu '0 -1 0 0  1 0 0 0  0 0 1 0  0 0 0 1'\n"},
      {"calibrate-sigma",
       "  inertialnet calibrate-sigma head.safetensors --val val1 val2            # fit, and write into the head\n"
       "  inertialnet calibrate-sigma head.safetensors --val val1 --dry-run       # print the fit only\n"},
      {"export",
       "  inertialnet export rates.csv --format gyroflow -o clip.gcsv            # Gyroflow's gyro log\n"
       "  inertialnet export rates.csv --format euroc-imu -o virtual/imu0/data.csv # a gyro for a VIO to replay\n"
       "  inertialnet export rates.csv --format tum --head geometric -o orientation.txt  # evo_traj tum orientation.txt\n"},
      {"calibrate",
       "  inertialnet calibrate data/seq                       # offset, rotation and readout, predicting weight-free\n"
       "  inertialnet calibrate data/seq --json > calib.json && inertialnet eval rates.csv data/seq --calibration-from calib.json\n"
       "  inertialnet calibrate phone.mp4 --imu gyro.csv --calibration camchain-imucam.yaml --readout-max 0.05\n"},
      {"calibrate-time",
       "  inertialnet calibrate-time data/seq                  # predicts weight-free, then estimates\n"
       "  inertialnet calibrate-time data/seq rates.csv --range 0.3\n"
       "  inertialnet calibrate-time clip.mp4 --imu imu.csv --calibration camchain-imucam.yaml\n"},
      {"viz",
       "  inertialnet viz out/flows/*.flo -o out/pictures --shared-scale   # one scale for a sequence\n"
       "  inertialnet viz ab.flo --legend --max-magnitude 20\n"},
      {"train",
       "  inertialnet train --train data/s1 data/s2 --val data/s3 -o head.safetensors --epochs 20\n"
       "  inertialnet train --train data/s1 --val data/s2 --optimizer adam --lr 1e-3 --head-size 64x48 \\\n"
       "      --log out/train.csv --plot out/loss.png -o out/head.safetensors\n"
       "  inertialnet train --train data/s1 --val data/s2 -o head.safetensors --resume\n"},
      {"synth",
       "  inertialnet synth data/seq --frames 40 --seed 1\n"
       "  inertialnet synth data/general --motion general --size 376x240 --no-noise --overwrite\n"},
      {"bench",
       "  inertialnet bench --model FlowNet2-C --size 256x192 --pairs 3\n"
       "  inertialnet bench --device all --json > bench.json\n"},
      {"tune",
       "  inertialnet tune --quick                              # the packed kernel's search, seconds\n"
       "  inertialnet tune --model FlowNet2-C --size 512x384 --json > tune.json\n"
       "  inertialnet tune --show                               # what is stored and in force\n"},
      {"weights",
       "  inertialnet weights --synthetic FlowNet2 -o flownet2.safetensors\n"
       "  inertialnet weights --synthetic InertialNetHead --size 752x480 -o head.safetensors\n"
       "  inertialnet weights --info flownet2.safetensors\n"},
      {"completion",
       "  inertialnet completion bash > /etc/bash_completion.d/inertialnet\n"
       "  inertialnet completion zsh > ~/.zfunc/_inertialnet\n"},
      {"man",
       "  inertialnet man > inertialnet.1 && man ./inertialnet.1\n"},
  };
  const auto found = examples.find(subcommand);
  return found == examples.end() ? std::string() : "Examples:\n" + found->second;
}

}  // namespace inertialnet::cli
