# SPDX-License-Identifier: Apache-2.0
# Videos as the user brings them (issue 20, item 3): a clip cut short is said and read as far as it
# goes; a clip with two damaged frames keeps the true times of every other frame, and the pairs of
# the damaged frames are decode_error rows naming them; FFmpeg prints nothing itself (with -v its
# lines come as "debug: FFmpeg: …").
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

# Damaged: frames 15 and 16 cannot be decoded. The run goes on (exit 0): the three pairs that use
# them are decode_error rows, with warnings naming the frames and their times, and every other row
# keeps its frame's true time (frame 17 at 850 ms, not 750 ms as when VideoCapture dropped the two
# frames and renumbered the rest; the last pair at 1950 ms, not 1850 ms).
run(0 ${CLI} predict damaged.avi ${intrinsics} -o damaged.csv)
expect_match("frame 15 \\(t = 750000000 ns\\) of video '[^']*damaged.avi' cannot be decoded: its data is corrupt")
expect_match("frame 16 \\(t = 800000000 ns\\) of video '[^']*damaged.avi' cannot be decoded: its data is corrupt")
expect_no_match("${raw}")
file(STRINGS "${WORK}/damaged.csv" lost REGEX "^[0-9]+,.*decode_error")
if(NOT lost STREQUAL "750000000,,,,decode_error,,,;800000000,,,,decode_error,,,;850000000,,,,decode_error,,,")
  message(FATAL_ERROR "damaged.csv: decode_error rows '${lost}'; expected those at 750, 800 and 850 ms")
endif()
rows_of(damaged.csv)
list(LENGTH rows n)
list(GET rows -1 last)
list(FIND rows 900000000 at18)
if(NOT n EQUAL 39 OR NOT last STREQUAL "1950000000" OR at18 EQUAL -1)
  message(FATAL_ERROR "damaged.csv: ${n} rows (${rows}); expected 39, frame 18's at 900000000, the last at 1950000000")
endif()

# -v: FFmpeg's complaints about the damage come through our log, prefixed.
run(0 ${CLI} -v predict damaged.avi ${intrinsics} -o damaged_v.csv)
expect_match("inertialnet: debug: FFmpeg: \\[mjpeg @ 0x[0-9a-f]+\\] ")
string(REGEX REPLACE "inertialnet: debug: FFmpeg: [^\n]*" "" output "${output}")
expect_no_match("${raw}")
