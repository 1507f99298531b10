# SPDX-License-Identifier: Apache-2.0
# An IMU file for any input (`eval --imu FILE`, `calibrate-time --imu FILE`): the frames of a
# synthetic EuRoC sequence as a plain folder of images (mav0/cam0/data, nanosecond names), its
# imu0/data.csv given with --imu and the rotation to the camera given three ways (16 numbers,
# cam0/sensor.yaml's T_BS, a Kalibr camchain written here in Kalibr's layout), must give the
# RMSE of the EuRoC path: the same rates, rotated by the same matrix, against the same gyro.
#   cmake -DCLI=<inertialnet> -DWORK=<scratch dir> -P imu_file.cmake
include(${CMAKE_CURRENT_LIST_DIR}/run_helpers.cmake)
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")

run(0 ${CLI} synth seq --frames 20 --size 188x120 --seed 3)
intrinsics_flags(intrinsics seq/mav0/cam0/sensor.yaml)
set(imu --imu seq/mav0/imu0/data.csv)
# The inverse of synth's (EuRoC's) cam0 T_BS: IMU → camera.
set(row0 "0.0148655429818, 0.999557249008, -0.0257744366974, 0.06522290953550845")
set(row1 "-0.999880929698, 0.0149672133247, 0.00375618835797, -0.020706385492708257")
set(row2 "0.00414029679422, 0.025715529948, 0.999660727178, -0.008054602460028365")
set(row3 "0.0, 0.0, 0.0, 1.0")
function(write_camchain name shift)
  file(WRITE "${WORK}/${name}"
       "cam0:\n  T_cam_imu:\n  - [${row0}]\n  - [${row1}]\n  - [${row2}]\n  - [${row3}]\n  cam_overlaps: []\n"
       "  camera_model: pinhole\n  distortion_coeffs: [0.0, 0.0, 0.0, 0.0]\n  distortion_model: radtan\n"
       "  intrinsics: [114.6635, 114.324, 91.42875, 61.71875]\n  resolution: [188, 120]\n"
       "  rostopic: /cam0/image_raw\n  timeshift_cam_imu: ${shift}\n")
endfunction()
write_camchain(camchain.yaml 0.0)
write_camchain(camchain_shift.yaml 0.004)

run(0 ${CLI} predict seq -o euroc.csv)
run(0 ${CLI} predict seq/mav0/cam0/data ${intrinsics} -o folder.csv)


foreach(frame "" "--camera-frame")
  run(0 ${CLI} eval euroc.csv seq --json ${frame})
  rmse_of(reference "${output}")
  run(0 ${CLI} eval folder.csv seq/mav0/cam0/data ${imu} --T-cam-imu "${row0}, ${row1}, ${row2}, ${row3}" --json ${frame})
  rmse_of(numbers "${output}")
  expect_same_rmse("${reference}" "${numbers}" "--T-cam-imu NUMBERS ${frame}")
  expect_json("${output}" estimators 0 rates_frame)
  if(NOT value STREQUAL "camera")
    message(FATAL_ERROR "the folder's rates should state the camera frame, not ${value}")
  endif()
  run(0 ${CLI} eval folder.csv seq/mav0/cam0/data ${imu} --T-cam-imu seq/mav0/cam0/sensor.yaml --json ${frame})
  rmse_of(sensor_yaml "${output}")
  expect_same_rmse("${reference}" "${sensor_yaml}" "--T-cam-imu sensor.yaml ${frame}")
  run(0 ${CLI} eval folder.csv seq/mav0/cam0/data ${imu} --camchain camchain.yaml --json ${frame})
  rmse_of(camchain "${output}")
  expect_same_rmse("${reference}" "${camchain}" "--camchain ${frame}")
endforeach()

