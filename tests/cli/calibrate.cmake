# SPDX-License-Identifier: Apache-2.0
# `calibrate` (issue 22's acceptance): a synthetic sequence whose camera stamps lag the IMU by 40 ms
# and whose cam0/sensor.yaml states a camera–IMU rotation 3° off (synth --extrinsic-error 1,2,2):
# calibrate recovers both (rotation within 0.5°, offset within 2 ms), each with an uncertainty and
# a rating, in text and --json; eval --calibration-from applies them as the explicit options do;
# the readout time is not detected on this global-shutter sequence and is detected on a
# rolling-shutter one.
#   cmake -DCLI=<inertialnet> -DWORK=<scratch dir> -P calibrate.cmake
cmake_policy(VERSION 3.25)
include(${CMAKE_CURRENT_LIST_DIR}/run_helpers.cmake)
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")

# 120 frames at 188x120 (60 leave the rotation's 1σ near 0.3°, too close to the 0.5° asked).
run(0 ${CLI} synth rig --frames 120 --size 188x120 --seed 5 --time-offset 0.04 --extrinsic-error 1,2,2)
expect_match("wrote ")
file(READ "${WORK}/rig/mav0/cam0/sensor.yaml" yaml)
if(NOT yaml MATCHES "Deliberately wrong \\(synth --extrinsic-error 1,2,2\\)")
  message(FATAL_ERROR "sensor.yaml does not say its T_BS is perturbed")
endif()
run(0 ${CLI} predict rig -o rates.csv)

# expect_between(<what> <value> <low> <high>)
function(expect_between what value low high)
  if(NOT value GREATER_EQUAL ${low} OR NOT value LESS_EQUAL ${high})
    message(FATAL_ERROR "${what} ${value}, expected within [${low}, ${high}]")
  endif()
endfunction()

# The offset 40 ms within 2 ms; the rotation θ = (1, 2, 2)°: each component within 0.28°, so the
# vector within 0.5° (for rotations this small the difference of the vectors is the angle between
# them, to 0.01°).
function(expect_recovered offset rx ry rz)
  expect_between("time offset" ${offset} 0.038 0.042)
  expect_between("rotation x" ${rx} 0.72 1.28)
  expect_between("rotation y" ${ry} 1.72 2.28)
  expect_between("rotation z" ${rz} 1.72 2.28)
endfunction()

run(0 ${CLI} calibrate rig rates.csv)
if(NOT output MATCHES "time_offset_s ([-0-9.]+)\nstd_error_s ([0-9.]+)\nconfidence ([a-z]+)\n")
  message(FATAL_ERROR "no time_offset_s / std_error_s / confidence lines")
endif()
set(offset ${CMAKE_MATCH_1})
expect_between("time offset 1 sigma" ${CMAKE_MATCH_2} 0.00001 0.002)
if(NOT output MATCHES "rotation_correction_deg ([-0-9.]+) ([-0-9.]+) ([-0-9.]+)\n")
  message(FATAL_ERROR "no rotation_correction_deg line")
endif()
expect_recovered(${offset} ${CMAKE_MATCH_1} ${CMAKE_MATCH_2} ${CMAKE_MATCH_3})
expect_match("rotation_angle_std_error_deg 0\\.[0-9]+\nrotation_confidence (high|medium)\n")
# A global shutter: no readout seen, with the bound below which one would not show.
expect_match("rolling-shutter readout time: none detected")
expect_match("readout_time_s 0\nreadout_upper_bound_s 0\\.00[0-9]+\nreadout_confidence none\n")
expect_match("apply it with: inertialnet eval RATES.csv rig --time-offset [-0-9.]+ --rotation-correction [-0-9.]+,[-0-9.]+,[-0-9.]+")

# --json: the same numbers with their errors and ratings, schema inertialnet.calibrate/1.
run_json(doc ${CLI} calibrate rig rates.csv --json)
expect_json("${doc}" schema)
if(NOT value STREQUAL "inertialnet.calibrate/1")
  message(FATAL_ERROR "schema ${value}")
endif()
expect_json("${doc}" time_offset offset_s)
set(offset ${value})
expect_json("${doc}" time_offset confidence)
if(NOT value STREQUAL "high")
  message(FATAL_ERROR "time offset confidence ${value}")
endif()
foreach(axis x y z)
  expect_json("${doc}" rotation_correction rotation_vector_deg ${axis})
  set(r_${axis} ${value})
  expect_json("${doc}" rotation_correction std_error_deg ${axis})
  expect_between("rotation std_error_deg.${axis}" ${value} 0.001 0.25)
endforeach()
expect_recovered(${offset} ${r_x} ${r_y} ${r_z})
expect_json("${doc}" rotation_correction confidence)
if(NOT value MATCHES "^(high|medium)$")
  message(FATAL_ERROR "rotation confidence ${value}")
endif()
expect_json("${doc}" rates_readout_time_s)
expect_between("rates_readout_time_s" ${value} 0 0)
expect_json("${doc}" readout_time detected)
if(NOT value STREQUAL "OFF" AND NOT value STREQUAL "false")
  message(FATAL_ERROR "readout detected on a global shutter: ${value}")
endif()
expect_json("${doc}" readout_time readout_s)
expect_between("global-shutter readout" ${value} -0.003 0.003)
expect_json("${doc}" readout_time confidence)
if(NOT value STREQUAL "none")
  message(FATAL_ERROR "global-shutter readout confidence ${value}")
endif()
file(WRITE "${WORK}/calib.json" "${doc}")

