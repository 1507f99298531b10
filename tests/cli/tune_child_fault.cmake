# SPDX-License-Identifier: Apache-2.0
# `inertialnet tune`'s CLBlast search runs each step in a child process: a child that crashes or
# hangs becomes a warning naming the shape and a "failed" step in the document, and tune still
# stores the packed search's result and exits 0. The child is made to fail at once through the
# test-only INERTIALNET_TEST_TUNE_CHILD_FAULT (segv | hang), so no CLBlast tuning runs. Also: where
# the plan runs the packed kernels the CLBlast search is skipped with a note unless --clblast.
#   cmake -DCLI=<inertialnet> -DWORK=<scratch dir> -P tune_child_fault.cmake
cmake_minimum_required(VERSION 3.19)  # string(JSON)
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")
set(ENV{INERTIALNET_CACHE_DIR} "${WORK}/cache")
unset(ENV{INERTIALNET_NO_CACHE})
unset(ENV{INERTIALNET_PLAN})
include(${CMAKE_CURRENT_LIST_DIR}/run_helpers.cmake)
set(small --model FlowNet2-C --size 64x48)

# tune_json(<expected exit code> <arguments>...): `tune --json`; sets `doc` (stdout) and `output`
# (stderr) in the caller.
function(tune_json expect_code)
  execute_process(COMMAND ${CLI} tune --json ${small} ${ARGN} WORKING_DIRECTORY "${WORK}" RESULT_VARIABLE code
                  OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 600)
  message("$ inertialnet tune --json ${small} ${ARGN}\n${out}${err}(exit ${code})")
  if(NOT "${code}" STREQUAL "${expect_code}")
    message(FATAL_ERROR "expected exit code ${expect_code}, got ${code}")
  endif()
  set(doc "${out}" PARENT_SCOPE)
  set(output "${err}" PARENT_SCOPE)
endfunction()

function(expect_value expected)
  expect_json("${doc}" ${ARGN})
  if(NOT value STREQUAL "${expected}")
    message(FATAL_ERROR "${ARGN}: '${value}', expected '${expected}'")
  endif()
endfunction()

# 1. Every step's child dies of SIGSEGV: warnings, failed steps, the packed result stored, exit 0.
set(ENV{INERTIALNET_TEST_TUNE_CHILD_FAULT} segv)
tune_json(0 --quick --clblast)
expect_match("warning: CLBlast's tuner crashed \\(SIGSEGV\\) on 128x256x1600; that shape keeps its current parameters")
expect_match("warning: CLBlast's tuner crashed \\(SIGSEGV\\) on 256x64x3200; that shape keeps its current parameters")
expect_value("failed: SIGSEGV" clblast steps 0 status)
expect_value("128x256x1600" clblast steps 0 shape)
expect_value("failed: 128x256x1600: SIGSEGV; 256x64x3200: SIGSEGV" clblast status)
expect_value("0" clblast candidates)
expect_json("${doc}" packed parameters MR)
file(GLOB stored "${WORK}/cache/tuning/*.json")
list(LENGTH stored count)
if(NOT count EQUAL 1)
  message(FATAL_ERROR "expected one stored tuning file, found: ${stored}")
endif()

# 2. A child that never answers is killed at --clblast-timeout.
set(ENV{INERTIALNET_TEST_TUNE_CHILD_FAULT} hang)
tune_json(0 --quick --clblast --clblast-timeout 1)
expect_match("warning: CLBlast's tuner gave up \\(no result within 1 s \\(killed\\)\\) on 128x256x1600")
expect_value("failed: no result within 1 s (killed)" clblast steps 1 status)

# 3. The plan decides whether CLBlast is searched at all: not where it runs the packed kernels
#    (a note says why), but under timed plans, where CLBlast is a candidate.
set(ENV{INERTIALNET_TEST_TUNE_CHILD_FAULT} segv)
tune_json(0 --plan packed)
expect_match("note: CLBlast's search skipped: the GEMM plan on this device runs the packed kernels")
expect_value("skipped: the GEMM plan on this device runs the packed kernels, not CLBlast" clblast status)
tune_json(0 --plan auto --quick --clblast)
expect_value("failed: SIGSEGV" clblast steps 0 status)
tune_json(0 --quick)
expect_value("skipped: --quick" clblast status)