# The text report says where the rotation came from; without one, the IMU frame is the camera's.
run(0 ${CLI} eval folder.csv seq/mav0/cam0/data ${imu} --camchain camchain.yaml)
expect_match("note: IMU to camera rotation from camchain.yaml \\(cam0\\)")
expect_match("Predictions rotated from the camera frame \\(as the rates file states\\) into the body frame with the IMU-camera rotation given")
run(0 ${CLI} eval folder.csv seq/mav0/cam0/data ${imu})
expect_match("the IMU frame is taken to be the camera frame")

# The camchain's timeshift_cam_imu is the time offset (t_imu = t_cam + shift) unless --time-offset.
run(0 ${CLI} eval folder.csv seq/mav0/cam0/data ${imu} --camchain camchain_shift.yaml --json)
expect_json("${output}" estimators 0 time_offset_s)
if(NOT value EQUAL 0.004)
  message(FATAL_ERROR "time_offset_s ${value}, expected the camchain's 0.004")
endif()
run(0 ${CLI} eval folder.csv seq/mav0/cam0/data ${imu} --camchain camchain_shift.yaml --time-offset 0 --json)
expect_json("${output}" estimators 0 time_offset_s)
if(NOT value EQUAL 0)
  message(FATAL_ERROR "time_offset_s ${value}: --time-offset 0 should win over the camchain")
endif()

# A EuRoC sequence takes --imu in place of imu0/data.csv (the same file here: the same raw RMSE).
run(0 ${CLI} eval euroc.csv seq --json)
rmse_of(reference "${output}")
run(0 ${CLI} eval euroc.csv seq ${imu} --json)
rmse_of(replaced "${output}")
expect_same_rmse("${reference}" "${replaced}" "EuRoC with --imu")
expect_match("instead of [^\n]*imu0/data.csv, taken to be in imu0's frame")

# The same gyro as a gyro-only CSV in seconds (the time unit named by the header, t_s) and as
# Gyroflow's .gcsv (t in milliseconds with tscale 0.001, the accelerometer left out): the same
# samples to the nanosecond, so the same RMSE as the EuRoC path.
file(STRINGS "${WORK}/seq/mav0/imu0/data.csv" imu_rows REGEX "^[0-9]")
set(seconds_csv "t_s,gx,gy,gz\n")
set(gcsv "GYROFLOW IMU LOG\nversion,1.3\nid,inertialnet_test\norientation,XYZ\ntscale,0.001\ngscale,1\nt,gx,gy,gz\n")
foreach(row IN LISTS imu_rows)
  if(NOT row MATCHES "^([0-9]+)([0-9][0-9][0-9])([0-9][0-9][0-9][0-9][0-9][0-9]),([^,]+,[^,]+,[^,]+),")
    message(FATAL_ERROR "unexpected imu0 row: ${row}")
  endif()
  string(APPEND seconds_csv "${CMAKE_MATCH_1}.${CMAKE_MATCH_2}${CMAKE_MATCH_3},${CMAKE_MATCH_4}\n")
  string(APPEND gcsv "${CMAKE_MATCH_1}${CMAKE_MATCH_2}.${CMAKE_MATCH_3},${CMAKE_MATCH_4}\n")
endforeach()
file(WRITE "${WORK}/gyro_seconds.csv" "${seconds_csv}")
file(WRITE "${WORK}/gyro.gcsv" "${gcsv}")
run(0 ${CLI} eval euroc.csv seq --json)
rmse_of(reference "${output}")
foreach(log gyro_seconds.csv gyro.gcsv)
  run(0 ${CLI} eval folder.csv seq/mav0/cam0/data --imu ${log} --camchain camchain.yaml --json)
  rmse_of(from_log "${output}")
  expect_same_rmse("${reference}" "${from_log}" "--imu ${log}")
endforeach()
# --imu-time-unit reads a file whose header names no unit.
string(REPLACE "t_s,gx,gy,gz" "time,gx,gy,gz" unnamed "${seconds_csv}")
file(WRITE "${WORK}/gyro_unnamed.csv" "${unnamed}")
run(0 ${CLI} eval folder.csv seq/mav0/cam0/data --imu gyro_unnamed.csv --imu-time-unit s --camchain camchain.yaml --json)
rmse_of(from_option "${output}")
expect_same_rmse("${reference}" "${from_option}" "--imu-time-unit s")

