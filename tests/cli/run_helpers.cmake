# SPDX-License-Identifier: Apache-2.0
# What the CLI scripts share (end_to_end, outputs, bad_inputs, bench_json, tune): run a command in ${WORK}, check
# its exit code, and match its output.

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
