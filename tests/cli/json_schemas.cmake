# SPDX-License-Identifier: Apache-2.0
# The machine-readable outputs parse, carry their schema name, and keep one shape: `eval --json`
# is one object with a list of estimators (one or two), three-vectors are {"x","y","z"};
# `devices --json` names each device once ("index", "address"); `--series` without `--json` is
# refused, not ignored. Parsed with CMake's own JSON reader (string(JSON)).
#   cmake -DCLI=<inertialnet> -DWORK=<scratch dir> -P json_schemas.cmake
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")

include(${CMAKE_CURRENT_LIST_DIR}/run_helpers.cmake)

function(expect_json json expected)
  string(JSON value ERROR_VARIABLE error GET "${json}" ${ARGN})
  if(error)
    message(FATAL_ERROR "JSON ${ARGN}: ${error}")
  endif()
  if(NOT "${value}" STREQUAL "${expected}")
    message(FATAL_ERROR "JSON ${ARGN} is '${value}', expected '${expected}'")
  endif()
endfunction()

function(expect_number json)
  string(JSON type ERROR_VARIABLE error TYPE "${json}" ${ARGN})
  if(error OR NOT type STREQUAL "NUMBER")
    message(FATAL_ERROR "JSON ${ARGN} is no number (${type}${error})")
  endif()
endfunction()

run(0 ${CLI} synth seq --frames 5 --size 96x64 --seed 6)
run(0 ${CLI} weights --synthetic FlowNet2-C -o c.safetensors)
run(0 ${CLI} weights --synthetic InertialNetHead --size 96x64 -o head.safetensors)
run(0 ${CLI} predict seq -o one.csv)
# --max-sigma 0: the synthetic weights' flow is noise, and so the geometric rates' σ is above the
# default limit; this case is about the JSON's shape.
run(0 ${CLI} predict seq -w c.safetensors -w head.safetensors --head both -o both.csv --max-sigma 0)

# eval, one estimator: still an object with a list.
run_json(one ${CLI} eval one.csv seq --json --series)
expect_json("${one}" "inertialnet.eval/1" schema)
string(JSON estimators LENGTH "${one}" estimators)
if(NOT estimators EQUAL 1)
  message(FATAL_ERROR "eval --json of one estimator lists ${estimators}")
endif()
expect_json("${one}" "wx" estimators 0 columns x)
expect_json("${one}" "4" estimators 0 frames_evaluated)
expect_number("${one}" estimators 0 raw rmse_deg_s x)
expect_number("${one}" estimators 0 raw rmse_deg_s z)
expect_number("${one}" estimators 0 series 0 predicted_rad_s y)
string(JSON counts LENGTH "${one}" estimators 0 error_histogram x counts)

# eval, two estimators: the same shape, two entries, named.
run_json(two ${CLI} eval both.csv seq --json)
expect_json("${two}" "inertialnet.eval/1" schema)
string(JSON estimators LENGTH "${two}" estimators)
if(NOT estimators EQUAL 2)
  message(FATAL_ERROR "eval --json of two estimators lists ${estimators}")
endif()
expect_json("${two}" "" estimators 0 estimator)
expect_json("${two}" "geometric" estimators 1 estimator)
expect_json("${two}" "wz_geometric" estimators 1 columns z)
string(JSON has_series ERROR_VARIABLE no_series GET "${two}" estimators 0 series)
if(NOT no_series)
  message(FATAL_ERROR "series without --series")
endif()

# --series alone: refused with a reason, exit 2.
run(2 ${CLI} eval one.csv seq --series)
expect_match("--series requires --json")

# devices: an object with the schema, each device once, no duplicate index keys.
run_json(devices ${CLI} devices --json)
expect_json("${devices}" "inertialnet.devices/1" schema)
expect_json("${devices}" "0" devices 0 index)
expect_json("${devices}" "0:0" devices 0 address)
if(devices MATCHES "device_index" OR devices MATCHES "platform_index")
  message(FATAL_ERROR "devices --json still has device_index/platform_index")
endif()
string(JSON count LENGTH "${devices}" devices)
string(REGEX MATCHALL "\"index\"" index_keys "${devices}")
list(LENGTH index_keys index_count)
if(NOT index_count EQUAL count)
  message(FATAL_ERROR "${index_count} \"index\" keys for ${count} devices")
endif()