# calibrate-time on the folder: predicts with --fx …, and finds a 40 ms offset as on EuRoC input.
run(0 ${CLI} synth late --frames 60 --size 188x120 --seed 5 --time-offset 0.04)
run(0 ${CLI} calibrate-time late/mav0/cam0/data --imu late/mav0/imu0/data.csv --T-cam-imu seq/mav0/cam0/sensor.yaml ${intrinsics})
expect_match("no rates file given: predicting 59 pairs")
if(NOT output MATCHES "time_offset_s (-?[0-9.]+)")
  message(FATAL_ERROR "no time_offset_s line")
endif()
if(CMAKE_MATCH_1 LESS 0.035 OR CMAKE_MATCH_1 GREATER 0.045)
  message(FATAL_ERROR "time_offset_s ${CMAKE_MATCH_1}, expected 0.040 within 0.005")
endif()
expect_match("apply it with: inertialnet eval RATES.csv late/mav0/cam0/data --imu late/mav0/imu0/data.csv --T-cam-imu")

# calibrate-time reads the same gyro log in seconds (--imu-time-unit s, the header naming no unit),
# finds the same offset, and its suggested eval line repeats the unit.
file(STRINGS "${WORK}/late/mav0/imu0/data.csv" late_rows REGEX "^[0-9]")
set(late_seconds "time,gx,gy,gz\n")
foreach(row IN LISTS late_rows)
  if(NOT row MATCHES "^([0-9]+)([0-9][0-9][0-9][0-9][0-9][0-9][0-9][0-9][0-9]),([^,]+,[^,]+,[^,]+),")
    message(FATAL_ERROR "unexpected imu0 row: ${row}")
  endif()
  string(APPEND late_seconds "${CMAKE_MATCH_1}.${CMAKE_MATCH_2},${CMAKE_MATCH_3}\n")
endforeach()
file(WRITE "${WORK}/late_seconds.csv" "${late_seconds}")
run(0 ${CLI} calibrate-time late/mav0/cam0/data --imu late_seconds.csv --imu-time-unit s --T-cam-imu seq/mav0/cam0/sensor.yaml ${intrinsics})
if(NOT output MATCHES "time_offset_s (-?[0-9.]+)")
  message(FATAL_ERROR "no time_offset_s line")
endif()
if(CMAKE_MATCH_1 LESS 0.035 OR CMAKE_MATCH_1 GREATER 0.045)
  message(FATAL_ERROR "time_offset_s ${CMAKE_MATCH_1} from the log in seconds, expected 0.040 within 0.005")
endif()
expect_match("apply it with: inertialnet eval RATES.csv late/mav0/cam0/data --imu late_seconds.csv --imu-time-unit s --T-cam-imu")

# A generic CSV in seconds and deg/s, its columns in another order among others, read with
# --imu-columns and --imu-units: the same gyro (to the 17 digits written), so the same RMSE.
set(generic "temperature,wz_dps,stamp,wx_dps,pressure,wy_dps\n")
set(to_deg 57.295779513082320876798)
foreach(row IN LISTS imu_rows)
  string(REGEX MATCH "^([0-9]+)([0-9][0-9][0-9][0-9][0-9][0-9][0-9][0-9][0-9]),([^,]+),([^,]+),([^,]+)," _ "${row}")
  set(seconds "${CMAKE_MATCH_1}.${CMAKE_MATCH_2}")
  set(wx "${CMAKE_MATCH_3}")
  set(wy "${CMAKE_MATCH_4}")
  set(wz "${CMAKE_MATCH_5}")
  list(APPEND generic_rows "20.5,${wz},${seconds},${wx},1013,${wy}")
