# SPDX-License-Identifier: Apache-2.0
# What a person at a terminal sees: the progress line ends before any summary, after a normal
# run and after Ctrl-C, and -q draws none. Runs the CLI on a pseudo-terminal (pty_run.py).
#   cmake -DCLI=<inertialnet> -DPYTHON=<python3> -DWORK=<scratch dir> -P tty.cmake
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")

include(${CMAKE_CURRENT_LIST_DIR}/run_helpers.cmake)
set(PTY ${PYTHON} ${CMAKE_CURRENT_LIST_DIR}/pty_run.py)

run(0 ${CLI} synth seq --frames 8 --size 96x64 --seed 4)
# A long sequence, so that Ctrl-C lands in the middle of the run.
run(0 ${CLI} synth long --frames 200 --size 320x240 --seed 4 --no-noise)

# 1. The summary of --stats starts on its own line: never "eta 0s pairs: 7 in …".
run(0 ${PTY} -- ${CLI} predict seq -o rates.csv --stats)
expect_match("predict \\[#+\\] 7/7")
expect_match("\npairs: 7 in ")
if(output MATCHES "eta [0-9]+s *pairs:")
  message(FATAL_ERROR "the summary is on the progress line")
endif()

# 2. Ctrl-C: the progress line ends, then the message on a line of its own; exit 1.
run(1 ${PTY} --interrupt-after "  eta " -- ${CLI} predict long -o long.csv --lanes 1)
expect_match("\ninertialnet: interrupted after [0-9]+ of 199 pairs")
if(output MATCHES "eta [0-9]+s[ ^C]*inertialnet:")
  message(FATAL_ERROR "the interruption message is on the progress line")
endif()

# 3. -q: no progress line, no notes.
run(0 ${PTY} -- ${CLI} predict seq -o quiet.csv -q)
if(output MATCHES "predict \\[" OR output MATCHES "no weights given")
  message(FATAL_ERROR "-q still shows progress or notes")
endif()
