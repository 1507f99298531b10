# SPDX-License-Identifier: Apache-2.0
# `inertialnet train` as a user meets it, on tiny synthetic sequences: the per-epoch report and
# CSV, the loss plot, best/last checkpoints with training metadata that predict loads, resuming,
# predict refusing a head of another flow size, and bad usage; and that no result is lost or
# falsified (issue 20): a diverging run stops without a NaN head, every output is checked before
# the flows, resuming a finished or a foreign state, -q and the prefix of every line.
#   cmake -DCLI=<inertialnet> -DWORK=<scratch dir> -P train.cmake
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")

include(${CMAKE_CURRENT_LIST_DIR}/run_helpers.cmake)

run(0 ${CLI} synth a --frames 12 --motion general --size 64x48 --seed 31)
run(0 ${CLI} synth b --frames 12 --motion general --size 64x48 --seed 32)
run(0 ${CLI} synth big --frames 3 --motion general --size 96x64 --seed 33)

run(0 ${CLI} train --train a --val b --head-size 64x48 --optimizer adam --lr 1e-3 --epochs 2 -o head.safetensors
    --log train.csv --plot loss.png --cache cache)
expect_match("epoch 1/2 +lr 0.001 +train [0-9.e-]+ +val [0-9.e-]+ +RMSE [0-9.]+ [0-9.]+ [0-9.]+ deg/s \\(zero")
expect_match("flows cached in")
expect_match("wrote head.safetensors \\(best\\), head.last.safetensors \\(last\\)")
foreach(f head.safetensors head.last.safetensors head.state.safetensors loss.png)
  if(NOT EXISTS "${WORK}/${f}")
    message(FATAL_ERROR "train did not write ${f}")
  endif()
endforeach()
file(STRINGS "${WORK}/train.csv" rows)
list(LENGTH rows count)
if(NOT count EQUAL 3)
  message(FATAL_ERROR "train.csv has ${count} lines, expected a header and 2 epochs")
endif()
run(0 ${CLI} weights --info head.safetensors)
expect_match("inertialnet.training = .*\"flow\":\"dis\".*\"input_size\":\"64x48\".*\"train_sequences\":\\[\"a\"\\]")

# A second run reads the cached flows; --resume continues after epoch 2.
run(0 ${CLI} train --train a --val b --head-size 64x48 --optimizer adam --lr 1e-3 --epochs 3 -o head.safetensors
    --log train.csv --cache cache --resume)
expect_match("read from the cache")
expect_match("resuming after epoch 2")
expect_match("epoch 3/3")

# Resuming a state that has done every epoch: nothing to do, and nothing claimed as written.
run(0 ${CLI} train --train a --val b --head-size 64x48 --optimizer adam --lr 1e-3 --epochs 3 -o head.safetensors
    --cache cache --resume)
expect_match("inertialnet: nothing to do: head.state.safetensors has finished epoch 3 of --epochs 3")
expect_no_match("wrote")
# Another optimiser than the state's (SGD's velocity is not Adam's moment): refused, naming both.
run(2 ${CLI} train --train a --val b --head-size 64x48 --optimizer sgd --lr 1e-3 --epochs 4 -o head.safetensors
    --cache cache --resume)
expect_match("head.state.safetensors was trained with the optimizer adam, this run asks for sgd")
# A resumed run whose epochs do not beat the state's best (a learning rate too small to move a
# weight): -o keeps that epoch's head and says so (before: "best epoch 0 … 0.000", "wrote (best)").
file(SHA256 "${WORK}/head.safetensors" best_before)
run(0 ${CLI} train --train a --val b --head-size 64x48 --optimizer adam --lr 1e-30 --epochs 4 -o head.safetensors
    --cache cache --resume)
# (The state's best is one of its epochs 1–3: which one depends on the trajectory, not on resume.)
expect_match("best epoch [1-3] \\(before this run\\): mean validation RMSE [0-9.]+ deg/s; no epoch of this run improved")
expect_match("kept head.safetensors \\(best\\), wrote head.last.safetensors \\(last\\)")
file(SHA256 "${WORK}/head.safetensors" best_after)
if(NOT best_before STREQUAL best_after)
  message(FATAL_ERROR "the best head changed although no epoch improved")
