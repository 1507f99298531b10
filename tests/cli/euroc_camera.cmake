# SPDX-License-Identifier: Apache-2.0
# `--camera cam0|cam1` (predict, eval, calibrate-time) on a EuRoC sequence with two cameras: a
# synthetic sequence whose mav0/cam1 lists every other image of cam0, stamped 1 ms later, so that
# rates from cam1 are told from cam0's by their count and their times.
#   cmake -DCLI=<inertialnet> -DWORK=<scratch dir> -P euroc_camera.cmake
include(${CMAKE_CURRENT_LIST_DIR}/run_helpers.cmake)
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")

run(0 ${CLI} synth seq --frames 20 --size 188x120 --seed 3)
run(0 ${CLI} synth mono --frames 8 --size 188x120 --seed 4)
file(COPY "${WORK}/seq/mav0/cam0/" DESTINATION "${WORK}/seq/mav0/cam1")
file(STRINGS "${WORK}/seq/mav0/cam0/data.csv" rows REGEX "^[0-9]")
set(cam1 "#timestamp [ns],filename\n")
set(index 0)
foreach(row IN LISTS rows)
  math(EXPR keep "${index} % 2")
  if(keep EQUAL 0 AND row MATCHES "^([0-9]+),(.*)$")
    math(EXPR later "${CMAKE_MATCH_1} + 1000000")
    string(APPEND cam1 "${later},${CMAKE_MATCH_2}\n")
  endif()
  math(EXPR index "${index} + 1")
endforeach()
file(WRITE "${WORK}/seq/mav0/cam1/data.csv" "${cam1}")

# count_rows(<var> <csv>): the rates rows (lines that start with a timestamp).
function(count_rows var csv)
  file(STRINGS "${WORK}/${csv}" lines REGEX "^[0-9]")
  list(LENGTH lines n)
  set(${var} ${n} PARENT_SCOPE)
endfunction()

run(0 ${CLI} predict seq -o cam0.csv)
run(0 ${CLI} predict seq --camera cam0 -o cam0_named.csv)
run(0 ${CLI} predict seq --camera cam1 -o cam1.csv)
count_rows(n0 cam0.csv)
count_rows(n0_named cam0_named.csv)
count_rows(n1 cam1.csv)
if(NOT n0 EQUAL 19 OR NOT n0_named EQUAL 19 OR NOT n1 EQUAL 9)
  message(FATAL_ERROR "rows: ${n0} (default), ${n0_named} (cam0), ${n1} (cam1); expected 19, 19, 9")
endif()
file(STRINGS "${WORK}/cam1.csv" first REGEX "^[0-9]" LIMIT_COUNT 1)
list(GET rows 2 third)
string(REGEX MATCH "^[0-9]+" t2 "${third}")
math(EXPR expected "${t2} + 1000000")
if(NOT first MATCHES "^${expected},")
  message(FATAL_ERROR "cam1's first rates row should be stamped ${expected} (cam1's second frame): ${first}")
endif()

# eval against cam1's frames: every row is a frame; against cam0's, none is.
run(0 ${CLI} eval cam1.csv seq --camera cam1 --json)
expect_json("${output}" estimators 0 rows_not_frames)
if(NOT value EQUAL 0)
  message(FATAL_ERROR "rows_not_frames ${value} against cam1, expected 0")
endif()
run(2 ${CLI} eval cam1.csv seq)
expect_match("None of the 9 rows of the rates file matches a camera frame of seq")
# calibrate-time predicts cam1 itself, and finds the 1 ms by which its stamps are late.
run(0 ${CLI} calibrate-time seq --camera cam1 --range 0.02)
expect_match("no rates file given: predicting 9 pairs")
expect_match("time_offset_s -0\\.00(09|10)")
expect_match("apply it with: inertialnet eval RATES.csv seq --camera cam1 --time-offset")

# Refused: a camera the sequence lacks (its cameras named), one that is not cam0/cam1, and
# --camera cam1 for an image folder.
run(2 ${CLI} predict mono --camera cam1)
expect_match("mono has no camera cam1 \\(no [^\n]*mono/mav0/cam1/data.csv\\); its cameras: cam0")
run(2 ${CLI} eval cam1.csv mono --camera cam1)
expect_match("has no camera cam1")
run(2 ${CLI} predict seq --camera cam2)
expect_match("--camera: unknown camera 'cam2'; expected one of cam0, cam1")
run(2 ${CLI} predict seq/mav0/cam0/data --camera cam1 --fx 100)
expect_match("--camera cam1 picks a camera of a EuRoC sequence \\(mav0/cam1\\); seq/mav0/cam0/data is an image folder")
