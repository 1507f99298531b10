# Videos as the user brings them (issue 20, item 3): a clip cut short is said and read as far as it
# goes; a clip with two damaged frames keeps the true times of every other frame and names the
# damaged frames; FFmpeg prints nothing itself (with -v its lines come as "debug: FFmpeg: …").
# The videos come from make_test_video (tests/support/test_video.hpp): 40 frames at 20 Hz, frame 15
# garbled, frame 16 without JPEG data, the cut copy ending where frame 28 begins.
#   cmake -DCLI=<inertialnet> -DMAKE_VIDEO=<make_test_video> -DWORK=<scratch dir> -P video_integrity.cmake
include(${CMAKE_CURRENT_LIST_DIR}/run_helpers.cmake)
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")
run(0 ${MAKE_VIDEO} .)
set(intrinsics --fx 150 --fy 150 --cx 94 --cy 60)
# What FFmpeg, GStreamer or OpenCV would print themselves.
set(raw "\\[(mjpeg|avi|mpeg4|h264) @ 0x|libpng|GStreamer|OpenCV\\(|\\[ WARN:")

# rows_of(<csv>): sets `rows` to the timestamps (first column) of the file's data rows.
function(rows_of file)
  file(STRINGS "${WORK}/${file}" lines REGEX "^[0-9]")
  set(stamps "")
  foreach(line IN LISTS lines)
    string(REGEX MATCH "^[0-9]+" stamp "${line}")
    list(APPEND stamps ${stamp})
  endforeach()
  set(rows "${stamps}" PARENT_SCOPE)
endfunction()

# The intact clip: 39 pairs, the last at frame 39's time.
run(0 ${CLI} predict clip.avi ${intrinsics} -o clip.csv)
expect_no_match("${raw}")
rows_of(clip.csv)
list(LENGTH rows n)
list(GET rows -1 last)
if(NOT n EQUAL 39 OR NOT last STREQUAL "1950000000")
  message(FATAL_ERROR "clip.csv: ${n} rows, the last at ${last}; expected 39, the last at 1950000000")
endif()

# Cut short: 28 frames, 27 pairs, and a note saying that 12 frames are missing.
run(0 ${CLI} predict cut.avi ${intrinsics} -o cut.csv)
expect_match("note: The video cut.avi ends after 28 of the 40 frames its header announces; the rest is missing.")
expect_no_match("${raw}")
rows_of(cut.csv)
list(LENGTH rows n)
if(NOT n EQUAL 27)
  message(FATAL_ERROR "cut.csv: ${n} rows, expected 27")
endif()

# Damaged: frames 15 and 16 cannot be decoded, named with their times. Until the pipeline keeps
# going past an undecodable frame the run stops there with exit 2; once it does (decode_error rows,
# issue 20 item 1) it exits 0 and every row after the damage keeps its frame's true time (frame 17
# at 850 ms, not 750 ms as when the two frames were dropped and the rest renumbered).
execute_process(COMMAND ${CLI} predict damaged.avi ${intrinsics} -o damaged.csv WORKING_DIRECTORY "${WORK}"
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 600)
set(output "${out}${err}")
message("$ predict damaged.avi\n${output}(exit ${code})")
expect_match("frame 15 \\(t = 750000000 ns\\) of video '[^']*damaged.avi' cannot be decoded: its data is corrupt")
expect_no_match("${raw}")
if(code EQUAL 0)
  expect_match("frame 16 \\(t = 800000000 ns\\) of video '[^']*damaged.avi' cannot be decoded")
  file(READ "${WORK}/damaged.csv" csv)
  if(NOT csv MATCHES "decode_error")
    message(FATAL_ERROR "damaged.csv has no decode_error row")
  endif()
  rows_of(damaged.csv)
  list(GET rows -1 last)
  if(NOT last STREQUAL "1950000000" OR NOT "850000000" IN_LIST rows OR NOT "900000000" IN_LIST rows)
    message(FATAL_ERROR "damaged.csv: rows ${rows}; expected frame 17 at 850000000, 18 at 900000000, the last at 1950000000")
  endif()
elseif(NOT code EQUAL 2)
  message(FATAL_ERROR "predict damaged.avi: exit ${code}, expected 0 (decode_error rows) or 2 (stopped at frame 15)")
endif()

# -v: FFmpeg's complaints about the damage come through our log, prefixed.
execute_process(COMMAND ${CLI} -v predict damaged.avi ${intrinsics} -o damaged_v.csv WORKING_DIRECTORY "${WORK}"
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 600)
set(output "${out}${err}")
expect_match("inertialnet: debug: FFmpeg: \\[mjpeg @ 0x[0-9a-f]+\\] ")
string(REGEX REPLACE "inertialnet: debug: FFmpeg: [^\n]*" "" output "${output}")
expect_no_match("${raw}")
