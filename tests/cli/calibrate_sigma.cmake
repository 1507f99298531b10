# SPDX-License-Identifier: Apache-2.0
# calibrate-sigma (issue 23, docs/cli.md "The head's own σ calibration"): a head trained here in
# seconds is calibrated on a validation sequence; the calibration lands in its metadata and predict
# --fuse applies it (the learned σ columns change); too few pairs is exit 2; a calibration with a
# negative floor or a NaN is exit 2 for predict --fuse, naming the file, the key and the value.
#   cmake -DCLI=<inertialnet> -DWORK=<scratch dir> -DPYTHON=<python3> -P calibrate_sigma.cmake
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")
include(${CMAKE_CURRENT_LIST_DIR}/run_helpers.cmake)

run(0 ${CLI} synth a --frames 12 --motion general --size 96x64 --seed 41)
run(0 ${CLI} synth b --frames 8 --motion general --size 96x64 --seed 42)
run(0 ${CLI} synth val --frames 26 --size 96x64 --seed 44)
run(0 ${CLI} synth low --frames 8 --size 96x64 --seed 43 --texture-contrast 0.1)
run(0 ${CLI} train --train a --val b --head-size 96x64 --optimizer adam --lr 1e-3 --epochs 2 --target mean
    --no-flow-cache -o head.safetensors)
file(COPY_FILE "${WORK}/head.safetensors" "${WORK}/cal.safetensors")

# b has 7 pairs: fewer than the 20 the fit needs.
run(2 ${CLI} calibrate-sigma cal.safetensors --val b --max-sigma 0)
expect_match("the σ calibration needs at least 20 validation pairs the learned head answered, got 7")
run(0 ${CLI} calibrate-sigma cal.safetensors --val val --max-sigma 0 --dry-run)
expect_match("on 25 pairs: scale")
expect_match("after: mean \\(e/σ\\)² 1.00 1.00 1.00")
run(0 ${CLI} weights --info cal.safetensors)
expect_no_match("inertialnet.sigma_calibration")
run(0 ${CLI} calibrate-sigma cal.safetensors --val val --max-sigma 0)
expect_match("wrote inertialnet.sigma_calibration into cal.safetensors")
run(0 ${CLI} weights --info cal.safetensors)
expect_match("inertialnet.sigma_calibration")

# predict --fuse applies it: the learned head's σ columns differ from the built-in model's.
foreach(h head cal)
  run(0 ${CLI} predict low -w ${h}.safetensors --head both --fuse --smooth off --max-sigma 0 -o ${h}.csv)
  file(STRINGS "${WORK}/${h}.csv" lines REGEX "^[0-9]")
  list(GET lines 0 row)
  string(REPLACE "," ";" f "${row}")
  list(GET f 5 sigma_${h})
endforeach()
if(sigma_head STREQUAL sigma_cal)
  message(FATAL_ERROR "the calibrated head's σ_x ${sigma_cal} is the built-in model's")
endif()

# Bad values in the metadata: rewritten with Python (standard library only).
file(WRITE "${WORK}/edit.py" [=[
import json, struct, sys
path, out, replacement = sys.argv[1], sys.argv[2], sys.argv[3]
data = open(path, "rb").read()
n = struct.unpack("<Q", data[:8])[0]
header = json.loads(data[8:8 + n])
meta = json.loads(header["__metadata__"]["inertialnet.sigma_calibration"])
meta["floor_rad_s"][1] = "@"
header["__metadata__"]["inertialnet.sigma_calibration"] = json.dumps(meta).replace('"@"', replacement)
text = json.dumps(header).encode()
text += b" " * (-len(text) % 8)
open(out, "wb").write(struct.pack("<Q", len(text)) + text + data[8 + n:])
]=])
run(0 ${PYTHON} edit.py cal.safetensors negative.safetensors -0.5)
run(2 ${CLI} predict low -w negative.safetensors --head both --fuse -o bad.csv)
expect_match("negative.safetensors: metadata inertialnet.sigma_calibration")
expect_match("floor_rad_s\\[1\\] \\(y\\) is -0.5: must be a finite number > 0")
run(0 ${PYTHON} edit.py cal.safetensors nan.safetensors NaN)
run(2 ${CLI} predict low -w nan.safetensors --head both --fuse -o bad.csv)
expect_match("nan.safetensors: metadata inertialnet.sigma_calibration '.*NaN.*' is not a valid σ calibration: it is not JSON")
if(EXISTS "${WORK}/bad.csv")
  message(FATAL_ERROR "a refused run left bad.csv")
endif()

# Issue 23, an ensemble of heads (train --ensemble): calibrate-sigma fits the members' spread, and
# predict --fuse uses it; a malformed inertialnet.ensemble is exit 2 naming file, key and value.
run(0 ${CLI} train --train a --val b --head-size 96x64 --optimizer adam --lr 1e-3 --epochs 2 --target mean
    --no-flow-cache --ensemble 2 -o ens.safetensors)
run(0 ${CLI} calibrate-sigma ens.safetensors --val val --max-sigma 0)
expect_match("on 25 pairs: scale")
expect_match("wrote inertialnet.sigma_calibration into ens.safetensors")
run(0 ${CLI} predict low -w ens.safetensors --head both --fuse --smooth off --max-sigma 0 -o ens.csv)
file(WRITE "${WORK}/edit_ensemble.py" [=[
import json, struct, sys
path, out, value = sys.argv[1], sys.argv[2], sys.argv[3]
data = open(path, "rb").read()
n = struct.unpack("<Q", data[:8])[0]
header = json.loads(data[8:8 + n])
header["__metadata__"]["inertialnet.ensemble"] = value
text = json.dumps(header).encode()
text += b" " * (-len(text) % 8)
open(out, "wb").write(struct.pack("<Q", len(text)) + text + data[8 + n:])
]=])
run(0 ${PYTHON} edit_ensemble.py ens.safetensors ens_bad.safetensors "{\"members\":1,\"version\":1}")
run(2 ${CLI} predict low -w ens_bad.safetensors -o bad.csv)
expect_match("ens_bad.safetensors: metadata inertialnet.ensemble '\\{\"members\":1,\"version\":1\\}' is not a head ensemble description: \"members\" is 1: must be a whole number from 2 to 64")
if(EXISTS "${WORK}/bad.csv")
  message(FATAL_ERROR "a refused ensemble left bad.csv")
endif()
