# SPDX-License-Identifier: Apache-2.0
# Where the CLI's output goes: it never replaces what is not a regular file, writes through
# symbolic links, and never exits 0 when an output (standard output included) could not be written.
# Non-regular targets are private FIFOs in the scratch folder, never the system's /dev.
#   cmake -DCLI=<inertialnet> -DWORK=<scratch dir> -P outputs.cmake
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")

include(${CMAKE_CURRENT_LIST_DIR}/run_helpers.cmake)

function(make_fifo name)
  file(REMOVE "${WORK}/${name}")
  execute_process(COMMAND mkfifo "${WORK}/${name}" RESULT_VARIABLE code)
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "mkfifo ${name} failed")
  endif()
endfunction()

function(expect_fifo name)
  execute_process(COMMAND test -p "${WORK}/${name}" RESULT_VARIABLE code)
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "${name} is no longer a FIFO")
  endif()
endfunction()

run(0 ${CLI} synth seq --frames 3 --size 96x64 --seed 5)

# 1. weights -o, flow -o / --png, predict --save-flow: a FIFO is refused (exit 2) and kept.
make_fifo(pipe.safetensors)
run(2 ${CLI} weights --synthetic InertialNetHead --size 32x32 -o pipe.safetensors)
expect_match("pipe.safetensors: it exists and is not a regular file")
expect_fifo(pipe.safetensors)
run(0 ${CLI} weights --synthetic InertialNetHead --size 32x32 -o head.safetensors)
file(CREATE_LINK head.safetensors "${WORK}/link.safetensors" SYMBOLIC)
run(0 ${CLI} weights --synthetic InertialNetHead --size 40x32 -o link.safetensors)
if(NOT IS_SYMLINK "${WORK}/link.safetensors")
  message(FATAL_ERROR "weights -o replaced the symbolic link")
endif()
run(0 ${CLI} weights --info head.safetensors)
expect_match("\"input_width\":40")
run(0 ${CLI} weights --synthetic FlowNet2-C -o real.safetensors)

file(GLOB frames "${WORK}/seq/mav0/cam0/data/*.png")
list(SORT frames)
list(GET frames 0 first)
list(GET frames 1 second)
make_fifo(pipe.flo)
run(2 ${CLI} flow ${first} ${second} -w real.safetensors -o pipe.flo)
expect_match("pipe.flo: it exists and is not a regular file")
expect_fifo(pipe.flo)
make_fifo(pipe.png)
run(2 ${CLI} flow ${first} ${second} -w real.safetensors --png pipe.png)
expect_match("pipe.png: it exists and is not a regular file")
expect_fifo(pipe.png)

run(0 ${CLI} predict seq -o rates.csv --save-flow flows)
file(GLOB flows RELATIVE "${WORK}" "${WORK}/flows/*.flo")
list(GET flows 0 flo)
make_fifo(${flo})
run(2 ${CLI} predict seq -o rates.csv --save-flow flows)
expect_match("${flo}: it exists and is not a regular file")
expect_fifo(${flo})

# 2. eval --plot onto a FIFO: refused by name (exit 2), the FIFO kept.
make_fifo(pipe_plot.png)
run(2 ${CLI} eval rates.csv seq --plot pipe_plot.png)
expect_match("pipe_plot.png: it exists and is not a regular file")
expect_fifo(pipe_plot.png)

# 3. Standard output that cannot be written (/dev/full as a sink: opened for writing, never
# replaced) is a runtime failure, exit 1 with a message on stderr, for every command that prints.
function(run_to_full)
  execute_process(COMMAND ${ARGN} WORKING_DIRECTORY "${WORK}" RESULT_VARIABLE code OUTPUT_FILE /dev/full
                  ERROR_VARIABLE err TIMEOUT 300)
  message("$ ${ARGN} > /dev/full\n${err}(exit ${code})")
  if(NOT "${code}" STREQUAL "1")
    message(FATAL_ERROR "expected exit code 1, got ${code}")
  endif()
  if(NOT err MATCHES "cannot write to standard output")
    message(FATAL_ERROR "stderr does not say that standard output could not be written")
  endif()
endfunction()
run_to_full(${CLI} predict seq)
run_to_full(${CLI} eval rates.csv seq)
run_to_full(${CLI} eval rates.csv seq --json)
run_to_full(${CLI} weights --info head.safetensors)
run_to_full(${CLI} devices --json)
run_to_full(${CLI} devices)

# 4. One rule for output paths: missing folders are created for -o, --png, --plot and
# --save-flow alike; a file where a folder should be is refused by name (exit 2).
run(0 ${CLI} predict seq -o new/deeper/rates.csv --save-flow new/flows/deeper)
if(NOT EXISTS "${WORK}/new/deeper/rates.csv")
  message(FATAL_ERROR "predict -o did not create its folder")
endif()
file(GLOB deep_flows "${WORK}/new/flows/deeper/*.flo")
if(NOT deep_flows)
  message(FATAL_ERROR "predict --save-flow did not create its folder")
endif()
run(0 ${CLI} flow ${first} ${second} -w real.safetensors -o made/flow/pair.flo --png made/png/pair.png)
if(NOT EXISTS "${WORK}/made/flow/pair.flo" OR NOT EXISTS "${WORK}/made/png/pair.png")
  message(FATAL_ERROR "flow -o / --png did not create their folders")
endif()
run(0 ${CLI} eval new/deeper/rates.csv seq --plot plots/here/rates.png)
if(NOT EXISTS "${WORK}/plots/here/rates.png" OR NOT EXISTS "${WORK}/plots/here/rates_hist.png")
  message(FATAL_ERROR "eval --plot did not create its folder")