endif()
# A state whose epoch is not a number (edited in place, same length, so the file stays readable):
# exit 2 naming the file and the key (before: "error: stoi", exit 1).
file(MAKE_DIRECTORY "${WORK}/damaged")
file(COPY_FILE "${WORK}/head.state.safetensors" "${WORK}/damaged/h.state.safetensors")
execute_process(COMMAND sed -i -E "s/\"inertialnet\\.train\\.epoch\":\"[0-9]\"/\"inertialnet.train.epoch\":\"x\"/"
                        "${WORK}/damaged/h.state.safetensors" RESULT_VARIABLE sed_code)
if(NOT sed_code EQUAL 0)
  message(FATAL_ERROR "sed could not edit the state")
endif()
run(2 ${CLI} train --train a --val b --head-size 64x48 --optimizer adam --epochs 5 -o damaged/h.safetensors
    --cache cache --resume)
expect_match("damaged/h.state.safetensors: the training state's inertialnet.train.epoch is 'x', expected a whole number")
run(2 ${CLI} train --train a --val b --head-size 64x48 --epochs 4 -o nostate.safetensors --cache cache --resume)
expect_match("--resume: there is no training state nostate.state.safetensors")

# -q: no progress, notes or epoch lines; the result still on standard output. Without -q every
# line on stderr carries the prefix (only the report lines on stdout do not).
run(0 ${CLI} train --train a --val b --head-size 64x48 --optimizer adam --lr 1e-3 --epochs 1 -o quiet.safetensors
    --cache cache -q)
expect_no_match("epoch 1/1|pairs|read from the cache|Target:")
expect_match("^best epoch 1: validation RMSE")
run(0 ${CLI} train --train a --val b --head-size 64x48 --optimizer adam --lr 1e-3 --epochs 1 -o loud.safetensors
    --cache cache)
string(REGEX REPLACE "[];[]" "," lines "${output}")  # no list separators or brackets inside a line
string(REPLACE "\n" ";" lines "${lines}")
foreach(line IN LISTS lines)
  if(NOT line MATCHES "^(inertialnet: |best epoch |wrote |kept |$)")
    message(FATAL_ERROR "a line without the inertialnet: prefix: '${line}'")
  endif()
endforeach()

# A diverging learning rate: exit 1 naming the epoch, the mini-batch and the likely cause; no head
# (before: -nan epochs, "wrote diverged.safetensors (best)", exit 0).
run(1 ${CLI} train --train a --val b --head-size 64x48 --optimizer adam --lr 1e6 --epochs 2 -o diverged.safetensors
    --cache cache)
expect_match("inertialnet: error: training stopped: the loss of epoch 1, mini-batch [0-9]+ of [0-9]+ is (inf|-?nan)")
expect_match("the learning rate 1e\\+06 is likely too large")
expect_no_match("wrote|best epoch")
if(EXISTS "${WORK}/diverged.safetensors")
  message(FATAL_ERROR "a diverged run wrote a head")
endif()

# Outputs: missing folders created (as docs/cli.md promises), for -o, --log and --plot alike.
run(0 ${CLI} train --train a --val b --head-size 64x48 --optimizer adam --lr 1e-3 --epochs 1 --cache cache
    -o new/heads/h.safetensors --log new/logs/train.csv --plot new/plots/loss.png)
foreach(f new/heads/h.safetensors new/heads/h.state.safetensors new/logs/train.csv new/plots/loss.png)
  if(NOT EXISTS "${WORK}/${f}")
    message(FATAL_ERROR "train did not write ${f}")
  endif()
