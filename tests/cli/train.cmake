# `inertialnet train` as a user meets it, on tiny synthetic sequences: the per-epoch report and
# CSV, the loss plot, best/last checkpoints with training metadata that predict loads, resuming,
# predict refusing a head of another flow size, and bad usage.
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

run(0 ${CLI} predict b --weights head.safetensors --flow dis -o rates.csv)
run(2 ${CLI} predict big --weights head.safetensors --flow dis -o rates.csv)
expect_match("built for 64×48 flow")

# FlowNet flows (FlowNet2-C with synthetic weights, the lightest family member): the flow method
# and the weights' identity key the cache apart from DIS's.
run(0 ${CLI} weights --synthetic FlowNet2-C -o c.safetensors)
run(0 ${CLI} train --train a --val b --flow flownet2 --weights c.safetensors --head-size 32x24 --epochs 1
    -o fc.safetensors --cache cache)
expect_match("synthetic")
expect_match("flows cached in")
run(0 ${CLI} weights --info fc.safetensors)
expect_match("\"flow\":\"flownet2\"")

run(2 ${CLI} train --train a --val b --head-size 64x48 --optimizer nadam -o x.safetensors)
expect_match("unknown optimizer 'nadam'")
run(2 ${CLI} train --train a --val b --flow flownet2 --head-size 64x48 -o x.safetensors)
expect_match("needs FlowNet2 weights")
run(2 ${CLI} train --train nowhere --val b --head-size 64x48 -o x.safetensors)
expect_match("nowhere is not a EuRoC sequence")
