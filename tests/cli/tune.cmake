# SPDX-License-Identifier: Apache-2.0
# `inertialnet tune`: the quick search writes an "inertialnet.tune/1" document (schema in
# include/inertialnet/runtime/device_tuning.hpp) beside the program cache, a second process picks
# it up (`tune --show`, `bench --json`'s gemm_tuning), --no-cache neither reads nor writes it,
# and a damaged file gives a warning and the defaults. The cache lives in ${WORK}, never in the
# user's cache, so the test tunes nothing for other runs.
#   cmake -DCLI=<inertialnet> -DWORK=<scratch dir> -P tune.cmake
cmake_minimum_required(VERSION 3.19)  # string(JSON)
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")
set(ENV{INERTIALNET_CACHE_DIR} "${WORK}/cache")
unset(ENV{INERTIALNET_NO_CACHE})
include(${CMAKE_CURRENT_LIST_DIR}/run_helpers.cmake)

# 1. The quick search and its document.
execute_process(COMMAND ${CLI} tune --quick --json RESULT_VARIABLE code OUTPUT_VARIABLE doc ERROR_VARIABLE err
                TIMEOUT 600)
message("$ inertialnet tune --quick --json\n${doc}${err}(exit ${code})")
if(NOT code EQUAL 0)
  message(FATAL_ERROR "expected exit code 0, got ${code}")
endif()
expect_json("${doc}" schema)
if(NOT value STREQUAL "inertialnet.tune/1")
  message(FATAL_ERROR "schema is '${value}'")
endif()
foreach(field platform device driver model width height quick fraction)
  expect_json("${doc}" ${field})
endforeach()
foreach(field layer layers m n k)
  expect_json("${doc}" shapes 0 ${field})
endforeach()
foreach(field kernel parameters status)
  expect_json("${doc}" clblast ${field})
endforeach()
foreach(field MR PANELS_FIRST)
  expect_json("${doc}" packed parameters ${field})
endforeach()
expect_json("${doc}" packed parameters MR)
set(mr "${value}")
foreach(field seconds_default seconds_tuned)
  expect_json("${doc}" packed ${field})
endforeach()
foreach(field MR PANELS_FIRST seconds matches)
  expect_json("${doc}" packed trials 0 ${field})
endforeach()
file(GLOB stored "${WORK}/cache/tuning/*.json")
list(LENGTH stored count)
if(NOT count EQUAL 1)
  message(FATAL_ERROR "expected one stored tuning file, found: ${stored}")
endif()

# 2. A second process applies it.
run(0 ${CLI} tune --show)
expect_match("tuning file: .*cache/tuning/")
expect_match("packed MR=${mr} ")
execute_process(COMMAND ${CLI} bench --model FlowNet2-C --size 64x64 --pairs 1 --json RESULT_VARIABLE code
                OUTPUT_VARIABLE bench ERROR_VARIABLE err TIMEOUT 600)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "bench --json: exit ${code}\n${err}")
endif()
expect_json("${bench}" results 0 gemm_tuning)
if(NOT value MATCHES "inertialnet tune")
  message(FATAL_ERROR "bench's gemm_tuning does not name the stored tuning: '${value}'")
endif()

# 3. --no-cache neither reads nor writes it.
run(0 ${CLI} --no-cache tune --show)
expect_match("no tuning stored")
file(READ "${stored}" before)
file(WRITE "${stored}" "${before} ")  # a marker a rewrite would drop
run(0 ${CLI} --no-cache tune --quick)
expect_match("nothing was stored")
file(READ "${stored}" after)
if(NOT after STREQUAL "${before} ")
  message(FATAL_ERROR "tune --no-cache rewrote ${stored}")
endif()

# 4. A damaged file: a warning naming it, the defaults, exit 0.
file(WRITE "${stored}" "{\"schema\": \"inertialnet.tu")
run(0 ${CLI} tune --show)
expect_match("warning: ignoring the tuning file .*cache/tuning/")
expect_match("no tuning stored")

# 5. Damaged CLBlast parameters (issue 20, item 6): CLBlast takes any full set and only fails when
#    it compiles, which broke every CLBlast run. They are checked when read: one warning naming the
#    file and the key in our words, and a CLBlast run goes on with the defaults.
set(xgemm [=[{"GEMMK": 0, "KREG": 1, "KWG": 16, "KWI": 2, "MDIMA": 16, "MDIMC": 8, "MWG": 128, "NDIMB": 32,
  "NDIMC": 16, "NWG": 128, "SA": 0, "SB": 0, "STRM": 1, "STRN": 1, "VWM": 3, "VWN": 4}]=])
string(JSON damaged SET "${doc}" clblast parameters "${xgemm}")
file(WRITE "${stored}" "${damaged}")
run(0 ${CLI} --plan clblast bench --model FlowNet2-C --size 64x64 --pairs 1)
expect_match("warning: ignoring the tuning file .*cache/tuning/.*VWM is 3")
expect_no_match("json\\.exception")
expect_no_match("OpenCL compiler")
string(JSON damaged SET "${doc}" clblast parameters "{\"MWG\": -1}")
file(WRITE "${stored}" "${damaged}")
run(0 ${CLI} tune --show)
expect_match("'clblast.parameters.MWG' should be a whole number")
expect_no_match("json\\.exception")

# 6. `tune --show` does not present a stored value the packed GEMM does not support as applied.
string(JSON unsupported SET "${doc}" packed parameters MR 3)
file(WRITE "${stored}" "${unsupported}")
run(0 ${CLI} tune --show)
expect_match("not applied: packed MR=3 \\(MR takes 1, 2, 4")
expect_no_match("\napplied: [^\n]*MR=3")

# 7. Frame sizes too small to tune on are refused before anything is measured or stored.
file(WRITE "${stored}" "${doc}")
run(2 ${CLI} tune --quick --size 1x1)
expect_match("tune --size 1x1: too small to tune on")
file(READ "${stored}" after)
if(NOT after STREQUAL doc)
  message(FATAL_ERROR "tune --size 1x1 replaced ${stored}")
endif()

# 8. A cache folder that cannot be written: said so, naming it, and no exit 0 with nothing stored
#    (a path under a regular file: unwritable even for root). $INERTIALNET_CACHE_DIR is the
#    user's choice, so exit 2; --no-cache stays a note with exit 0.
file(WRITE "${WORK}/not-a-folder" "")
set(ENV{INERTIALNET_CACHE_DIR} "${WORK}/not-a-folder/cache")
run(2 ${CLI} tune --quick)
expect_match("the cache folder .*not-a-folder/cache cannot be written")
expect_no_match("--no-cache\\)")
set(ENV{INERTIALNET_NO_CACHE} 1)
run(0 ${CLI} tune --quick)
expect_match("the disk cache is off \\(INERTIALNET_NO_CACHE\\): nothing was stored")
unset(ENV{INERTIALNET_NO_CACHE})
set(ENV{INERTIALNET_CACHE_DIR} "${WORK}/cache")