endforeach()
# Refused before any flow is computed (a fresh cache stays empty): a device node or a FIFO as the
# log (before: the log lost with exit 0, or a block forever), a folder as -o, an input as an output,
# two outputs naming one file, a plot that is not PNG.
set(T0 ${CLI} train --train a --val b --head-size 64x48 --epochs 1)
set(T ${T0} --cache fresh_cache)
run(2 ${T} -o h.safetensors --log /dev/null)
expect_match("--log /dev/null: it exists and is not a regular file")
execute_process(COMMAND mkfifo "${WORK}/fifo")
run(2 ${T} -o h.safetensors --log fifo)
expect_match("--log fifo: it exists and is not a regular file")
run(2 ${T} -o new)
expect_match("-o new: it exists and is not a regular file \\(a folder\\)")
run(2 ${T} -o a/mav0/cam0/data.csv)
expect_match("-o a/mav0/cam0/data.csv is inside the sequence a")
run(2 ${T} -o h.safetensors --plot b/mav0/loss.png)
expect_match("--plot b/mav0/loss.png is inside the sequence b")
run(2 ${T} -o b/mav0/heads/h.safetensors)
expect_match("-o b/mav0/heads/h.safetensors is inside the sequence b")
if(EXISTS "${WORK}/b/mav0/heads")
  message(FATAL_ERROR "a refused output left a new folder inside a sequence")
endif()
run(2 ${T} -o h.safetensors --log h.last.safetensors)
expect_match("the last head \\(beside -o\\) and --log name one file \\(h.last.safetensors\\)")
run(2 ${T} -o h.safetensors --log l.csv --plot l.csv)
expect_match("--plot l.csv: the name must end in .png")
run(2 ${T} -o h.safetensors --log same.png --plot same.png)
expect_match("--log and --plot name one file \\(same.png\\)")
if(EXISTS "${WORK}/fresh_cache")
  message(FATAL_ERROR "flows were computed before the outputs were refused")
endif()
if(NOT EXISTS "${WORK}/a/mav0/cam0/data.csv")
  message(FATAL_ERROR "train replaced a sequence's file")
endif()

# Bad numbers: refused, not wrapped or accepted.
run(2 ${T} -o h.safetensors --seed -1)
expect_match("inertialnet: error: --seed '-1': the seed is a whole number")
run(2 ${T} -o h.safetensors --weight-decay -5)
expect_match("the weight decay must be a finite number ≥ 0, got -5")

# A flow cache that cannot be written (here its folder cannot be created) is a warning; training goes on.
file(WRITE "${WORK}/a_file" "x")
run(0 ${T0} -o uncached.safetensors --cache a_file/cache)
expect_match("inertialnet: warning: the flows of a were not cached \\(.*\\); training goes on")
if(NOT EXISTS "${WORK}/uncached.safetensors")
  message(FATAL_ERROR "train did not write its head without a cache")
endif()

# The cache key covers every frame: an image replaced after the flows were cached is a new key,
# not stale flows (before: keyed by path, frame count and first/last timestamp only).
run(0 ${CLI} synth c --frames 8 --motion general --size 64x48 --seed 34)
run(0 ${CLI} train --train c --val b --head-size 64x48 --epochs 1 --cache cache -o c_head.safetensors)
expect_match("c: flows cached in")
file(GLOB c_frames "${WORK}/c/mav0/cam0/data/*.png")
list(SORT c_frames)
list(GET c_frames 4 frame4)
list(GET c_frames 5 frame5)
file(COPY_FILE "${frame5}" "${frame4}")
run(0 ${CLI} train --train c --val b --head-size 64x48 --epochs 1 --cache cache -o c_head.safetensors)
expect_match("c: flows cached in")
expect_no_match("c: flows read from the cache")

