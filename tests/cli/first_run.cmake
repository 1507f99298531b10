# SPDX-License-Identifier: Apache-2.0
# A first run says that it compiles kernels (once per device, naming the cache folder); a run
# served from the cache says nothing; --stats times pairs only, after the compile; -q hides
# notes, -v adds the library's debug messages. The program cache is a private folder here, so
# that this test sees a first run whatever ran before.
#   cmake -DCLI=<inertialnet> -DWORK=<scratch dir> -P first_run.cmake
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")

include(${CMAKE_CURRENT_LIST_DIR}/run_helpers.cmake)
set(ENV{INERTIALNET_CACHE_DIR} "${WORK}/cache")
unset(ENV{INERTIALNET_NO_CACHE})

run(0 ${CLI} synth seq --frames 5 --size 96x64 --seed 2)

# 1. First run: one line, before the work; with -v each program compiled; --stats after a
# warm-up pair, with no compile after it.
run(0 ${CLI} predict seq -o first.csv --stats -v)
expect_match("compiling OpenCL kernels for [^\n]+ \\(first run; cached in [^\n]*/cache\\)")
string(REGEX MATCHALL "compiling OpenCL kernels" announced "${output}")
list(LENGTH announced count)
if(NOT count EQUAL 1)
  message(FATAL_ERROR "expected one 'compiling OpenCL kernels' line, got ${count}")
endif()
expect_match("debug: compiled kernel family '")
expect_match("warm-up pair on [^\n]+: [0-9.]+ s \\(kernel compile and planning; not counted below\\)")
string(FIND "${output}" "warm-up pair on" warmup_at)
string(SUBSTRING "${output}" ${warmup_at} -1 after_warmup)
if(after_warmup MATCHES "compiled kernel family")
  message(FATAL_ERROR "kernels compiled after the warm-up pair: their time is counted in --stats")
endif()
expect_match("\npairs: 4 in ")
# The texture gate is a stage of its own, so that the stages add up to the pair's time.
expect_match("\ntexture_gate: [0-9.e+-]+ s \\(summed over lanes\\), [0-9.e+-]+ s per pair\n")

# 2. Second run: served from the cache, silent about it; -v shows the loads.
run(0 ${CLI} predict seq -o second.csv -v)
if(output MATCHES "compiling OpenCL kernels")
  message(FATAL_ERROR "a cache hit announced a compile")
endif()
expect_match("debug: loaded kernel family '")

# 3. --no-cache: compiled every time, and said so.
run(0 ${CLI} predict seq -o third.csv --no-cache)
expect_match("compiling OpenCL kernels for [^\n]+ \\(program cache off\\)")

# 4. -q: no notes, no compile line; the rates are the same.
run(0 ${CLI} --no-cache predict seq -o quiet.csv -q)
if(NOT output STREQUAL "")
  message(FATAL_ERROR "-q printed: ${output}")
endif()
file(READ "${WORK}/second.csv" second)
file(READ "${WORK}/quiet.csv" quiet)
if(NOT second STREQUAL quiet)
  message(FATAL_ERROR "-q changed the rates")
endif()