endif()
run(0 ${CLI} weights --synthetic InertialNetHead --size 32x32 -o weights/dir/head.safetensors)
if(NOT EXISTS "${WORK}/weights/dir/head.safetensors")
  message(FATAL_ERROR "weights -o did not create its folder")
endif()
file(WRITE "${WORK}/a_file" "")
run(2 ${CLI} predict seq -o a_file/rates.csv)
expect_match("-o a_file/rates.csv: cannot create the folder a_file")
run(2 ${CLI} eval new/deeper/rates.csv seq --plot a_file/plot.png)
expect_match("--plot a_file/plot.png: cannot create the folder a_file")
run(2 ${CLI} flow ${first} ${second} -w real.safetensors --png a_file/x/pair.png)
expect_match("--png a_file/x/pair.png: cannot create the folder a_file/x")

# 1. Device nodes as outputs: a private copy of /dev/null's node (character device 1:3) in the
# scratch folder, never the system's /dev. mknod needs root: skipped, saying so, otherwise.
running_as_root(root)
if(root)
  function(make_null name)
    file(REMOVE "${WORK}/${name}")
    execute_process(COMMAND mknod "${WORK}/${name}" c 1 3 RESULT_VARIABLE code)
    if(NOT code EQUAL 0)
      message(FATAL_ERROR "mknod ${name} failed")
    endif()
  endfunction()
  function(expect_device name)
    execute_process(COMMAND test -c "${WORK}/${name}" RESULT_VARIABLE code)
    if(NOT code EQUAL 0)
      message(FATAL_ERROR "${name} is no longer a character device")
    endif()
  endfunction()
  make_null(null.safetensors)
  run(2 ${CLI} weights --synthetic InertialNetHead --size 32x32 -o null.safetensors)
  expect_match("null.safetensors: it exists and is not a regular file")
  expect_device(null.safetensors)
  make_null(null.flo)
  run(2 ${CLI} flow ${first} ${second} -w real.safetensors -o null.flo)
  expect_match("null.flo: it exists and is not a regular file")
  expect_device(null.flo)
  make_null(null.png)
  run(2 ${CLI} eval rates.csv seq --plot null.png)
  expect_match("null.png: it exists and is not a regular file")
  expect_device(null.png)
  # A symbolic link to a device node is followed, and the node is refused just the same.
  make_null(null_target)
  file(CREATE_LINK null_target "${WORK}/link_to_null.flo" SYMBOLIC)
  run(2 ${CLI} flow ${first} ${second} -w real.safetensors -o link_to_null.flo)
  expect_match("it exists and is not a regular file")
  expect_device(null_target)
else()
  message("skipped: device nodes as outputs (mknod needs root)")
endif()

# 1. A symbolic link to a FIFO is followed and refused; the FIFO stays.
make_fifo(fifo_target)
file(CREATE_LINK fifo_target "${WORK}/link_to_fifo.safetensors" SYMBOLIC)
run(2 ${CLI} weights --synthetic InertialNetHead --size 32x32 -o link_to_fifo.safetensors)
expect_match("it exists and is not a regular file")
expect_fifo(fifo_target)

# 2. eval --plot where its folder cannot be made (a file is in the way): exit 2 naming the
# folder, and the file in the way is left as it was (missing folders are created: section 4).
file(WRITE "${WORK}/in_the_way" "keep me")
run(2 ${CLI} eval rates.csv seq --plot in_the_way/folder/plot.png)
expect_match("in_the_way")
file(READ "${WORK}/in_the_way" kept)
if(NOT kept STREQUAL "keep me")
  message(FATAL_ERROR "eval --plot changed the file in the way")
endif()

# 3. Standard output that cannot be written, for the remaining commands that print.
run_to_full(${CLI} synth full_seq --frames 2 --size 64x48 --seed 1)
run_to_full(${CLI} predict seq --head geometric)

# predict -o goes through the atomic writer: a symbolic link is written through and kept, a
# folder is refused, a character device the user names (here /dev/full's twin: /dev/full
# itself is only opened, never replaced) is written in place and its error is exit 1.
file(WRITE "${WORK}/rates_target.csv" "")
file(CREATE_LINK rates_target.csv "${WORK}/rates_link.csv" SYMBOLIC)
run(0 ${CLI} predict seq -o rates_link.csv)
if(NOT IS_SYMLINK "${WORK}/rates_link.csv")
  message(FATAL_ERROR "predict -o replaced the symbolic link")
endif()
file(STRINGS "${WORK}/rates_target.csv" linked_rows REGEX "^[^#]")  # the `# key: value` lines aside
list(LENGTH linked_rows linked_count)
if(NOT linked_count EQUAL 3)
  message(FATAL_ERROR "rates_target.csv has ${linked_count} lines besides its # lines, expected a header and 2 rows")
endif()
file(MAKE_DIRECTORY "${WORK}/rates_folder.csv")
run(2 ${CLI} predict seq -o rates_folder.csv)
expect_match("-o rates_folder.csv: it exists and is not a file")
run(1 ${CLI} predict seq -o /dev/full)
expect_match("Cannot write /dev/full: No space left on device")

# eval --plot never replaces what eval reads: the rates file as the plot is refused before any
# work, and the rates file is kept.
file(READ "${WORK}/new/deeper/rates.csv" rates_before)
run(2 ${CLI} eval new/deeper/rates.csv seq --plot new/deeper/rates.csv)
expect_match("--plot \\(new/deeper/rates.csv\\) would overwrite the input new/deeper/rates.csv")
file(READ "${WORK}/new/deeper/rates.csv" rates_after)
if(NOT rates_after STREQUAL rates_before)
  message(FATAL_ERROR "eval --plot onto its rates file changed it")
endif()
