# SPDX-License-Identifier: Apache-2.0
# `inertialnet predict --format csv|gcsv|euroc-imu|tum` (docs/cli.md, "Output formats"): each
# format read back by an independent reader (read_predicted.py: pandas and numpy for the CSV, the
# sidecar's row count and hash, read_exports.py's gcsv/EuRoC/TUM parsers, the TUM trajectory
# against the ground truth); the conversion is export's; pairs without an answer left out or held;
# outputs replaced whole or not at all; the sidecar's checks.
#   cmake -DCLI=<inertialnet> -DWORK=<scratch dir> -DPYTHON=<python with numpy and pandas> -P predict_formats.cmake
cmake_policy(VERSION 3.25)
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")
include(${CMAKE_CURRENT_LIST_DIR}/run_helpers.cmake)

function(expect_no_file name)
  if(EXISTS "${WORK}/${name}")
    message(FATAL_ERROR "${name} was written")
  endif()
endfunction()
function(expect_same a b)
  file(READ "${WORK}/${a}" ta)
  file(READ "${WORK}/${b}" tb)
  if(NOT ta STREQUAL tb)
    message(FATAL_ERROR "${a} and ${b} differ:\n${ta}\n---\n${tb}")
  endif()
endfunction()

# 12 frames, frame 9 a uniform grey: pairs 9 and 10 (rows 8 and 9) without an answer.
run(0 ${CLI} synth gap --frames 12 --size 376x240 --seed 2)
run(0 ${PYTHON} ${CMAKE_CURRENT_LIST_DIR}/deface_frame.py gap 9 uniform)

# 1. Every format; the pairs without an answer left out (gcsv, euroc-imu) or held (tum).
run(0 ${CLI} predict gap -o rates.csv)
run(0 ${CLI} predict gap --format gcsv -o out/clip.gcsv)
expect_match("pairs without an answer, left out: 2 \\(no_texture 2\\)")
expect_match("wrote 9 rows \\(gcsv\\) to out/clip.gcsv")
run(0 ${CLI} predict gap --format euroc-imu -o virtual/mav0/imu0/data.csv)
expect_match("wrote 9 rows \\(euroc-imu\\) to virtual/mav0/imu0/data.csv")
run(0 ${CLI} predict gap --format tum -o traj.txt)
expect_match("intervals without a rate, orientation held: 2")
expect_match("the integral drifts")
run(0 ${PYTHON} ${CMAKE_CURRENT_LIST_DIR}/read_predicted.py rates.csv out/clip.gcsv virtual/mav0/imu0/data.csv traj.txt gap)
expect_match("read back: csv 11 rows \\(pandas, numpy, sidecar\\), gcsv 9 rows, euroc-imu 9 rows, tum 11 poses")

# 2. One code path with `export`: the same files from the CSV (the gcsv's note names its source).
run(0 ${CLI} export rates.csv --format euroc-imu -o exported_imu.csv)
expect_same(exported_imu.csv virtual/mav0/imu0/data.csv)
run(0 ${CLI} export rates.csv --format tum -o exported.txt)
expect_same(exported.txt traj.txt)
# Without -o the file goes to standard output, the notes to the standard error.
run_json(streamed ${CLI} -q predict gap --format tum)
file(WRITE "${WORK}/streamed.txt" "${streamed}")
expect_same(streamed.txt traj.txt)

# 3. The CSV on standard output: the header first, the metadata as a note on the standard error.
run_json(stdout_csv ${CLI} predict gap)
if(NOT stdout_csv MATCHES "^timestamp_ns,wx,wy,wz,status,sigma_wx,sigma_wy,sigma_wz\n")
  message(FATAL_ERROR "predict's standard output does not start with the header:\n${stdout_csv}")
endif()
run(0 ${CLI} predict gap)
expect_match("note: the rates' metadata \\(a stream has no sidecar\\): schema: inertialnet.rates/4, frame: body, estimator: inter_frame")

# 4. A run that fails leaves every earlier output as it was: all pairs without an answer.
run(0 ${CLI} synth flat --frames 3 --size 376x240 --seed 2)
foreach(frame 0 1 2)
  run(0 ${PYTHON} ${CMAKE_CURRENT_LIST_DIR}/deface_frame.py flat ${frame} uniform)
endforeach()
file(SHA256 "${WORK}/traj.txt" before)
run(2 ${CLI} predict flat --format tum -o traj.txt)
expect_match("none of the 2 pairs")
file(SHA256 "${WORK}/traj.txt" after)
if(NOT after STREQUAL before)
  message(FATAL_ERROR "a failed predict --format tum changed traj.txt")
endif()
file(SHA256 "${WORK}/rates.csv.json" sidecar_before)
run(2 ${CLI} predict flat -o rates.csv)
file(SHA256 "${WORK}/rates.csv.json" sidecar_after)
if(NOT sidecar_after STREQUAL sidecar_before)
  message(FATAL_ERROR "a failed predict changed rates.csv.json")
endif()
run(0 ${CLI} eval rates.csv gap)  # the earlier pair still belongs together

# 5. Bad output choices, refused before any pair (exit 2).
run(2 ${CLI} predict gap --format mp4 -o x.txt)
expect_match("--format: unknown format 'mp4'; expected one of csv, gcsv, gyroflow, euroc-imu, tum")
# An image folder has no IMU: its rates are in the camera frame, which EuRoC's columns are not.
run(2 ${CLI} predict gap/mav0/cam0/data --rate 20 --fx 300 --format euroc-imu -o cam.csv)
expect_match("inertialnet: error: --format euroc-imu: the rates of .* are in the camera frame")
expect_no_file(cam.csv)
execute_process(COMMAND mkfifo "${WORK}/pipe.txt" RESULT_VARIABLE code)
if(code EQUAL 0)
  run(2 ${CLI} predict gap --format tum -o pipe.txt)
  expect_match("pipe.txt: it exists and is not a regular file; --format tum is written whole")
endif()

# 6. The sidecar: one that describes another CSV is refused naming both; a newer schema is refused;
#    a CSV alone reads without metadata and says so.
file(COPY_FILE "${WORK}/rates.csv" "${WORK}/edited.csv")
file(APPEND "${WORK}/edited.csv" "1403715279912142976,0.1,0.2,0.3,ok,,,\n")
file(COPY_FILE "${WORK}/rates.csv.json" "${WORK}/edited.csv.json")
run(2 ${CLI} eval edited.csv gap)
expect_match("edited.csv.json \\(the sidecar of edited.csv\\): it describes another CSV \\(11 rows")
file(COPY_FILE "${WORK}/rates.csv" "${WORK}/alone.csv")
run(0 ${CLI} eval alone.csv gap)
expect_match("alone.csv states no metadata \\(no sidecar alone.csv.json")
file(COPY_FILE "${WORK}/rates.csv" "${WORK}/future.csv")
file(WRITE "${WORK}/future.csv.json" "{\"schema\": \"inertialnet.rates/5\", \"metadata\": {}}")
foreach(command "eval;future.csv;gap" "export;future.csv;--format;tum;-o;f.txt" "calibrate-time;gap;future.csv")
  run(2 ${CLI} ${command})
  expect_match("future.csv.json is a rates file of schema inertialnet.rates/5, newer than this version reads")
endforeach()