# eval --calibration-from applies the report's offset and rotation: the RMSE of the explicit options.
run_json(explicit ${CLI} eval rates.csv rig --json --time-offset ${offset} --rotation-correction ${r_x},${r_y},${r_z})
rmse_of(expected "${explicit}")
run_json(from_file ${CLI} eval rates.csv rig --json --calibration-from calib.json)
rmse_of(actual "${from_file}")
expect_same_rmse("${expected}" "${actual}" "eval --calibration-from calib.json")
expect_json("${from_file}" estimators 0 rotation_correction_deg x)
run(0 ${CLI} eval rates.csv rig --calibration-from calib.json)
expect_match("calibration from calib.json: time offset \\+[0-9.]+ ms and the camera-IMU rotation correction")
# The offset holds for rates with the report's readout (0 here): with --readout-time 0.02 eval adds
# a 10 ms mid-exposure shift, so the offset applied is 10 ms less (the sum stays).
run(0 ${CLI} eval rates.csv rig --calibration-from calib.json --readout-time 0.02)
expect_match("calibration from calib.json: time offset \\+(2[89]|3[01])\\.[0-9]+ ms")

# Bad reports: exit 2 naming the file and what is wrong.
run(2 ${CLI} eval rates.csv rig --calibration-from calib.json --time-offset 0.04)
expect_match("--calibration-from gives the time offset and rotation correction: leave out --time-offset")
file(WRITE "${WORK}/not.json" "time_offset_s 0.04\n")
run(2 ${CLI} eval rates.csv rig --calibration-from not.json)
expect_match("--calibration-from not.json: not JSON")
string(REPLACE "inertialnet.calibrate/1" "inertialnet.eval/1" other "${doc}")
file(WRITE "${WORK}/other.json" "${other}")
run(2 ${CLI} eval rates.csv rig --calibration-from other.json)
expect_match("--calibration-from other.json: key \"schema\" should be \"inertialnet.calibrate/1\" or \"inertialnet.calibrate-time/1\", found \"inertialnet.eval/1\"")
string(JSON low_doc SET "${doc}" time_offset confidence "\"low\"")
file(WRITE "${WORK}/low.json" "${low_doc}")
run(2 ${CLI} eval rates.csv rig --calibration-from low.json)
expect_match("--calibration-from low.json: the camera-IMU time offset in it is rated low; not applying it")
string(JSON no_offset REMOVE "${doc}" time_offset offset_s)
file(WRITE "${WORK}/no_offset.json" "${no_offset}")
run(2 ${CLI} eval rates.csv rig --calibration-from no_offset.json)
expect_match("key \"time_offset.offset_s\" should be a number")

# --no-readout: the report says the readout was not searched.
run_json(doc ${CLI} calibrate rig rates.csv --json --no-readout)
expect_json("${doc}" readout_time searched)
if(NOT value STREQUAL "OFF" AND NOT value STREQUAL "false")
  message(FATAL_ERROR "readout searched with --no-readout: ${value}")
endif()

# Without a usable device a rates file still gives the offset and rotation; the readout alone is
# skipped, with a warning saying why.
run(0 ${CLI} calibrate rig rates.csv --device 99)
expect_match("time_offset_s 0\\.0[34]")
expect_match("warning: the readout time is not fitted: the readout's leak model needs an OpenCL device: There is no device with index 99")
expect_no_match("readout_time_s")

# A rolling shutter of 30 ms: detected, and of the right size within the bound the model holds
# (readout_fit.hpp: 50–62 % of the truth recovered on such frames), rated no higher than low.
run(0 ${CLI} synth rs --frames 60 --size 188x120 --seed 5 --readout-time 0.03)
run(0 ${CLI} predict rs -o rs.csv)
run_json(doc ${CLI} calibrate rs rs.csv --json)
expect_json("${doc}" readout_time detected)
if(NOT value STREQUAL "ON" AND NOT value STREQUAL "true")
  message(FATAL_ERROR "no readout detected on a 30 ms rolling shutter")
endif()
expect_json("${doc}" readout_time readout_s)
expect_between("rolling-shutter readout" ${value} 0.010 0.045)
expect_json("${doc}" readout_time confidence)
if(NOT value STREQUAL "low")
  message(FATAL_ERROR "rolling-shutter readout confidence ${value}, expected low (the leak model's error)")
endif()
expect_json("${doc}" readout_time std_error_s)
expect_between("rolling-shutter readout 1 sigma" ${value} 0.002 0.02)

# A near-still clip (0.05 deg/s): nothing in calibrate's report may be rated high — the offset is
# noise fitted to noise (low, with the excitation as the reason), no readout can show — and eval
# refuses to apply the report's offset.
run(0 ${CLI} synth still --frames 40 --size 188x120 --seed 1 --max-rate 0.05)
run(0 ${CLI} predict still -o still.csv)
run_json(doc ${CLI} calibrate still still.csv --json)
expect_json("${doc}" time_offset confidence)
if(NOT value STREQUAL "low")
  message(FATAL_ERROR "near-still clip: time offset confidence ${value}, expected low")
endif()
expect_json("${doc}" readout_time confidence)
if(NOT value STREQUAL "none")
  message(FATAL_ERROR "near-still clip: readout confidence ${value}, expected none")
endif()
file(WRITE "${WORK}/still.json" "${doc}")
run(2 ${CLI} eval still.csv still --calibration-from still.json)
expect_match("--calibration-from still.json: the camera-IMU time offset in it is rated low; not applying it")
