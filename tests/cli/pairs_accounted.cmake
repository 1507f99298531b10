# SPDX-License-Identifier: Apache-2.0
# Every frame pair accounted for (docs/cli.md, "Rates CSV"): one bad frame costs its pairs, never
# the run or a confident wrong number; a run that fails or is killed never replaces good output.
#   cmake -DCLI=<inertialnet> -DPYTHON=<python3> -DWORK=<scratch dir> -P pairs_accounted.cmake
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")
include(${CMAKE_CURRENT_LIST_DIR}/run_helpers.cmake)
set(DEFACE ${CMAKE_CURRENT_LIST_DIR}/deface_frame.py)

# rows(<csv> <var>): the data rows of a rates CSV (no '#' lines, no header).
function(rows csv var)
  file(STRINGS "${WORK}/${csv}" lines REGEX "^[0-9]")
  set(${var} "${lines}" PARENT_SCOPE)
endfunction()
# not_ok(<csv> <var>): its rows whose status is not ok.
function(not_ok csv var)
  rows(${csv} all)
  list(FILTER all EXCLUDE REGEX ",ok,[^,]*,[^,]*,[^,]*$")
  set(${var} "${all}" PARENT_SCOPE)
endfunction()

# 1. 300 frames with a frame of noise, a uniform grey and a black frame in the middle: exit 0, 299
#    rows, exactly the six pairs that touch those frames without an answer, each warned by name,
#    and eval's RMSE over the rest within 10 % of the clean sequence's.
run(0 ${CLI} synth clean --frames 300 --size 376x240 --seed 5)
file(COPY "${WORK}/clean/" DESTINATION "${WORK}/faulty")
run(0 ${PYTHON} ${DEFACE} faulty 100 noise)
run(0 ${PYTHON} ${DEFACE} faulty 150 uniform)
run(0 ${PYTHON} ${DEFACE} faulty 200 black)
run(0 ${CLI} predict clean -o clean.csv)
run(0 ${CLI} predict faulty -o faulty.csv)
foreach(pair 100 101 150 151 200 201)
  math(EXPR before "${pair} - 1")
  expect_match("warning: pair ${pair} \\(frames ${before} → ${pair}, t = [0-9]+ → [0-9]+ ns\\): geometric: [a-z_]+: ")
endforeach()
expect_match("pair 150 [^\n]*no_texture: frame 150 [^\n]*shows almost no texture")
expect_match("pair 201 [^\n]*no_texture: frame 200 ")
expect_match("6 of 299 pairs without an answer")
rows(faulty.csv faulty_rows)
list(LENGTH faulty_rows count)
if(NOT count EQUAL 299)
  message(FATAL_ERROR "faulty.csv has ${count} rows, expected 299")
endif()
not_ok(faulty.csv bad)
rows(clean.csv clean_rows)
set(expected "")
foreach(row 99 100 149 150 199 200)  # row k-1 is pair k
  list(GET clean_rows ${row} line)
  string(REGEX REPLACE ",.*" "" t "${line}")
  list(APPEND expected "${t}")
endforeach()
set(got "")
foreach(line IN LISTS bad)
  string(REGEX REPLACE ",.*" "" t "${line}")
  list(APPEND got "${t}")
  if(NOT line MATCHES "^[0-9]+,,,,(no_texture|too_few_vectors|unreliable),,,$")
    message(FATAL_ERROR "a pair without an answer reads '${line}'")
  endif()
endforeach()
if(NOT got STREQUAL expected)
  message(FATAL_ERROR "pairs without an answer at ${got}, expected ${expected}")
endif()
run(0 ${CLI} eval faulty.csv faulty)
expect_match("pairs without an answer, left out: 6")
run_json(clean_json ${CLI} eval clean.csv clean --json)
run_json(faulty_json ${CLI} eval faulty.csv faulty --json)
expect_json("${faulty_json}" estimators 0 rows_not_ok)
if(NOT value EQUAL 6)
  message(FATAL_ERROR "eval --json rows_not_ok is ${value}")
endif()
foreach(axis x y z)
  expect_json("${clean_json}" estimators 0 bias_corrected rmse_deg_s ${axis})
  set(clean_rmse ${value})
  expect_json("${faulty_json}" estimators 0 bias_corrected rmse_deg_s ${axis})
  run(0 ${PYTHON} -c "import sys; c, f = ${clean_rmse}, ${value}; print(c, f); sys.exit(abs(f - c) > 0.1 * c)")
endforeach()

# 2. The same faults on standard output and in calibrate-time: every pair, the run goes on.
run(0 ${CLI} predict faulty --max-pairs 155)
expect_match("\n[0-9]+,,,,no_texture,,,\n")
expect_match("4 of 155 pairs without an answer")
run(0 ${CLI} calibrate-time faulty)
expect_match("pair 150 ")
expect_match("time_offset_s ")

