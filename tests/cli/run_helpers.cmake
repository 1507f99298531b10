# SPDX-License-Identifier: Apache-2.0
# What the CLI scripts share (end_to_end, outputs, bad_inputs, bench_json, tune, the input tests): run a
# command in ${WORK}, check its exit code, match its output, compare eval's RMSE.

# run(<expected exit code> <command>...): runs in ${WORK}; sets `output` to stdout + stderr.
function(run expect_code)
  execute_process(COMMAND ${ARGN} WORKING_DIRECTORY "${WORK}" RESULT_VARIABLE code OUTPUT_VARIABLE out
                  ERROR_VARIABLE err TIMEOUT 600)
  message("$ ${ARGN}\n${out}${err}(exit ${code})")
  if(NOT "${code}" STREQUAL "${expect_code}")
    message(FATAL_ERROR "expected exit code ${expect_code}, got ${code}")
  endif()
  set(output "${out}${err}" PARENT_SCOPE)
endfunction()

# run_json(<variable> <command>...): runs it (exit 0) and stores its standard output alone.
function(run_json variable)
  execute_process(COMMAND ${ARGN} WORKING_DIRECTORY "${WORK}" RESULT_VARIABLE code OUTPUT_VARIABLE out
                  ERROR_VARIABLE err TIMEOUT 600)
  message("$ ${ARGN}\n${out}${err}(exit ${code})")
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "expected exit code 0, got ${code}")
  endif()
  set(${variable} "${out}" PARENT_SCOPE)
endfunction()

function(expect_match regex)
  if(NOT output MATCHES "${regex}")
    message(FATAL_ERROR "output does not match '${regex}'")
  endif()
endfunction()

# expect_json(<json> <path>...): sets `value` to the member at <path>; FATAL_ERROR when it is absent.
function(expect_json document)
  string(JSON value ERROR_VARIABLE problem GET "${document}" ${ARGN})
  if(problem)
    message(FATAL_ERROR "field ${ARGN}: ${problem}")
  endif()
  set(value "${value}" PARENT_SCOPE)
endfunction()

function(expect_no_match regex)
  if(output MATCHES "${regex}")
    message(FATAL_ERROR "output matches '${regex}', which it should not")
  endif()
endfunction()

# intrinsics_flags(<var> <sensor.yaml under ${WORK}>): "--fx;F;--fy;F;--cx;C;--cy;C" from a EuRoC
# sensor.yaml's intrinsics line (the camera of a synthetic sequence, given as flags).
function(intrinsics_flags var sensor_yaml)
  file(READ "${WORK}/${sensor_yaml}" yaml)
  if(NOT yaml MATCHES "intrinsics: \\[([^,]+), ([^,]+), ([^,]+), ([^]]+)\\]")
    message(FATAL_ERROR "no intrinsics in ${sensor_yaml}")
  endif()
  set(${var} --fx ${CMAKE_MATCH_1} --fy ${CMAKE_MATCH_2} --cx ${CMAKE_MATCH_3} --cy ${CMAKE_MATCH_4} PARENT_SCOPE)
endfunction()

# rates_lines_of(<var> <csv under ${WORK}>): the CSV's lines but # comments (header and rows); at
# least five, else FATAL_ERROR.
function(rates_lines_of var csv)
  file(STRINGS "${WORK}/${csv}" lines REGEX "^[^#]")
  list(LENGTH lines n)
  if(n LESS 5)
    message(FATAL_ERROR "${csv} holds ${n} lines of rates")
  endif()
  set(${var} "${lines}" PARENT_SCOPE)
endfunction()

# rmse_of(<var> <eval --json document>): "x;y;z" of the raw RMSE of the document's first estimator.
function(rmse_of var document)
  set(values "")
  foreach(axis x y z)
    expect_json("${document}" estimators 0 raw rmse_deg_s ${axis})
    list(APPEND values "${value}")
  endforeach()
  set(${var} "${values}" PARENT_SCOPE)
endfunction()

# expect_same_rmse(<expected> <actual> <what>): two rmse_of lists agree within 1e-5 deg/s (CMake
# has no floating-point arithmetic: both are read as whole micro-deg/s and subtracted; comparing
# five decimals as text failed on 1.8732799986 against 1.8732800006).
function(micro_of var text)
  if(NOT text MATCHES "^([0-9]+)\\.([0-9]*)")
    message(FATAL_ERROR "not a non-negative decimal: ${text}")
  endif()
  set(whole ${CMAKE_MATCH_1})
  string(SUBSTRING "${CMAKE_MATCH_2}000000" 0 6 fraction)
  math(EXPR micro "${whole} * 1000000 + 1${fraction} - 1000000")  # the leading 1 keeps zeros decimal
  set(${var} ${micro} PARENT_SCOPE)
endfunction()
function(expect_same_rmse expected actual what)
  foreach(k 0 1 2)
    list(GET expected ${k} e)
    list(GET actual ${k} a)
    micro_of(e6 "${e}")
    micro_of(a6 "${a}")
    math(EXPR difference "${a6} - ${e6}")
    if(difference GREATER 10 OR difference LESS -10)
      message(FATAL_ERROR "${what}: RMSE ${actual} deg/s, the EuRoC path gives ${expected}")
    endif()
  endforeach()
endfunction()

# running_as_root(<var>): TRUE when the tests run as root (device nodes and other users'
# folders can then be made in the scratch folder; without root those cases are skipped).
function(running_as_root var)
  execute_process(COMMAND id -u OUTPUT_VARIABLE uid OUTPUT_STRIP_TRAILING_WHITESPACE)
  if(uid STREQUAL "0")
    set(${var} TRUE PARENT_SCOPE)
  else()
    set(${var} FALSE PARENT_SCOPE)
  endif()
endfunction()
