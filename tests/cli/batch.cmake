# SPDX-License-Identifier: Apache-2.0
# Many sequences at once (issue 25, docs/cli.md "Batches"): `predict SEQ... -o FOLDER` writes one
# rates file per sequence and resumes a batch that stopped; `eval` over the folder prints the
# per-sequence table with a total row.
#   cmake -DCLI=<inertialnet> -DWORK=<scratch dir> -P batch.cmake
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")
include(${CMAKE_CURRENT_LIST_DIR}/run_helpers.cmake)

foreach(i 1 2 3)
  run(0 ${CLI} synth s${i} --frames 5 --size 96x64 --seed ${i})
endforeach()

# fingerprint(<var> <name>): the CSV's and sidecar's bytes and modification times, to tell a file
# left alone from one written again (a recompute writes the same bytes, so the times tell).
function(fingerprint var name)
  file(SHA256 "${WORK}/out/${name}.csv" csv)
  file(SHA256 "${WORK}/out/${name}.csv.json" sidecar)
  file(TIMESTAMP "${WORK}/out/${name}.csv" csv_time "%s")
  file(TIMESTAMP "${WORK}/out/${name}.csv.json" sidecar_time "%s")
  set(${var} "${csv} ${sidecar} ${csv_time} ${sidecar_time}" PARENT_SCOPE)
endfunction()
# later(): waits past the second, so that a file written again gets another modification time.
function(later)
  execute_process(COMMAND ${CMAKE_COMMAND} -E sleep 1.1)
endfunction()

# 1. Interrupted after the first sequence (the second cannot be read: its camera folder is gone):
#    the first is complete, nothing of the others; the batch says where it stopped, exit 2.
file(RENAME "${WORK}/s2/mav0/cam0" "${WORK}/s2_cam0")
run(2 ${CLI} predict s1 s2 s3 -o out)
expect_match("\\[1/3\\] s1: computing")
expect_match("the batch stopped at s2 \\(2 of 3\\); rerun the same command to resume it")
expect_match("s2 has no camera cam0")
foreach(f out/s1.csv out/s1.csv.json)
  if(NOT EXISTS "${WORK}/${f}")
    message(FATAL_ERROR "${f} missing after the first sequence completed")
  endif()
endforeach()
foreach(f out/s2.csv out/s3.csv)
  if(EXISTS "${WORK}/${f}")
    message(FATAL_ERROR "${f} written although the batch stopped before it")
  endif()
endforeach()
file(READ "${WORK}/out/s1.csv.json" sidecar)
expect_json("${sidecar}" provenance inputs)
expect_json("${sidecar}" provenance flow_check_px)
fingerprint(first s1)

# 2. Fixed and rerun: only the remaining two are computed; the first is left as it was.
file(RENAME "${WORK}/s2_cam0" "${WORK}/s2/mav0/cam0")
later()
run(0 ${CLI} predict s1 s2 s3 -o out)
expect_match("\\[1/3\\] s1: skipped \\(current\\)")
expect_match("\\[2/3\\] s2: computing \\(not computed yet\\)")
expect_match("\\[3/3\\] s3: computing")
expect_match("batch: 2 computed, 1 skipped \\(current\\)")
fingerprint(again s1)
if(NOT first STREQUAL again)
  message(FATAL_ERROR "s1's output changed on the resumed batch:\n${first}\n${again}")
endif()
# Each file is what `predict SEQ -o FILE` writes alone, byte for byte (the provenance aside).
run(0 ${CLI} predict s2 -o alone_s2.csv)
file(SHA256 "${WORK}/alone_s2.csv" alone)
file(SHA256 "${WORK}/out/s2.csv" batched)
if(NOT alone STREQUAL batched)
  message(FATAL_ERROR "out/s2.csv differs from predict s2 -o alone_s2.csv")
endif()
file(READ "${WORK}/alone_s2.csv.json" alone_sidecar)
string(JSON alone_provenance ERROR_VARIABLE none GET "${alone_sidecar}" provenance)
if(NOT none)
  message(FATAL_ERROR "a single-sequence predict wrote a provenance block; it should not")
endif()

# 3. Nothing left: a rerun (through a manifest and -o FOLDER/) computes nothing.
file(WRITE "${WORK}/list.txt" "# the three sequences\ns1\n\ns2\ns3\n")
fingerprint(first s3)
later()
run(0 ${CLI} predict --manifest list.txt -o out/)
expect_match("batch: 0 computed, 3 skipped \\(current\\)")
fingerprint(again s3)
if(NOT first STREQUAL again)
  message(FATAL_ERROR "s3's output changed although it was current")
endif()

# 4. Not complete, not current: a run killed in the middle (its journal, no CSV), an edited CSV, an
#    input touched since, each recomputed; an option that changes the rates recomputes all three.
file(RENAME "${WORK}/out/s3.csv" "${WORK}/out/s3.csv.partial")
file(REMOVE "${WORK}/out/s3.csv.json")
file(APPEND "${WORK}/out/s1.csv" "9999999999999999999,0,0,0,ok\n")
file(TOUCH "${WORK}/s2/mav0/cam0/data.csv")
run(0 ${CLI} predict s1 s2 s3 -o out)
expect_match("s1: computing \\(unreadable")
expect_match("s2: computing \\(made with another inputs")
expect_match("s3: computing \\(an earlier run stopped before its end\\)")
if(EXISTS "${WORK}/out/s3.csv.partial")
  message(FATAL_ERROR "the journal of the stopped run is still there")
endif()
run(0 ${CLI} predict s1 s2 s3 -o out --flow-check 0.25)
expect_match("s1: computing \\(made with another flow_check_px: 0.5, now 0.25\\)")
expect_match("batch: 3 computed, 0 skipped")
run(0 ${CLI} predict s1 s2 s3 -o out --flow-check 0.25)
expect_match("batch: 0 computed, 3 skipped")

# 5. Bad batches, refused before anything is computed (exit 2, naming the problem).
file(MAKE_DIRECTORY "${WORK}/other/s1")
file(COPY "${WORK}/s1/mav0" DESTINATION "${WORK}/other/s1")
run(2 ${CLI} predict s1 other/s1 -o dup)
expect_match("would both write dup/s1.csv")
run(2 ${CLI} predict s1 s2)
expect_match("give the folder with -o FOLDER")
run(2 ${CLI} predict s1 s2 -o fmt --format tum)
expect_match("--format tum: a batch writes rates CSVs")
file(WRITE "${WORK}/empty.txt" "# nothing\n")
run(2 ${CLI} predict --manifest empty.txt -o out)
expect_match("empty.txt lists no sequence")
file(WRITE "${WORK}/a_file" "x")
run(2 ${CLI} predict s1 s2 -o a_file)
expect_match("-o a_file: it exists and is not a folder")