run(0 ${CLI} predict b --weights head.safetensors --flow dis -o rates.csv)
# Issue 23: the head's metadata says how it was trained (normalized input, DIS flow): predict
# needs no --flow, turns the flow of frames of another size into the head's input as train did
# (before: "built for 64×48 flow", exit 2), and refuses a flow the head never saw.
run(0 ${CLI} weights --info head.safetensors)
# A normalized head learns camera-frame rates and says so (predict turns them into the body frame).
expect_match("inertialnet.head_input = \\{\"convention\":\"normalized\",\"flow\":\"dis\",\"frame\":\"camera\"\\}")
run(0 ${CLI} predict big --weights head.safetensors -o rates_big.csv)
expect_match("DIS flow \\+ InertialNet head")
run(2 ${CLI} predict big --weights head.safetensors --flow flownet2 -o rates_big.csv)
expect_match("inertialnet: error: --flow flownet2: the InertialNet head in head.safetensors was trained on dis flow")
# Its input is divided by the focal lengths: an image folder without a calibration is refused
# (exit 2) before any flow, and with --fx it runs.
run(2 ${CLI} predict b/mav0/cam0/data --weights head.safetensors -o rates_folder.csv)
expect_match("this InertialNet head \\(trained on normalized input\\) needs the camera")
run(0 ${CLI} predict b/mav0/cam0/data --weights head.safetensors --fx 40 -o rates_folder.csv)
# A head without that metadata (converted, or trained before it) is the paper's: pixel flow,
# resized the same way; a normalized one needs the camera.
run(0 ${CLI} weights --synthetic InertialNetHead --size 64x48 -o paper_head.safetensors)
run(0 ${CLI} predict big --weights paper_head.safetensors --flow dis -o rates_paper.csv)
run(0 ${CLI} train --train a --val b --head-size 64x48 --head-input paper --epochs 1 --augment-rotation 30
    --dropout 0 -o paper_trained.safetensors --cache cache)
run(0 ${CLI} weights --info paper_trained.safetensors)
expect_match("\"convention\":\"paper\"")
expect_match("\"augment_rotation_deg_s\":30")
run(2 ${CLI} train --train a --val b --head-size 64x48 --head-input pixels -o x.safetensors)
expect_match("unknown head input 'pixels'; expected normalized or paper")
run(2 ${CLI} train --train a --val b --head-size 64x48 --augment-rotation -5 -o x.safetensors)
expect_match("--augment-rotation: must be a finite number from 0 up, got -5")  # named at parse

# FlowNet flows (FlowNet2-C with synthetic weights, the lightest family member): the flow method
# and the weights' identity key the cache apart from DIS's.
run(0 ${CLI} weights --synthetic FlowNet2-C -o c.safetensors)
run(0 ${CLI} train --train a --val b --flow flownet2 --weights c.safetensors --head-size 32x24 --epochs 1
    -o fc.safetensors --cache cache)
expect_match("synthetic")
expect_match("flows cached in")
run(0 ${CLI} weights --info fc.safetensors)
expect_match("\"flow\":\"flownet2\"")
# The weights are an input: no output may replace them.
run(2 ${CLI} train --train a --val b --flow flownet2 --weights c.safetensors --head-size 32x24 --epochs 1
    -o fc.safetensors --log c.safetensors --cache cache)
expect_match("--log \\(c.safetensors\\) would overwrite the input c.safetensors")

run(2 ${CLI} train --train a --val b --head-size 64x48 --optimizer nadam -o x.safetensors)
expect_match("unknown optimizer 'nadam'")
run(2 ${CLI} train --train a --val b --flow flownet2 --head-size 64x48 -o x.safetensors)
expect_match("needs FlowNet2 weights")
run(2 ${CLI} train --train nowhere --val b --head-size 64x48 -o x.safetensors)
expect_match("nowhere is not a EuRoC sequence")

# --- issue 23, "a head users can get": train --recipe general renders its own synthetic
# sequences and trains with fixed settings; the same command gives the same head bit for bit
# (here at --recipe-scale tiny: the recipe's code path in seconds). Two runs in other work and
# cache folders (every sequence rendered and every flow computed afresh), and a third that reuses
# the first's rendered sequences and cached flows: one file, metadata included.
run(0 ${CLI} train --recipe general --recipe-scale tiny -o recipe1/head.safetensors --work recipe_work1
    --cache recipe_cache1)