# 3. With both heads (on DIS flow) the network answers the pair whose frame is noise while the
#    geometric head (its forward-backward check finds no consistent vector) does not; a frame
#    without texture leaves neither an answer.
run(0 ${CLI} synth small --frames 8 --size 96x64 --seed 3)
run(0 ${PYTHON} ${DEFACE} small 3 noise)
run(0 ${PYTHON} ${DEFACE} small 6 uniform)
run(0 ${CLI} weights --synthetic FlowNet2-C --seed 1 -o c.safetensors)
run(0 ${CLI} weights --synthetic InertialNetHead --size 96x64 -o head.safetensors)
run(0 ${CLI} predict small -w head.safetensors --flow dis --head both -o both.csv)
file(STRINGS "${WORK}/both.csv" header REGEX "^timestamp_ns")
if(NOT header STREQUAL "timestamp_ns,wx,wy,wz,status,sigma_wx,sigma_wy,sigma_wz,wx_geometric,wy_geometric,wz_geometric,status_geometric,sigma_wx_geometric,sigma_wy_geometric,sigma_wz_geometric")
  message(FATAL_ERROR "both.csv header is '${header}'")
endif()
rows(both.csv both_rows)
list(GET both_rows 2 noise_pair)  # pair 3
if(NOT noise_pair MATCHES "^[0-9]+,[-0-9.e]+,[-0-9.e]+,[-0-9.e]+,ok,,,,,,,(too_few_vectors|unreliable),,,$")
  message(FATAL_ERROR "the pair with a frame of noise reads '${noise_pair}'")
endif()
list(GET both_rows 5 flat_pair)  # pair 6
if(NOT flat_pair MATCHES "^[0-9]+,,,,no_texture,,,,,,,no_texture,,,$")
  message(FATAL_ERROR "the pair with a uniform frame reads '${flat_pair}'")
endif()

# 4. A rerun that fails late (weights that do not fit FlowNet2 fail when the lanes build the
#    network) leaves the complete rates.csv of the earlier run as it was and nothing beside it.
run(0 ${CLI} predict small -o rates.csv)
file(READ "${WORK}/rates.csv" good)
run(2 ${CLI} predict small -w head.safetensors -o rates.csv)
expect_match("do not fit FlowNet2")
file(READ "${WORK}/rates.csv" after)
if(NOT after STREQUAL good)
  message(FATAL_ERROR "a failed rerun changed rates.csv")
endif()
if(EXISTS "${WORK}/rates.csv.partial")
  message(FATAL_ERROR "a run that failed before its first row left rates.csv.partial")
endif()
# A run in which no pair can be answered is a failure too: exit 2, rates.csv kept, the rows with
# their reasons in rates.csv.partial.
run(0 ${CLI} synth flat --frames 8 --size 96x64 --seed 3)
foreach(frame RANGE 0 7)
  run(0 ${PYTHON} ${DEFACE} flat ${frame} black)
endforeach()
run(2 ${CLI} predict flat -o rates.csv)
expect_match("none of the 7 pairs of EuRoC sequence flat \\(8 frames\\) could be answered \\(7 of 7 pairs without an answer \\(no_texture 7\\)\\); their rows, with the reasons, are in rates.csv.partial")
file(READ "${WORK}/rates.csv" after)
if(NOT after STREQUAL good)
  message(FATAL_ERROR "a run without any answer replaced rates.csv")
endif()
not_ok(rates.csv.partial flat_rows)
list(LENGTH flat_rows count)
if(NOT count EQUAL 7)
  message(FATAL_ERROR "rates.csv.partial holds ${count} rows without an answer, expected 7")
endif()

# A damaged first frame costs pair 1 only: the camera's size comes from the first frames that
# decode, with --fx and with a sensor.yaml alike, and the run goes on.
run(0 ${CLI} synth first_bad --frames 5 --size 96x64 --seed 3)
file(GLOB first_bad_frames "${WORK}/first_bad/mav0/cam0/data/*.png")
list(SORT first_bad_frames)
list(GET first_bad_frames 0 frame0)
file(WRITE "${frame0}" "not an image")
# --max-sigma 0: at 96x64 a pair's σ (5-7 deg/s) exceeds the default limit; this case is about decoding.
run(0 ${CLI} predict first_bad -o first_bad.csv --stats --max-sigma 0)
expect_match("pair 1 \\(frames 0 → 1, [^\n]*decode_error: ")
not_ok(first_bad.csv first_bad_rows)
list(LENGTH first_bad_rows count)
if(NOT count EQUAL 1)
  message(FATAL_ERROR "first_bad.csv holds ${count} rows without an answer, expected 1 (pair 1)")
endif()
run(0 ${CLI} predict first_bad --fx 80 --max-sigma 0)
expect_match("1 of 4 pairs without an answer \\(decode_error 1\\)")

# 5. -o never names an input: the sequence's own files, the weights.
run(2 ${CLI} predict small -o small/mav0/cam0/data.csv)
expect_match("-o small/mav0/cam0/data.csv is inside the sequence small \\(its mav0 folder, the recording itself\\)")
run(2 ${CLI} predict small -w c.safetensors -w head.safetensors -o head.safetensors)
expect_match("-o \\(head.safetensors\\) would overwrite the input head.safetensors")

# 6. kill -9 in the middle of a run (kill_during_predict.py says what it checks).
run(0 ${PYTHON} ${CMAKE_CURRENT_LIST_DIR}/kill_during_predict.py ${CLI} "${WORK}" "${WORK}/clean")
expect_match("all checks passed")
