# SPDX-License-Identifier: Apache-2.0
# Bad inputs through the CLI: each case asserts the exit code (2 bad input, 1 runtime failure)
# and a fragment of the one-line message. Cases edit a copy of a small synthetic sequence.
#   cmake -DCLI=<inertialnet> -DWORK=<scratch dir> -P bad_inputs.cmake
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")

include(${CMAKE_CURRENT_LIST_DIR}/run_helpers.cmake)

# copy_with(<name> <file under mav0> <search> <replace>): a copy of the sequence with one edit.
function(copy_with name file search replace)
  file(REMOVE_RECURSE "${WORK}/${name}")
  file(COPY "${WORK}/seq/" DESTINATION "${WORK}/${name}")
  file(READ "${WORK}/${name}/mav0/${file}" text)
  string(FIND "${text}" "${search}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "${file} holds no '${search}' to replace")
  endif()
  string(REPLACE "${search}" "${replace}" text "${text}")
  file(WRITE "${WORK}/${name}/mav0/${file}" "${text}")
endfunction()

run(0 ${CLI} synth seq --frames 3 --size 96x64 --seed 7)

# 4. A NaN in T_BS is not a rotation; it is refused where it is read, naming the file and entry.
copy_with(nan_tbs cam0/sensor.yaml "data: [0.0148655429818" "data: [.nan")
run(2 ${CLI} predict nan_tbs)
expect_match("nan_tbs/mav0/cam0/sensor.yaml: T_BS.data\\[0\\] is nan; it should be a finite number")

# 6. Frames of mixed sizes in a folder (the DIS path): refused before OpenCV, naming the frame.
run(0 ${CLI} synth small --frames 2 --size 64x48 --seed 7)
file(GLOB frames "${WORK}/seq/mav0/cam0/data/*.png")
file(GLOB small_frames "${WORK}/small/mav0/cam0/data/*.png")
list(SORT frames)
list(GET frames 0 frame_a)
list(GET frames 1 frame_b)
list(GET small_frames 0 frame_c)
file(MAKE_DIRECTORY "${WORK}/mixed")
file(COPY_FILE "${frame_a}" "${WORK}/mixed/frame1.png")
file(COPY_FILE "${frame_b}" "${WORK}/mixed/frame2.png")
file(COPY_FILE "${frame_c}" "${WORK}/mixed/frame3.png")
# Since every pair has a row, the odd frame costs its pair (decode_error, warned by name), not the run.
run(0 ${CLI} predict mixed --fx 50)
expect_match("pair 2 \\(frames 1 → 2, t = 50000000 → 100000000 ns\\): geometric: decode_error: frame 2 \\(t = 100000000 ns\\) is 64x48 but frame 1 \\(t = 50000000 ns\\) is 96x64; every frame")
expect_match("100000000,,,,decode_error")

# 6b. A frame whose bytes are no frame format (the fuzzer's finding: "DICM" at byte 128 sent it to
# OpenCV's DICOM decoder, whose assert aborted the process): its two pairs are decode_error rows
# naming the file and what it is; the third pair is answered and the run completes.
file(MAKE_DIRECTORY "${WORK}/dicom")
file(COPY_FILE "${frame_a}" "${WORK}/dicom/frame1.png")
file(COPY_FILE "${CMAKE_CURRENT_LIST_DIR}/../fuzz/regressions/image/gdcm_assert_dicm_at_byte_128.png"
     "${WORK}/dicom/frame2.png")
file(COPY_FILE "${frame_b}" "${WORK}/dicom/frame3.png")
file(COPY_FILE "${frame_a}" "${WORK}/dicom/frame4.png")
run(0 ${CLI} predict dicom --fx 50)
expect_match("pair 2 \\(frames 1 → 2, [^)]*\\): geometric: decode_error: frame 1 [^:]*: The image \"[^\"]*dicom/frame2.png\" cannot be decoded: it is a DICOM file \\(\"DICM\" at byte 128\\); frames are PNG, JPEG")
expect_match("2 of 3 pairs without an answer \\(decode_error 2\\)")
expect_no_match("Assertion")

# 7. A resolution far from the images' is refused before anything is allocated for it.
copy_with(huge_resolution cam0/sensor.yaml "resolution: [96, 64]" "resolution: [100000, 100000]")
run(2 ${CLI} predict huge_resolution)
expect_match("gives the resolution 100000x100000, which does not match the images \\(96x64\\)")

# 8. Options and files that used to be taken silently or blamed on something else.
run(2 ${CLI} predict seq --max-pairs -1)
expect_match("--max-pairs: must be a count of pairs \\(0 for all\\), got -1")
run(2 ${CLI} predict mixed --rate nan)
expect_match("--rate: must be a finite positive number, got nan")
run(2 ${CLI} predict mixed --rate 0)
expect_match("--rate: must be a finite positive number, got 0")
run(2 ${CLI} predict mixed --fx nan)
expect_match("--fx: must be a finite positive number, got nan")
run(2 ${CLI} predict mixed --fx 50 --cx inf)
expect_match("--cx: must be a finite number, got inf")
file(REMOVE_RECURSE "${WORK}/yaml_folder")
file(COPY "${WORK}/seq/" DESTINATION "${WORK}/yaml_folder")
file(REMOVE "${WORK}/yaml_folder/mav0/cam0/sensor.yaml")
file(MAKE_DIRECTORY "${WORK}/yaml_folder/mav0/cam0/sensor.yaml")
run(2 ${CLI} predict yaml_folder)
expect_match("yaml_folder/mav0/cam0/sensor.yaml is not a regular file")
# A sensor.yaml on which OpenCV's YAML parser looped forever (a fuzzing finding, 35 bytes): the
# root mapping ends early and a '-' follows, so it is refused before the parser runs.
file(REMOVE_RECURSE "${WORK}/yaml_hang")
file(COPY "${WORK}/seq/" DESTINATION "${WORK}/yaml_hang")
file(WRITE "${WORK}/yaml_hang/mav0/cam0/sensor.yaml" "%Y:\n- coXlvBS \nY:\n- coXlvBS:r_+)+ty")
run(2 ${CLI} predict yaml_hang)
expect_match("yaml_hang/mav0/cam0/sensor.yaml line 2: '-' where a key of the root mapping should be")
file(WRITE "${WORK}/not_a_folder" "")
run(2 ${CLI} predict seq --save-flow not_a_folder)
expect_match("--save-flow not_a_folder: cannot use it as a folder")

# A FIFO as cam0/data.csv: refused before it is opened (opening it would wait for a writer for ever).
file(REMOVE_RECURSE "${WORK}/fifo_csv")
file(COPY "${WORK}/seq/" DESTINATION "${WORK}/fifo_csv")
file(REMOVE "${WORK}/fifo_csv/mav0/cam0/data.csv")
execute_process(COMMAND mkfifo "${WORK}/fifo_csv/mav0/cam0/data.csv" RESULT_VARIABLE fifo_code)
if(NOT fifo_code EQUAL 0)
  message(FATAL_ERROR "mkfifo failed")
endif()
run(2 ${CLI} predict fifo_csv)
expect_match("fifo_csv/mav0/cam0/data.csv is not a regular file")

# --- The acceptance table of issue 11 continues: one case per bad input or fault, by item. ----

run(0 ${CLI} predict seq -o rates.csv)

# 4. NaN and infinity where numbers enter.
copy_with(inf_intrinsics cam0/sensor.yaml "intrinsics: [58.5515744680851" "intrinsics: [.inf")
run(2 ${CLI} predict inf_intrinsics)
expect_match("inf_intrinsics/mav0/cam0/sensor.yaml: intrinsics\\[0\\] is inf")
copy_with(nan_distortion cam0/sensor.yaml "distortion_coefficients: [0.0" "distortion_coefficients: [.nan")
run(2 ${CLI} predict nan_distortion)
expect_match("nan_distortion/mav0/cam0/sensor.yaml: distortion_coefficients\\[0\\] is nan")
copy_with(nan_gyro imu0/data.csv "1403715273262142976,0.0851979807676885" "1403715273262142976,nan")
run(2 ${CLI} eval rates.csv nan_gyro)
expect_match("nan_gyro/mav0/imu0/data.csv line 2: w_RS_S_x is \"nan\", expected a finite number")
file(WRITE "${WORK}/nan_rates.csv" "timestamp_ns,wx,wy,wz\n1403715273312142976,nan,0,0\n")
run(2 ${CLI} eval nan_rates.csv seq)
expect_match("nan_rates.csv line 2: wx is \"nan\", expected a finite number")

# 5. A lens model that does not invert (k1 = 1e6) is refused naming the file and coefficients.
copy_with(k1_huge cam0/sensor.yaml "distortion_coefficients: [0.0" "distortion_coefficients: [1e6")
run(2 ${CLI} predict k1_huge)
expect_match("cam0/sensor.yaml: the radial-tangential distortion coefficients \\[1e\\+06, 0, 0, 0\\] do not invert")
copy_with(k1_fold cam0/sensor.yaml "distortion_coefficients: [0.0" "distortion_coefficients: [-3.0")
run(2 ${CLI} predict k1_fold)
expect_match("cam0/sensor.yaml: the radial-tangential distortion coefficients \\[-3, 0, 0, 0\\] do not invert")

# 6. Timestamps at the ends of int64: no overflow, a message naming the rows.
copy_with(ts_overflow cam0/data.csv "1403715273312142976,1403715273312142976.png"
          "99999999999999999999,1403715273312142976.png")
run(2 ${CLI} predict ts_overflow)
expect_match("ts_overflow/mav0/cam0/data.csv line 3")
copy_with(ts_limits cam0/data.csv "1403715273262142976,1403715273262142976.png"
          "-9223372036854775807,1403715273262142976.png")
run(2 ${CLI} predict ts_limits)
expect_match("ts_limits/mav0/cam0/data.csv: the timestamps run from -9223372036854775807 \\(line 2\\).*the span must fit in a signed 64-bit count")

# 7. 1×1 frames (the fuzz corpus's smallest PNG): refused before OpenCV's DIS.
file(MAKE_DIRECTORY "${WORK}/one_pixel")
foreach(i 1 2 3)
  file(COPY_FILE "${CMAKE_CURRENT_LIST_DIR}/../fuzz/corpus/image/1x1.png" "${WORK}/one_pixel/frame${i}.png")
endforeach()
run(2 ${CLI} predict one_pixel --fx 50)
expect_match("camera size 1×1 is too small")
expect_no_match("Assertion failed")

# 8. A resolution of zero pixels.
copy_with(zero_resolution cam0/sensor.yaml "resolution: [96, 64]" "resolution: [0, 0]")
run(2 ${CLI} predict zero_resolution)
expect_match("zero_resolution/mav0/cam0/sensor.yaml: resolution should be \\[width, height\\] in pixels")

# 9. A program cache folder of another user is refused, never loaded from (root only: chown).
running_as_root(root)
if(root)
  file(MAKE_DIRECTORY "${WORK}/their_cache")
  execute_process(COMMAND chown 65534:65534 "${WORK}/their_cache" RESULT_VARIABLE chown_code)
  if(NOT chown_code EQUAL 0)
    message(FATAL_ERROR "chown failed")
  endif()
  run(2 ${CMAKE_COMMAND} -E env INERTIALNET_CACHE_DIR=${WORK}/their_cache ${CLI} predict seq)
  expect_match("their_cache belongs to user 65534, not to this user \\(0\\)")
  run(0 ${CMAKE_COMMAND} -E env INERTIALNET_CACHE_DIR=${WORK}/their_cache ${CLI} predict seq --no-cache)
else()
  message("skipped: a cache folder of another user (needs root to chown)")
endif()
file(WRITE "${WORK}/cache_file" "")
run(2 ${CMAKE_COMMAND} -E env INERTIALNET_CACHE_DIR=${WORK}/cache_file ${CLI} predict seq)
expect_match("cache_file exists and is not a folder")

# 10. A symbolic-link loop as an image: a message, never raw filesystem_error text.
file(REMOVE_RECURSE "${WORK}/loop")
file(COPY "${WORK}/seq/" DESTINATION "${WORK}/loop")
file(GLOB loop_frames "${WORK}/loop/mav0/cam0/data/*.png")
list(SORT loop_frames)
list(GET loop_frames 1 loop_frame)
file(REMOVE "${loop_frame}")
# Two links naming each other (CMake refuses to make a link to itself).
file(CREATE_LINK "${loop_frame}.other" "${loop_frame}" SYMBOLIC)
file(CREATE_LINK "${loop_frame}" "${loop_frame}.other" SYMBOLIC)
run(2 ${CLI} predict loop)
expect_match("loop/mav0/cam0/data.csv line 3: the image .* cannot be accessed: Too many levels of symbolic links")
expect_no_match("filesystem error")
file(MAKE_DIRECTORY "${WORK}/loop_folder")
file(COPY_FILE "${frame_a}" "${WORK}/loop_folder/frame1.png")
file(COPY_FILE "${frame_b}" "${WORK}/loop_folder/frame2.png")
file(CREATE_LINK "${WORK}/loop_folder/frame4.png" "${WORK}/loop_folder/frame3.png" SYMBOLIC)
file(CREATE_LINK "${WORK}/loop_folder/frame3.png" "${WORK}/loop_folder/frame4.png" SYMBOLIC)
run(2 ${CLI} predict loop_folder --fx 50)
expect_match("Image folder loop_folder: frame[34].png cannot be accessed: Too many levels of symbolic links")
expect_no_match("filesystem error")

# 10. An IMU that covers a minority of the rated frames: refused, not metrics over 1 of 5 rows.
run(0 ${CLI} synth seq5 --frames 6 --size 96x64 --seed 7)
run(0 ${CLI} predict seq5 -o rates5.csv)
file(STRINGS "${WORK}/seq5/mav0/imu0/data.csv" imu_lines)
list(SUBLIST imu_lines 0 14 imu_head)  # the header and 65 ms of samples: frames 0 and 1
list(JOIN imu_head "\n" imu_text)
file(WRITE "${WORK}/seq5/mav0/imu0/data.csv" "${imu_text}\n")
run(2 ${CLI} eval rates5.csv seq5)
expect_match("covers only 1 of the 5 rates rows")

# 10. Sizes: the documented × works, a stray byte of it does not, six digits get a range.
run(0 ${CLI} synth times --frames 2 --size 64×48 --seed 1)
expect_match("64x48")
string(ASCII 195 stray)
run(2 ${CLI} synth stray --frames 2 --size 64${stray}48)
expect_match("is not of the form WIDTHxHEIGHT")
run(2 ${CLI} bench --size 123456x96)
expect_match("width and height must be from 1 to 99999 pixels")
run(2 ${CLI} synth zero --frames 2 --size 0x48)
expect_match("width and height must be from 1 to 99999 pixels")

# 10. Numbers out of range, named with their value.
run(2 ${CLI} predict mixed --fx 1e308)
expect_match("--fx: must be at most 1e\\+06 pixels, got 1e308")
run(2 ${CLI} predict mixed --fx 50 --fy -1)
expect_match("--fy: must be a finite positive number, got -1")
run(2 ${CLI} predict mixed --fx 50 --cy 1e300)
expect_match("--cy: must be at most 1e\\+06 pixels from the origin, got 1e300")
run(2 ${CLI} predict mixed --rate 1e300)
expect_match("--rate: must be at most 1e\\+06 Hz, got 1e300")
copy_with(huge_gyro imu0/data.csv "1403715273267142976,0.09197330478921553" "1403715273267142976,1e308")
run(2 ${CLI} eval rates.csv huge_gyro)
expect_match("huge_gyro/mav0/imu0/data.csv line 3: w_RS_S_x is \"1e308\", beyond ±1000 rad/s")
file(WRITE "${WORK}/huge_rates.csv" "timestamp_ns,wx,wy,wz\n1403715273312142976,0,1e300,0\n")
run(2 ${CLI} eval huge_rates.csv seq)
expect_match("huge_rates.csv line 2: wy is \"1e300\", beyond ±1000 rad/s")

# 10. An inherited ignored SIGINT stays ignored: a background job must not die of the terminal's
# Ctrl-C. SIGINT is sent every 50 ms for the whole run; the run must finish every pair.
run(0 ${CLI} synth long --frames 30 --size 160x120 --seed 3)
# (A script file: run() passes its arguments as a CMake list, which would split at semicolons.)
file(WRITE "${WORK}/ignore_sigint.sh" [=[
trap '' INT
"$1" predict long -o ignored.csv &
pid=$!
while kill -0 $pid 2>/dev/null
do
  kill -INT $pid 2>/dev/null
  sleep 0.05
done
wait $pid
]=])
run(0 bash ignore_sigint.sh ${CLI})
file(STRINGS "${WORK}/ignored.csv" ignored_rows REGEX "^[^#]")  # the `# key: value` lines aside
list(LENGTH ignored_rows ignored_count)
if(NOT ignored_count EQUAL 30)
  message(FATAL_ERROR "ignored.csv has ${ignored_count} lines besides its # lines, expected a header and 29 rows")
endif()

# Usage and files that are simply wrong.
run(2 ${CLI} predict nosuch)
expect_match("sequence 'nosuch' does not exist")
run(2 ${CLI} predict seq --lanes 0)
expect_match("--lanes: Value 0 not in range 1 to 16")
run(2 ${CLI} predict seq --head sideways)
expect_match("unknown head 'sideways'")
run(2 ${CLI} predict seq --flow farneback)
expect_match("unknown flow method 'farneback'")
run(2 ${CLI} predict seq --solver fast)
expect_match("unknown solver 'fast'")
run(2 ${CLI} predict seq --flow flownet2)
expect_match("need weights")
run(2 ${CLI} weights --info seq/mav0/cam0/data.csv)
expect_match("not a safetensors file")
run(2 ${CLI} weights --synthetic Nope -o nope.safetensors)
expect_match("unknown model 'Nope'")
run(2 ${CLI} synth spin --frames 3 --motion spin)
expect_match("unknown motion 'spin'")
run(2 ${CLI} eval seq/mav0/cam0/data.csv seq)
expect_match("expected the header timestamp_ns,wx,wy,wz")
file(WRITE "${WORK}/backwards.csv" "timestamp_ns,wx,wy,wz\n1403715273362142976,0,0,0\n1403715273312142976,0,0,0\n")
run(2 ${CLI} eval backwards.csv seq)
expect_match("backwards.csv")
file(WRITE "${WORK}/short_row.csv" "timestamp_ns,wx,wy,wz\n1403715273312142976,0,0\n")
run(2 ${CLI} eval short_row.csv seq)
expect_match("short_row.csv line 2")
file(WRITE "${WORK}/empty_rates.csv" "")
run(2 ${CLI} eval empty_rates.csv seq)
expect_match("is empty")
copy_with(imu_columns imu0/data.csv "1403715273262142976,0.0851979807676885," "1403715273262142976,")
run(2 ${CLI} eval rates.csv imu_columns)
expect_match("imu_columns/mav0/imu0/data.csv line 2")
copy_with(no_filename cam0/data.csv "1403715273312142976,1403715273312142976.png" "1403715273312142976,")
run(2 ${CLI} predict no_filename)
expect_match("no_filename/mav0/cam0/data.csv line 3")
file(MAKE_DIRECTORY "${WORK}/truncated_folder")
file(COPY_FILE "${frame_a}" "${WORK}/truncated_folder/frame1.png")
execute_process(COMMAND head -c 200 "${frame_b}" OUTPUT_FILE "${WORK}/truncated_folder/frame2.png")
run(2 ${CLI} predict truncated_folder --fx 50)
expect_match("frame2.png\" is truncated")

# An IMU file beside an image folder or a video (eval --imu, --T-cam-imu, --camchain): each bad
# input is exit 2 with the option or file, and the key, named.
set(folder seq/mav0/cam0/data)
set(imu --imu seq/mav0/imu0/data.csv)
run(2 ${CLI} eval rates.csv ${folder})
expect_match("data is not a EuRoC sequence \\(no mav0/cam0/data.csv\\); as an image folder it holds no gyro: give the IMU with --imu FILE")
run(2 ${CLI} eval rates.csv ${folder} --imu nosuch.csv)
expect_match("--imu: File does not exist: nosuch.csv")
run(2 ${CLI} eval rates.csv ${folder} --imu imu_columns/mav0/imu0/data.csv)
expect_match("imu_columns/mav0/imu0/data.csv line 2: expected 7 comma-separated fields")
# Gyro logs in other units and layouts (--imu-time-unit, Gyroflow's .gcsv): a unit that clashes
# with the header's, one that is no unit, one without --imu, a time with decimals in a file that
# names no unit, a .gcsv without its scales.
file(WRITE "${WORK}/gyro_s.csv" "t_s,gx,gy,gz\n1403715273.262142976,0.1,0.2,0.3\n")
run(2 ${CLI} eval rates.csv ${folder} --imu gyro_s.csv --imu-time-unit ns)
expect_match("gyro_s.csv line 1: the time column \"t_s\" is in s, but --imu-time-unit says ns")
run(2 ${CLI} eval rates.csv ${folder} --imu gyro_s.csv --imu-time-unit sec)
expect_match("--imu-time-unit: unknown time unit 'sec'; expected one of s, ms, us, ns")
run(2 ${CLI} eval rates.csv seq --imu-time-unit s)
expect_match("--imu-time-unit describes the file given with --imu, and none is given")
file(WRITE "${WORK}/gyro_bare.csv" "0.005,0.1,0.2,0.3\n0.010,0.1,0.2,0.3\n")
run(2 ${CLI} eval rates.csv ${folder} --imu gyro_bare.csv)
expect_match("gyro_bare.csv line 1: the timestamp \\[ns\\] is \"0.005\", a time with decimals in a file that does not name its unit: give --imu-time-unit")
file(WRITE "${WORK}/no_scale.gcsv" "GYROFLOW IMU LOG\nversion,1.3\nid,x\norientation,XYZ\ngscale,1\nt,gx,gy,gz\n0,1,2,3\n")
run(2 ${CLI} calibrate-time ${folder} --imu no_scale.gcsv --fx 100)
expect_match("no_scale.gcsv \\(a Gyroflow .gcsv\\) has no tscale line")
# --imu-columns / --imu-units: without --imu, with --imu-time-unit, a gyro value that is not a
# number in a column chosen by name (file, line, column, value), an MP4 cut inside its first box.
run(2 ${CLI} eval rates.csv seq --imu-columns 0,1,2,3)
expect_match("--imu-columns and --imu-units describe the file given with --imu, and none is given")
run(2 ${CLI} eval rates.csv ${folder} --imu gyro_s.csv --imu-units s,rad/s --imu-time-unit s)
expect_match("--imu-time-unit excludes --imu-units")
file(WRITE "${WORK}/gyro_named.csv" "temp,wz,stamp,wx,wy
20,0.1,1.0,0.2,0.3
20,0.1,1.005,0.2,oops
")
run(2 ${CLI} eval rates.csv ${folder} --imu gyro_named.csv --imu-columns stamp,wx,wy,wz --imu-units s,rad/s)
expect_match("gyro_named.csv line 3: wy should be a number, found \"oops\"")
file(WRITE "${WORK}/short.mp4" "AAAAftypmp42")  # an ftyp box whose size (0x41414141) overruns the file
run(2 ${CLI} eval rates.csv ${folder} --imu short.mp4)
expect_match("short.mp4: damaged MP4 at byte offset 0: box 'ftyp' claims 1094795585 bytes, beyond the file's end \\(12 bytes\\)")
run(2 ${CLI} eval rates.csv ${folder} ${imu} --T-cam-imu "1 0 0 0 0 1 0 0 0 0 1 0")
expect_match("--T-cam-imu should be 16 numbers \\(a 4×4 T_cam_imu, row-major\\), found 12")
run(2 ${CLI} eval rates.csv ${folder} ${imu} --T-cam-imu "1 0.5 0 0 0 1 0 0 0 0 1 0 0 0 0 1")
expect_match("--T-cam-imu: the top-left 3×3 of T_cam_imu is not a rotation matrix \\(rows are not orthonormal within 1e-3\\)")
run(2 ${CLI} eval rates.csv ${folder} ${imu} --T-cam-imu "nan 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1")
expect_match("--T-cam-imu: the top-left 3×3 of T_cam_imu is not a rotation matrix")
run(2 ${CLI} eval rates.csv ${folder} ${imu} --T-cam-imu "-1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1")
expect_match("T_cam_imu is a reflection \\(determinant -1")
run(2 ${CLI} eval rates.csv ${folder} ${imu} --T-cam-imu "1 0 0 0 0 1 0 0 0 0 1 0 0 0 2 1")
expect_match("the last row of T_cam_imu should be \\[0, 0, 0, 1\\]")
run(2 ${CLI} eval rates.csv ${folder} ${imu} --T-cam-imu no_such_transform.yaml)
expect_match("\"no_such_transform.yaml\" is neither 16 numbers \\(a 4×4 T_cam_imu, row-major\\) nor an existing file")
file(WRITE "${WORK}/cam1_only.yaml" "cam1:\n  T_cam_imu:\n  - [1, 0, 0, 0]\n  - [0, 1, 0, 0]\n  - [0, 0, 1, 0]\n  - [0, 0, 0, 1]\n")
run(2 ${CLI} eval rates.csv ${folder} ${imu} --camchain cam1_only.yaml)
expect_match("cam1_only.yaml has no cam0 entry, so it is not a Kalibr camchain \\(its keys: cam1\\)")
file(WRITE "${WORK}/camchain_nan.yaml" "cam0:\n  T_cam_imu:\n  - [1, 0, 0, 0]\n  - [0, .nan, 0, 0]\n  - [0, 0, 1, 0]\n  - [0, 0, 0, 1]\n")
run(2 ${CLI} eval rates.csv ${folder} ${imu} --camchain camchain_nan.yaml)
expect_match("camchain_nan.yaml: cam0.T_cam_imu\\[1\\]\\[1\\] is nan; it should be a finite number")
file(WRITE "${WORK}/camchain_3x4.yaml" "cam0:\n  T_cam_imu:\n  - [1, 0, 0, 0]\n  - [0, 1, 0, 0]\n  - [0, 0, 1, 0]\n")
run(2 ${CLI} eval rates.csv ${folder} ${imu} --camchain camchain_3x4.yaml)
expect_match("camchain_3x4.yaml: cam0.T_cam_imu should be 4 rows of 4 numbers, found 3 rows")
file(WRITE "${WORK}/camchain_no_imu.yaml" "cam0:\n  camera_model: pinhole\n  intrinsics: [100, 100, 48, 32]\n")
run(2 ${CLI} eval rates.csv ${folder} ${imu} --camchain camchain_no_imu.yaml)
expect_match("camchain_no_imu.yaml: cam0 has no T_cam_imu")
run(2 ${CLI} eval rates.csv ${folder} ${imu} --camchain camchain_no_imu.yaml --T-cam-imu "1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1")
expect_match("--T-cam-imu excludes --camchain")
run(2 ${CLI} eval rates.csv seq ${imu} --T-cam-imu "1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1")
expect_match("seq is a EuRoC sequence, whose camera rotation comes from mav0/cam0/sensor.yaml's T_BS")
run(2 ${CLI} calibrate-time ${folder} ${imu})
expect_match("calibrate-time: seq/mav0/cam0/data has no camera calibration to predict with; give --calibration FILE or --fx")
# train's camera-IMU offset: a number of seconds, finite, within an hour.
run(2 ${CLI} train --train seq --val seq -o head.safetensors --time-offset nan)
expect_match("--time-offset should be a number of seconds")
run(2 ${CLI} train --train seq --val seq -o head.safetensors --time-offset 7200)
expect_match("time offset should be finite and within an hour, found 7200 s")

# Issue 20, item 9 (tune helper): numbers read as the user wrote them, echoed within 40
# characters; device indices of any length; rates whose frame interval fits in int64 ns; and a
# time offset the data do not fix is not offered for applying.
run(2 ${CLI} eval rates.csv seq --time-offset 0x10)
expect_match("--time-offset should be a number of seconds .*found \"0x10\"")
run(2 ${CLI} predict seq --rate 0x10)
expect_match("--rate: must be written in decimal, got 0x10")
run(2 ${CLI} predict seq --rate 1e-12)
expect_match("--rate: must be at least 1e-06 Hz, got 1e-12")
string(REPEAT "9" 300 long_number)
string(REPEAT "9" 40 shown_number)
run(2 ${CLI} predict seq --rate ${long_number})
expect_match("--rate: must be at most 1e\\+06 Hz, got ${shown_number}…")
expect_no_match("${shown_number}9")
run(2 ${CLI} eval rates.csv seq --time-offset ${long_number})
expect_match("found \"${shown_number}…\"")
expect_no_match("${shown_number}9")
run(2 ${CLI} synth long --frames ${long_number})  # CLI11's own message, cut the same way
expect_match("--frames: .*${shown_number}…")
expect_no_match("${shown_number}9")
run(2 ${CLI} --device 1234567 devices)
expect_match("There is no device with index 1234567 \\(there (is|are) [0-9]+ devices?")
run(0 ${CLI} synth still --frames 20 --size 96x64 --max-rate 0 --no-noise)
run(1 ${CLI} calibrate-time still)
expect_match("time offset not determined: the predicted rates show no rotation")
expect_no_match("apply it with")
expect_no_match("time_offset_s")

# --- The options and files of the last wave (issues 22-25), audited for bad input: each is exit
# 2 with one message naming the option, file or key and the value, before anything is computed.
# Numbers that CLI11's Range let through by other names ("Value abc not in range"):
run(2 ${CLI} predict seq --max-sigma abc)
# CLI11's messages too start with `inertialnet: error:` (docs/cli.md, "Output"), one line with
# the subcommand's help named (they came bare, with "Run with --help …" on a second line).
expect_match("^inertialnet: error: --max-sigma: must be a finite number from 0 up, got abc \\(see inertialnet predict --help\\)\n$")
run(2 ${CLI} predict seq --flow-check nan)
expect_match("--flow-check: must be a finite number from 0 up, got nan")
# --smooth: q read by strtod (0x10 was 16), q's value and the option named, a lag of four digits.
run(2 ${CLI} predict seq --smooth lag:2,q:0x10)
expect_match("--smooth \"lag:2,q:0x10\": q must be a positive decimal number, got 0x10")
run(2 ${CLI} predict seq --smooth lag:2,q:nan)
expect_match("--smooth \"lag:2,q:nan\": q must be a positive decimal number, got nan")
run(2 ${CLI} predict seq --smooth lag:2,q:1e300)
expect_match("--smooth \"lag:2,q:1e300\": .*must be from 1e-06 to 1e\\+06, got 1e\\+300")
run(2 ${CLI} predict seq --smooth lag:1000)
expect_match("--smooth \"lag:1000\": the lag must be 0 to 100 pairs, got 1000")
# calibrate --range and eval --time-offset-range: named and refused at parse (calibrate refused a
# NaN only after predicting every pair, without naming it; 1e300 was echoed in 300 digits).
run(2 ${CLI} calibrate seq --range nan)
expect_match("--range: must be a finite positive number, got nan")
expect_no_match("predicting")
run(2 ${CLI} eval rates.csv seq --time-offset auto --time-offset-range 1e300)
expect_match("--time-offset-range: must be at most 3600 s, got 1e300")
# Three numbers x,y,z (--extrinsic-error, --gyro-bias, --rotation-correction): decimal only (0x1
# was read as 1), a bias no gyro has refused (1e300 ran to exit 0).
run(2 ${CLI} synth hex_extrinsic --frames 2 --size 64x48 --extrinsic-error 0x1,0,0)
expect_match("--extrinsic-error should be three decimal numbers x,y,z; \"0x1\" is not one")
run(2 ${CLI} synth huge_extrinsic --frames 2 --size 64x48 --extrinsic-error 1e300,0,0)
expect_match("rotation vector of at most 30 degrees, found \\(1e\\+300, 0, 0\\) degrees")
run(2 ${CLI} eval rates.csv seq --gyro-bias 1e300,0,0)
expect_match("--gyro-bias: each component should be within \\+-1000 rad/s, found \"1e300,0,0\"")
run(2 ${CLI} eval rates.csv seq --rotation-correction 0x1,0,0)
expect_match("--rotation-correction should be three decimal numbers x,y,z; \"0x1\" is not one")
# eval --calibration-from: a report with a number beyond a double (exit 1 with the JSON library's
# text before), a readout the rates cannot have, a rotation or rating of another schema (taken
# silently before). A minimal good report first, so that each case differs from it by one key.
set(report_head "{\"schema\": \"inertialnet.calibrate/1\", ")
set(good_offset "\"time_offset\": {\"determined\": true, \"confidence\": \"high\", \"offset_s\": 0.001}")
file(WRITE "${WORK}/calib_good.json" "${report_head}\"rates_readout_time_s\": 0, ${good_offset}}")
run(0 ${CLI} eval rates.csv seq --calibration-from calib_good.json)
file(WRITE "${WORK}/calib_overflow.json" "${report_head}\"rates_readout_time_s\": 1e400, ${good_offset}}")
run(2 ${CLI} eval rates.csv seq --calibration-from calib_overflow.json)
expect_match("--calibration-from calib_overflow.json: holds a number beyond the range of a double")
expect_no_match("json.exception")
file(WRITE "${WORK}/calib_readout.json" "${report_head}\"rates_readout_time_s\": -5, ${good_offset}}")
run(2 ${CLI} eval rates.csv seq --calibration-from calib_readout.json)
expect_match("calib_readout.json: key \"rates_readout_time_s\" should be a readout time from 0 to 1 s, found -5")
file(WRITE "${WORK}/calib_rotation.json" "${report_head}${good_offset}, \"rotation_correction\": [1, 2, 3]}")
run(2 ${CLI} eval rates.csv seq --calibration-from calib_rotation.json)
expect_match("calib_rotation.json: key \"rotation_correction\" should be an object, found \\[1,2,3\\]")
file(WRITE "${WORK}/calib_rating.json"
     "${report_head}\"time_offset\": {\"determined\": true, \"confidence\": \"great\", \"offset_s\": 0.001}}")
run(2 ${CLI} eval rates.csv seq --calibration-from calib_rating.json)
expect_match("calib_rating.json: key \"time_offset.confidence\" should be high, medium, low or none, found \"great\"")
file(WRITE "${WORK}/calib_offset.json"
     "${report_head}\"time_offset\": {\"determined\": true, \"confidence\": \"high\", \"offset_s\": \"0.001\"}}")
run(2 ${CLI} eval rates.csv seq --calibration-from calib_offset.json)
expect_match("calib_offset.json: key \"time_offset.offset_s\" should be a number, found \"0.001\"")
# A batch whose manifest lists a sequence that is not there: refused before the first sequence is
# computed (it stopped the batch at its turn, naming neither the manifest nor the line's path).
file(WRITE "${WORK}/missing_manifest.txt" "seq\n\nno_such_sequence\n")
run(2 ${CLI} predict --manifest missing_manifest.txt -o missing_batch/)
# The line is named (third, after a blank one): a manifest may list hundreds.
expect_match("--manifest missing_manifest.txt:3: it lists the sequence .*no_such_sequence, which does not exist; nothing was computed")
if(EXISTS "${WORK}/missing_batch/seq.csv")
  message(FATAL_ERROR "the batch computed seq before refusing the manifest")
endif()
# The readout time quoted as given (std::to_string wrote -1.000000).
run(2 ${CLI} predict seq --readout-time -1)
expect_match("the readout time should be between 0 and 1 s, got -1[\r\n]")
# train --dropout and --augment-rotation, named at parse (the library's checks named no option and
# quoted 1 as 1.000000).
run(2 ${CLI} train --train seq --val seq -o head.safetensors --dropout 1)
expect_match("--dropout: must be below 1 \\(1 drops every unit\\), got 1")
run(2 ${CLI} train --train seq --val seq -o head.safetensors --dropout nan)
expect_match("--dropout: must be a finite number from 0 up, got nan")
run(2 ${CLI} train --train seq --val seq -o head.safetensors --augment-rotation 1e6)
expect_match("--augment-rotation: must be at most 1000 deg/s, got 1e6")
# train --cache-budget: NaN, inf and negatives were taken silently (no budget, or an undefined
# cast of inf to a byte count); refused at parse, naming the option and the value.
run(2 ${CLI} train --train seq --val seq -o head.safetensors --cache-budget nan)
expect_match("--cache-budget: must be a finite number from 0 up, got nan")
run(2 ${CLI} train --train seq --val seq -o head.safetensors --cache-budget inf)
expect_match("--cache-budget: must be a finite number from 0 up, got inf")
run(2 ${CLI} train --train seq --val seq -o head.safetensors --cache-budget -1)
expect_match("--cache-budget: must be a finite number from 0 up, got -1")
# train --lr: refused by the Trainer, which did not quote the value ("must be positive").
run(2 ${CLI} train --train seq --val seq -o head.safetensors --lr nan)
expect_match("the learning rate must be a finite number > 0, got nan")
# synth --extrinsic-error "": taken as not given before (a sequence without the error asked for).
# run() passes its arguments through ${ARGN}, which drops an empty one: called directly here.
execute_process(COMMAND ${CLI} synth empty_extrinsic --frames 3 --size 96x64 --extrinsic-error ""
                WORKING_DIRECTORY "${WORK}" RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 600)
message("$ synth --extrinsic-error \"\"\n${out}${err}(exit ${code})")
if(NOT "${code}" STREQUAL "2")
  message(FATAL_ERROR "expected exit code 2, got ${code}")
endif()
set(output "${out}${err}")
expect_match("--extrinsic-error should be three comma-separated numbers x,y,z, found \"\"")
if(EXISTS "${WORK}/empty_extrinsic")
  message(FATAL_ERROR "synth wrote a sequence for an empty --extrinsic-error")
endif()
# --flow-check above 1000 px (at 752 columns) switched the check off silently; the library's bound.
run(2 ${CLI} predict seq --flow-check 5000)
expect_match("--flow-check: must be at most 1000 pixels, got 5000")