expect_match("recipe general v3 \\(tiny\\): 3 training and 1 validation sequences in recipe_work1 \\(4 rendered now\\)")
run(0 ${CLI} train --recipe general --recipe-scale tiny -o recipe2/head.safetensors --work recipe_work2
    --cache recipe_cache2)
run(0 ${CLI} train --recipe general --recipe-scale tiny -o recipe3/head.safetensors --work recipe_work1
    --cache recipe_cache1)
expect_match("\\(0 rendered now\\)")
expect_match("read from the cache")
file(SHA256 "${WORK}/recipe1/head.safetensors" recipe_head1)
foreach(n 2 3)
  file(SHA256 "${WORK}/recipe${n}/head.safetensors" recipe_head)
  if(NOT recipe_head STREQUAL recipe_head1)
    message(FATAL_ERROR "train --recipe general gave another head in run ${n} than in run 1")
  endif()
endforeach()
run(0 ${CLI} weights --info recipe1/head.safetensors)
expect_match("inertialnet.recipe = \\{\"name\":\"general\",\"scale\":\"tiny\",\"version\":3\\}")
# Version 3 trains on the fine DIS and says so: predict gives its head that flow (test_head_input_predict).
expect_match("inertialnet.head_input = \\{\"convention\":\"normalized\",\"flow\":\"dis-fine\",\"frame\":\"camera\"\\}")
expect_match("\"train_sequences\":\\[\"general-160x100\",\"close-200x150\",\"rotation-224x126\"\\]")
# The user's sequences are added to the recipe's.
run(0 ${CLI} train --recipe general --recipe-scale tiny --train a --val b -o recipe4/head.safetensors
    --work recipe_work1 --cache recipe_cache1)
run(0 ${CLI} weights --info recipe4/head.safetensors)
expect_match("\"train_sequences\":\\[\"general-160x100\",\"close-200x150\",\"rotation-224x126\",\"a\"\\]")
expect_match("\"val_sequences\":\\[\"val-general-200x150\",\"b\"\\]")
# Bad values: exit 2 naming the value, before anything is rendered.
run(2 ${CLI} train --recipe generic -o recipe_bad/head.safetensors --work recipe_work_bad)
expect_match("--recipe 'generic': no such recipe; the recipes are: general")
run(2 ${CLI} train --recipe general --train a nowhere -o recipe_bad/head.safetensors --work recipe_work_bad)
expect_match("--train nowhere: no such sequence")
run(2 ${CLI} train --recipe general --val nowhere2 -o recipe_bad/head.safetensors --work recipe_work_bad)
expect_match("--val nowhere2: no such sequence")
run(2 ${CLI} train --recipe general --recipe-scale huge -o recipe_bad/head.safetensors --work recipe_work_bad)
expect_match("--recipe-scale 'huge': expected full or tiny")
run(2 ${CLI} train --recipe general --epochs 3 -o recipe_bad/head.safetensors --work recipe_work_bad)
expect_match("--epochs with --recipe general: the recipe fixes it")
if(EXISTS "${WORK}/recipe_work_bad")
  message(FATAL_ERROR "a refused --recipe run rendered sequences")
endif()
run(2 ${CLI} train --val b -o recipe_bad/head.safetensors)
expect_match("--train is required \\(or --recipe general")
run(2 ${CLI} train --train a --val b --work w -o recipe_bad/head.safetensors)
expect_match("--work is for --recipe")

# --- issue 23, an ensemble of heads: the recipe (v2) trains its members (2 at tiny scale) with
# seeds 3 and 4, each with its own files, and writes their best heads as one file, the same bit for
# bit in every run above (the SHA-256 comparison); its sequences keep version 1's folder.
run(0 ${CLI} weights --info recipe1/head.safetensors)
expect_match("inertialnet.ensemble = \\{\"members\":2,\"version\":1\\}")
if(NOT IS_DIRECTORY "${WORK}/recipe_work1/general-v1-tiny")
  message(FATAL_ERROR "the recipe's sequences are not in general-v1-tiny")