endforeach()
if(PYTHON)
  # CMake has no floating point: Python converts rad/s to deg/s (17 significant digits).
  file(WRITE "${WORK}/rows.txt" "${generic_rows}")
  execute_process(COMMAND ${PYTHON} -c "
import math
rows = open('${WORK}/rows.txt').read().split(';')
out = ['temperature,wz_dps,stamp,wx_dps,pressure,wy_dps']
for r in rows:
    t, wz, s, wx, p, wy = r.split(',')
    out.append(','.join([t, repr(math.degrees(float(wz))), s, repr(math.degrees(float(wx))), p, repr(math.degrees(float(wy)))]))
open('${WORK}/gyro_generic.csv', 'w').write('\\n'.join(out) + '\\n')
" RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "writing gyro_generic.csv failed")
  endif()
  run(0 ${CLI} eval folder.csv seq/mav0/cam0/data --imu gyro_generic.csv --imu-columns stamp,wx_dps,wy_dps,wz_dps
      --imu-units s,deg/s --camchain camchain.yaml --json)
  rmse_of(from_generic "${output}")
  expect_same_rmse("${reference}" "${from_generic}" "--imu gyro_generic.csv --imu-columns --imu-units s,deg/s")
  # The same by 0-based index; and a unit that contradicts the header is refused.
  run(0 ${CLI} eval folder.csv seq/mav0/cam0/data --imu gyro_generic.csv --imu-columns 2,3,5,1
      --imu-units s,deg/s --camchain camchain.yaml --json)
  rmse_of(from_index "${output}")
  expect_same_rmse("${reference}" "${from_index}" "--imu-columns 2,3,5,1")
  run(2 ${CLI} eval folder.csv seq/mav0/cam0/data --imu gyro_generic.csv --imu-columns stamp,wx_dps,wy_dps,wz_dps
      --imu-units s,rad/s)
  expect_match("gyro_generic.csv line 1: the gyro column \"wx_dps\" is in deg/s, but --imu-units says rad/s")
  run(2 ${CLI} eval folder.csv seq/mav0/cam0/data --imu gyro_generic.csv --imu-units s,degrees)
  expect_match("--imu-units: expected TIME,GYRO with TIME one of s, ms, us, ns and GYRO rad/s or deg/s, got s,degrees")
  run(2 ${CLI} eval folder.csv seq/mav0/cam0/data --imu gyro_generic.csv --imu-columns stamp,wx,wy,omega --imu-units s,deg/s)
  expect_match("--imu-columns: gyro_generic.csv line 1: no column named \"omega\" among: temperature, wz_dps, stamp")

  # A GoPro MP4 (tests/support/write_gopro_mp4.py: the PNG frames as a lossless 'png ' video track,
  # the gyro as HERO5 GPMF, int16 / SCAL 10000): `predict` gives the folder's rates exactly (the
  # same pixels), and `eval rec.mp4 --imu rec.mp4` reads the samples the writer says it stored
  # (expected.csv, to every digit: the same RMSE). Against the EuRoC path the gyro differs by the
  # int16 rounding, at most half of 1/SCAL rad/s per axis before rotation, so the camera-frame RMSE
  # agrees within sqrt(3)·0.5e-4 rad/s = 0.005 deg/s.
  run(0 ${PYTHON} ${CMAKE_CURRENT_LIST_DIR}/../support/write_gopro_mp4.py seq rec.mp4 --expected expected.csv)
  run(0 ${CLI} predict rec.mp4 ${intrinsics} -o video.csv)
  foreach(csv folder.csv video.csv)
    file(STRINGS "${WORK}/${csv}" rows REGEX "^[0-9]")
    list(TRANSFORM rows REPLACE "^[0-9]+," "")
    set(rates_${csv} "${rows}")
  endforeach()
  if(NOT rates_folder.csv STREQUAL rates_video.csv)
    message(FATAL_ERROR "predict on rec.mp4 gives other rates than on its frames as a folder:\n${rates_video.csv}\n${rates_folder.csv}")
  endif()
  run(0 ${CLI} eval euroc.csv seq --json --camera-frame)
  rmse_of(euroc_camera "${output}")
  run(0 ${CLI} eval video.csv rec.mp4 --imu expected.csv --json --camera-frame)
  rmse_of(expected_camera "${output}")
  run(0 ${CLI} eval video.csv rec.mp4 --imu rec.mp4 --json --camera-frame)
  rmse_of(gopro_camera "${output}")
  expect_same_rmse("${expected_camera}" "${gopro_camera}" "--imu rec.mp4 against the samples written")
  foreach(k 0 1 2)
    list(GET euroc_camera ${k} e)
    list(GET gopro_camera ${k} g)
    execute_process(COMMAND ${PYTHON} -c "import sys; sys.exit(abs(${e} - ${g}) > 0.005)" RESULT_VARIABLE far)
    if(NOT far EQUAL 0)
      message(FATAL_ERROR "--imu rec.mp4: camera-frame RMSE ${gopro_camera} deg/s, the EuRoC path ${euroc_camera}")
    endif()
  endforeach()
  # The axis order an ORIN item states (lower case: negated), as HERO8 and later write it.
  run(0 ${PYTHON} ${CMAKE_CURRENT_LIST_DIR}/../support/write_gopro_mp4.py seq rec_orin.mp4 --orin yZx --expected expected_orin.csv)
  run(0 ${CLI} eval video.csv rec.mp4 --imu expected_orin.csv --json --camera-frame)
  rmse_of(expected_orin "${output}")
  run(0 ${CLI} eval video.csv rec.mp4 --imu rec_orin.mp4 --json --camera-frame)
  rmse_of(gopro_orin "${output}")
  expect_same_rmse("${expected_orin}" "${gopro_orin}" "--imu rec_orin.mp4 (ORIN yZx) against the samples written")
  expect_no_match("no ORIN in its GPMF")
  run(0 ${CLI} eval video.csv rec.mp4 --imu rec.mp4)
  expect_match("note: rec.mp4: 191 gyro samples from its GoPro metadata \\(GPMF, axis order ZXY\\), timed by a fit to the payload times: 200 Hz from t = 0 ns")
  expect_match("IMU to camera rotation from GoPro's IMU axis labels")
  run(2 ${CLI} eval video.csv rec.mp4 --imu rec.mp4 --imu-units s,deg/s)
  expect_match("rec.mp4 is an MP4, whose GoPro metadata \\(GPMF\\) states its own units")

  # Damaged MP4s: the file and the byte offset named, exit 2. Cut short (the moov is lost and
  # mdat overruns the end); a GYRO item whose repeat claims more than its payload; no gpmd track.
  execute_process(COMMAND ${PYTHON} -c "
d = open('${WORK}/rec.mp4', 'rb').read()
open('${WORK}/cut.mp4', 'wb').write(d[:len(d) // 2])
k = d.index(b'GYRO')
open('${WORK}/klv.mp4', 'wb').write(d[:k + 6] + b'\\xff\\xff' + d[k + 8:])
print(k)
s = d.index(b'gpmd')
open('${WORK}/nogpmd.mp4', 'wb').write(d[:s] + b'xxxx' + d[s + 4:])
" OUTPUT_VARIABLE gyro_offset OUTPUT_STRIP_TRAILING_WHITESPACE)
  run(2 ${CLI} eval video.csv rec.mp4 --imu cut.mp4)
  expect_match("cut.mp4: damaged MP4 at byte offset 24: box 'mdat' claims [0-9]+ bytes, beyond the file's end")
  run(2 ${CLI} eval video.csv rec.mp4 --imu klv.mp4)
  expect_match("klv.mp4: damaged GPMF at byte offset ${gyro_offset}: GYRO claims 393210 bytes")
  run(2 ${CLI} eval video.csv rec.mp4 --imu nogpmd.mp4)
  expect_match("nogpmd.mp4 is an MP4 without GoPro metadata \\(a track whose sample description is 'gpmd'; tracks found, handler/format: vide/png , meta/xxxx\\)")
endif()
