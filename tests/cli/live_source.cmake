# SPDX-License-Identifier: Apache-2.0
# Live input (issue 21): predict on a GStreamer pipeline as a live source. The same frames as a
# EuRoC folder give the same rates, bit for bit, and eval gives the same figures; Ctrl-C on a
# never-ending source is a clean end; a missing camera or a bad pipeline is exit 2 with a message.
#   cmake -DCLI=<inertialnet> -DPYTHON=<python3> -DWORK=<scratch dir> -P live_source.cmake
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")
include(${CMAKE_CURRENT_LIST_DIR}/run_helpers.cmake)

run(0 ${CLI} synth seq --frames 8 --size 96x64 --seed 3)
# The sequence's frames played back by GStreamer (its base plugins decode no PNG: raw GRAY8 bytes,
# read by rawvideoparse at the sequence's 20 Hz).
run(0 ${PYTHON} ${CMAKE_CURRENT_LIST_DIR}/png_frames_to_raw.py "${WORK}/seq/mav0/cam0" "${WORK}/frames.raw")
expect_match("96x64 8")
set(playback "gst:filesrc location=${WORK}/frames.raw ! rawvideoparse width=96 height=64 format=gray8 framerate=20/1 ! appsink")

# The same camera on both sides: the synthetic camera's intrinsics, given as flags.
intrinsics_flags(camera seq/mav0/cam0/sensor.yaml)

# 1. The frames as a EuRoC folder and as a live source. The capture clock cannot give the folder's
# stamps (GStreamer's position is the pipeline's running time, not exact 50 ms steps), so the live
# run takes --rate 20: frame k at k × 50 ms. The recording is put on that clock (every time in its
# CSVs less the first frame's), so that the same frames and gyro are a EuRoC folder on it.
file(STRINGS "${WORK}/seq/mav0/cam0/data.csv" stamps REGEX "^[0-9]")
list(GET stamps 0 first)
string(REGEX REPLACE ",.*" "" t0 "${first}")
file(COPY "${WORK}/seq/" DESTINATION "${WORK}/seq0")
foreach(csv cam0/data.csv imu0/data.csv state_groundtruth_estimate0/data.csv)
  file(STRINGS "${WORK}/seq0/mav0/${csv}" lines)
  set(text "")
  foreach(line IN LISTS lines)
    if(line MATCHES "^([0-9]+)(,.*)$")
      math(EXPR t "${CMAKE_MATCH_1} - ${t0}")
      set(line "${t}${CMAKE_MATCH_2}")
    endif()
    string(APPEND text "${line}\n")
  endforeach()
  file(WRITE "${WORK}/seq0/mav0/${csv}" "${text}")
endforeach()

run(0 ${CLI} predict seq0 ${camera} -o folder.csv)
run(0 ${CLI} predict ${playback} --rate 20 ${camera} -o live.csv)
expect_match("GStreamer pipeline, pairs until Ctrl-C or its end")
file(STRINGS "${WORK}/folder.csv" folder_rows REGEX "^[0-9]")
list(LENGTH folder_rows n)
if(NOT n EQUAL 7)
  message(FATAL_ERROR "expected 7 rows from the folder, got ${n}")
endif()
if(NOT folder_rows MATCHES ",ok")
  message(FATAL_ERROR "no pair answered: the comparison would prove nothing")
endif()
# Character for character: the same times, rates and statuses.
file(READ "${WORK}/folder.csv" folder_csv)
file(READ "${WORK}/live.csv" live_csv)
if(NOT folder_csv STREQUAL live_csv)
  message(FATAL_ERROR "live rates differ from the folder's:\n${live_csv}\nvs\n${folder_csv}")
endif()
# eval of both against the recording: the same figures (the file name aside).
run(0 ${CLI} eval folder.csv seq0)
string(REGEX MATCH "RMS\\(t\\)[^\n]*\n[^\n]*" folder_eval "${output}")
run(0 ${CLI} eval live.csv seq0)
string(REGEX MATCH "RMS\\(t\\)[^\n]*\n[^\n]*" live_eval "${output}")
if(folder_eval STREQUAL "" OR NOT folder_eval STREQUAL live_eval)
  message(FATAL_ERROR "eval differs: '${folder_eval}' vs '${live_eval}'")
endif()

# 2. Without --rate, the capture's clock, said in a note; the times increase.
run(0 ${CLI} predict ${playback} ${camera} -o clock.csv)
expect_match("note: Frame times of GStreamer pipeline from the capture's clock")
file(STRINGS "${WORK}/clock.csv" clock_rows REGEX "^[0-9]")
set(previous -1)
foreach(row IN LISTS clock_rows)
  string(REGEX MATCH "^[0-9]+" t "${row}")
  if(NOT t GREATER previous)
    message(FATAL_ERROR "capture times do not increase: ${clock_rows}")
  endif()
  set(previous ${t})
endforeach()

# 3. --max-pairs ends a never-ending source; rows on standard output.
set(endless "gst:videotestsrc is-live=true pattern=smpte horizontal-speed=2 ! video/x-raw,width=96,height=64,framerate=20/1 ! videoconvert ! appsink")
run(0 ${CLI} predict ${endless} --fx 80 --max-pairs 2)
expect_match("up to 2 pairs")
string(REGEX MATCHALL "\n[0-9]+,[^\n]*,(ok|[a-z_]+)" rows "${output}")
list(LENGTH rows n)
if(NOT n EQUAL 2)
  message(FATAL_ERROR "--max-pairs 2 wrote ${n} rows")
endif()

# 4. Ctrl-C: exit 0, every computed pair written, rows flushed as they come (interrupt_live.py).
run(0 ${PYTHON} ${CMAKE_CURRENT_LIST_DIR}/interrupt_live.py ${CLI} "${WORK}")
expect_match("all checks passed")

# 5. What cannot be opened: exit 2, our words (no "does not exist" for a folder, no GLib criticals).
run(2 ${CLI} predict /dev/video97 --fx 80)
expect_match("inertialnet: error: no camera at /dev/video97: the device does not exist")
expect_no_match("sequence '/dev/video97' does not exist")
run(2 ${CLI} predict camera:x --fx 80)
expect_match("expected camera:N with N a camera index")
run(2 ${CLI} predict "gst:videotestsrc ! fakesink" --fx 80)
expect_match("should end in appsink")
run(2 ${CLI} predict "gst:nosuchsource ! appsink" --fx 80)
expect_match("GStreamer cannot run the pipeline 'nosuchsource ! appsink'")
expect_no_match("CRITICAL|WARNING \\*\\*")
run(2 ${CLI} predict "gst:videotestsrc num-buffers=1 ! video/x-raw,width=96,height=64 ! appsink" --fx 80)
expect_match("GStreamer pipeline ended before its second frame")
run(2 ${CLI} predict ${playback} --camera cam1 --fx 80)
expect_match("--camera cam1 picks a camera of a EuRoC sequence")