endif()
foreach(k 0 1)
  math(EXPR seed "3 + ${k}")
  run(0 ${CLI} weights --info recipe1/head.member${k}.safetensors)
  expect_match("\"seed\":${seed}")
  expect_no_match("inertialnet.ensemble")
endforeach()
file(SHA256 "${WORK}/recipe1/head.member0.safetensors" member0)
file(SHA256 "${WORK}/recipe1/head.member1.safetensors" member1)
if(member0 STREQUAL member1)
  message(FATAL_ERROR "the recipe's two ensemble members are the same head")
endif()
run(0 ${CLI} predict a -w recipe1/head.safetensors --smooth off -o ensemble_rates.csv)
# --ensemble K without the recipe: K members' files beside -o (log and plot too), one ensemble file.
run(0 ${CLI} train --train a --val b --head-size 64x48 --optimizer adam --lr 1e-3 --epochs 1 --ensemble 2
    -o ens/head.safetensors --log ens/train.csv --plot ens/loss.png --cache cache)
expect_match("ensemble member 1 of 2: seed 2")
expect_match("wrote ens/head.safetensors \\(an ensemble of the 2 members' best heads\\)")
foreach(f head.member0.safetensors head.member1.last.safetensors head.member1.state.safetensors train.member0.csv
          train.member1.csv loss.member1.png head.safetensors)
  if(NOT EXISTS "${WORK}/ens/${f}")
    message(FATAL_ERROR "train --ensemble 2 did not write ens/${f}")
  endif()
endforeach()
# --resume: every member from its own state. Finished members are kept and the ensemble is
# written again (also when it is missing); resumed to 2 epochs, both members train their second.
file(REMOVE "${WORK}/ens/head.safetensors")
run(0 ${CLI} train --train a --val b --head-size 64x48 --optimizer adam --lr 1e-3 --epochs 1 --ensemble 2
    -o ens/head.safetensors --cache cache --resume)
expect_match("nothing to do: ens/head.member1.state.safetensors has finished epoch 1 .*Its best head is kept as it is")
expect_match("wrote ens/head.safetensors \\(an ensemble")
run(0 ${CLI} train --train a --val b --head-size 64x48 --optimizer adam --lr 1e-3 --epochs 2 --ensemble 2
    -o ens/head.safetensors --cache cache --resume)
expect_match("resuming after epoch 1 from ens/head.member0.state.safetensors")
expect_match("resuming after epoch 1 from ens/head.member1.state.safetensors")
foreach(k 0 1)
  run(0 ${CLI} weights --info ens/head.member${k}.last.safetensors)
  expect_match("\"epoch\":2")
endforeach()
run(2 ${CLI} train --train a --val b --ensemble 0 -o ens_bad/head.safetensors)
expect_match("--ensemble")
run(2 ${CLI} train --recipe general --ensemble 3 -o recipe_bad/head.safetensors --work recipe_work_bad)
expect_match("--ensemble with --recipe general: the recipe fixes it")

# --- issue 23, the fine DIS (`--flow dis-fine`): a head trained on it says so, predict runs it
# without --flow, and the other DIS asked for is refused (the head never saw it) both ways.
run(0 ${CLI} train --train a --val b --flow dis-fine --head-size 64x48 --optimizer adam --lr 1e-3 --epochs 1
    -o fine/head.safetensors --cache cache)
run(0 ${CLI} weights --info fine/head.safetensors)
expect_match("inertialnet.head_input = \\{\"convention\":\"normalized\",\"flow\":\"dis-fine\",\"frame\":\"camera\"\\}")
run(0 ${CLI} predict a -w fine/head.safetensors --smooth off -o fine/rates.csv)
expect_match("DIS flow \\(fine: full resolution\\) \\+ InertialNet head")
run(2 ${CLI} predict a -w fine/head.safetensors --flow dis -o fine/x.csv)
expect_match("--flow dis: the InertialNet head in fine/head.safetensors was trained on dis-fine flow .*give --flow dis-fine")
run(2 ${CLI} predict a -w head.safetensors --flow dis-fine -o fine/y.csv)
expect_match("was trained on dis flow .*give --flow dis")
