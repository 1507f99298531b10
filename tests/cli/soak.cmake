# SPDX-License-Identifier: Apache-2.0
# tools/soak.sh: its verdict on samples made up here (flat, a step, a dip, the warm-up left out),
# and a short DIS soak end to end (warm-up run, samples, summary file). The long soaks are not
# run here (see docs/performance.md).
#   cmake -DCLI=<inertialnet> -DWORK=<scratch dir> -DSOURCE=<source tree> -P soak.cmake
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")
include(${CMAKE_CURRENT_LIST_DIR}/run_helpers.cmake)
set(soak bash ${SOURCE}/tools/soak.sh)

# samples(<file> <kB>:<count>...): one sample a second, load 1.5, in runs of equal RSS.
function(samples file)
  set(text "")
  set(second 0)
  foreach(run IN LISTS ARGN)
    string(REPLACE ":" ";" run "${run}")
    list(GET run 0 kb)
    list(GET run 1 n)
    foreach(i RANGE 1 ${n})
      math(EXPR second "${second} + 1")
      string(APPEND text "${second},${kb},1.5\n")
    endforeach()
  endforeach()
  file(WRITE "${WORK}/${file}" "${text}")
endfunction()

# Start-up (the first 20 % of the samples) and tear-down (the last 3 s, as the process frees its
# buffers) are not judged: 10 samples at 100 MiB, 37 at 1 GiB, 3 at 600 MiB.
samples(startup.csv 102400:10 1048576:37 614400:3)
run(0 ${soak} --analyse ${WORK}/startup.csv startup 50)
expect_match("startup: 50 pairs in 50 s \\(1.00 pairs/s, start-up included\\), load average 1.5 \\(max 1.5\\)")
expect_match("after the first 20 % of 50 samples and before the last 3 s: median 1024.0 MiB, min \\+0.0 %, max \\+0.0 %, largest step 0.0 MiB; peak 1024.0 MiB: flat")
# A step of 6 % after the warm-up: not flat, and the step is named.
samples(step.csv 1048576:40 1111490:20)
run(0 ${soak} --analyse ${WORK}/step.csv step 60)
expect_match("max \\+6.0 %, largest step 61.4 MiB; peak 1085.4 MiB: NOT flat")
# A dip of 5.1 % below the median: not flat either; 4.9 % is.
samples(dip.csv 1048576:40 995099:10 1048576:3)
run(0 ${soak} --analyse ${WORK}/dip.csv dip 50)
expect_match("min -5.1 %.*NOT flat")
samples(within.csv 1048576:40 997196:10 1048576:3)
run(0 ${soak} --analyse ${WORK}/within.csv within 50)
expect_match("min -4.9 %.*: flat")
# Nothing left between warm-up and tear-down: no verdict.
samples(short.csv 1048576:3)
run(0 ${soak} --analyse ${WORK}/short.csv short 3)
expect_match("short: 3 pairs in 3 s, 3 samples: too short to judge")

# End to end on a few DIS pairs: the warm-up run, the samples (seconds,kB,load) and the summary.
execute_process(COMMAND ${CMAKE_COMMAND} -E env INERTIALNET_CLI=${CLI} SOAK_DIR=${WORK}/run
                        INERTIALNET_CACHE_DIR=${WORK}/cache ${soak} dis 12
                RESULT_VARIABLE code OUTPUT_VARIABLE output ERROR_VARIABLE err TIMEOUT 600)
message("$ tools/soak.sh dis 12\n${output}${err}(exit ${code})")
if(NOT code EQUAL 0)
  message(FATAL_ERROR "tools/soak.sh dis 12 failed")
endif()
expect_match("dis: warm-up run \\(2 pairs, fills the kernel caches\\): [0-9]+ s")
expect_match("dis: 12 pairs in [0-9]+ s.*: (flat|NOT flat|too short to judge)")
file(READ "${WORK}/run/summary_dis.txt" summary)
if(NOT summary MATCHES "^dis: 12 pairs")
  message(FATAL_ERROR "summary_dis.txt: ${summary}")
endif()
file(STRINGS "${WORK}/run/rss_dis.csv" rows)
list(GET rows 0 row)
if(NOT row MATCHES "^[0-9]+,[0-9]+,[0-9.]+$")
  message(FATAL_ERROR "rss_dis.csv: '${row}' is not seconds,kB,load")
endif()
file(STRINGS "${WORK}/run/rates_dis.csv" rates REGEX "^[0-9]")
list(LENGTH rates count)
if(NOT count EQUAL 12)
  message(FATAL_ERROR "rates_dis.csv has ${count} rows, expected 12")
endif()
