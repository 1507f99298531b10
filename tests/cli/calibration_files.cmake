# SPDX-License-Identifier: Apache-2.0
# --calibration FILE (predict, eval, calibrate-time) on the frames of synthetic EuRoC sequences given
# as plain image folders (mav0/cam0/data, nanosecond names): the camera in each format — EuRoC
# sensor.yaml, a Kalibr camchain (with and without T_cam_imu, several cameras), OpenCV's
# cv::FileStorage YAML and XML (written here as that writer writes them) — must give the rates of
# the EuRoC folder itself, whose sensor.yaml holds the same numbers. synth renders an ideal pinhole,
# so the lens models are exercised by writing radtan and equidistant coefficients into copies of
# the sequence's sensor.yaml: the images stay the same, the rates change (checked), and they must
# change the same way through every file. Also: the notes of --fx alone, --cx 0 used, files that
# are refused naming file and key.
#   cmake -DCLI=<inertialnet> -DWORK=<scratch dir> [-DMAKE_VIDEO=<make_test_video>] -P calibration_files.cmake
include(${CMAKE_CURRENT_LIST_DIR}/run_helpers.cmake)
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")

run(0 ${CLI} synth seq --frames 8 --size 188x120 --seed 3)
file(READ "${WORK}/seq/mav0/cam0/sensor.yaml" yaml)
if(NOT yaml MATCHES "intrinsics: \\[([^,]+), ([^,]+), ([^,]+), ([^]]+)\\]")
  message(FATAL_ERROR "no intrinsics in the synthetic sensor.yaml")
endif()
set(fx ${CMAKE_MATCH_1})
set(fy ${CMAKE_MATCH_2})
set(cx ${CMAKE_MATCH_3})
set(cy ${CMAKE_MATCH_4})
set(intrinsics "[${fx}, ${fy}, ${cx}, ${cy}]")
# T_BS's 16 numbers, and T_cam_imu's rows: the rotation transposed (the same decimals, so the same
# doubles as predict's T_BS), no translation (it does not enter the rates).
if(NOT yaml MATCHES "data: \\[([^]]+)\\]")
  message(FATAL_ERROR "no T_BS in the synthetic sensor.yaml")
endif()
string(REGEX REPLACE "[ \n]" "" T_BS "${CMAKE_MATCH_1}")
string(REPLACE "," ";" T_BS "${T_BS}")
foreach(i 0 1 2)
  math(EXPR j "${i} + 4")
  math(EXPR k "${i} + 8")
  list(GET T_BS ${i} a)
  list(GET T_BS ${j} b)
  list(GET T_BS ${k} c)
  set(row${i} "[${a}, ${b}, ${c}, 0.0]")
endforeach()
set(identity "data: [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0]")

# variant(<name> <distortion model> <coefficients> <identity T_BS?>): a copy of seq with that lens
# in its sensor.yaml.
function(variant name model coefficients identity_T_BS)
  file(COPY "${WORK}/seq/" DESTINATION "${WORK}/${name}")
  string(REPLACE "distortion_model: radial-tangential" "distortion_model: ${model}" text "${yaml}")
  string(REPLACE "distortion_coefficients: [0.0, 0.0, 0.0, 0.0]" "distortion_coefficients: [${coefficients}]" text
         "${text}")
  if(identity_T_BS)
    string(REGEX REPLACE "data: \\[[^]]+\\]" "${identity}" text "${text}")
  endif()
  file(WRITE "${WORK}/${name}/mav0/cam0/sensor.yaml" "${text}")
endfunction()
set(radtan_d "-0.05, 0.01, 0.001, -0.002")
set(equi_d "-0.01, 0.004, -0.002, 0.0005")
variant(radtan radial-tangential "${radtan_d}" FALSE)  # EuRoC's T_BS: body-frame rates
variant(plain radial-tangential "${radtan_d}" TRUE)    # identity T_BS: camera frame = body frame
variant(equi equidistant "${equi_d}" TRUE)

# The rates of two runs compared line by line (header and rows: run_helpers' rates_lines_of).
function(expect_same_rows reference csv what)
  rates_lines_of(a ${reference})
  rates_lines_of(b ${csv})
  if(NOT a STREQUAL b)
    message(FATAL_ERROR "${what}: ${csv} differs from ${reference}:\n${b}\nvs\n${a}")
  endif()
endfunction()
function(expect_other_rows reference csv what)
  rates_lines_of(a ${reference})
  rates_lines_of(b ${csv})
  if(a STREQUAL b)
    message(FATAL_ERROR "${what}: ${csv} should differ from ${reference}")
  endif()
endfunction()

# --- The files ----------------------------------------------------------------------------------
# Kalibr's camchain-imucam.yaml (PyYAML block style), radtan, with T_cam_imu.
file(WRITE "${WORK}/camchain-imucam.yaml"
     "cam0:\n  T_cam_imu:\n  - ${row0}\n  - ${row1}\n  - ${row2}\n  - [0.0, 0.0, 0.0, 1.0]\n"
     "  cam_overlaps: []\n  camera_model: pinhole\n  distortion_coeffs: [${radtan_d}]\n"
     "  distortion_model: radtan\n  intrinsics: ${intrinsics}\n  resolution: [188, 120]\n"
     "  rostopic: /cam0/image_raw\n  timeshift_cam_imu: 0.0\n")
# A camera-only camchain.yaml of two cameras: cam1 is the equidistant camera, cam0 another.
file(WRITE "${WORK}/camchain.yaml"
     "cam0:\n  cam_overlaps: [1]\n  camera_model: pinhole\n  distortion_coeffs: [0.0, 0.0, 0.0, 0.0]\n"
     "  distortion_model: radtan\n  intrinsics: [100.0, 100.0, 93.5, 59.5]\n  resolution: [188, 120]\n"
     "  rostopic: /cam0/image_raw\n"
     "cam1:\n  cam_overlaps: [0]\n  camera_model: pinhole\n  distortion_coeffs: [${equi_d}]\n"
     "  distortion_model: equidistant\n  intrinsics: ${intrinsics}\n  resolution: [188, 120]\n"
     "  rostopic: /cam1/image_raw\n")
# opencv_yaml(<file> <width> <height> <fx> <cx> <coefficient count> <coefficients> <extra lines>):
# what cv::FileStorage writes for calibrateCamera's results (OpenCV's calibration sample).
function(opencv_yaml name width height fx_value cx_value count coefficients extra)
  file(WRITE "${WORK}/${name}"
       "%YAML:1.0\n---\ncalibration_time: \"Thu Nov 26 13:00:00 2026\"\nimage_width: ${width}\n"
       "image_height: ${height}\nflags: 0\ncamera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
       "   data: [ ${fx_value}, 0., ${cx_value}, 0., ${fy}, ${cy}, 0., 0., 1. ]\n"
       "distortion_coefficients: !!opencv-matrix\n   rows: ${count}\n   cols: 1\n   dt: d\n"
       "   data: [ ${coefficients} ]\n${extra}avg_reprojection_error: 2.1e-01\n")
endfunction()
opencv_yaml(fisheye.yaml 188 120 ${fx} ${cx} 4 "${equi_d}" "distortion_model: fisheye\n")
opencv_yaml(rational.yaml 188 120 ${fx} ${cx} 8 "${radtan_d}, 0., 0., 0., 0." "")
opencv_yaml(cx0.yaml 188 120 ${fx} 0. 5 "${radtan_d}, 0." "")
# The camera at twice the frames' size: the focal lengths doubled, c' = (c + 0.5)·2 − 0.5.
if(NOT intrinsics STREQUAL "[114.6635, 114.324, 91.42875, 61.71875]")
  message(FATAL_ERROR "synth's intrinsics changed to ${intrinsics}: update double.yaml's numbers")
endif()
opencv_yaml(double.yaml 376 240 229.327 183.3575 5 "${radtan_d}, 0." "")
file(READ "${WORK}/double.yaml" text)
string(REPLACE "0., ${fy}, ${cy}, 0." "0., 228.648, 123.9375, 0." text "${text}")
file(WRITE "${WORK}/double.yaml" "${text}")
opencv_yaml(wide.yaml 200 120 ${fx} ${cx} 5 "${radtan_d}, 0." "")
string(REPLACE ", " " " radtan_xml "${radtan_d}")
file(WRITE "${WORK}/opencv.xml"
     "<?xml version=\"1.0\"?>\n<opencv_storage>\n<calibration_time>\"Thu Nov 26 13:00:00 2026\"</calibration_time>\n"
     "<image_width>188</image_width>\n<image_height>120</image_height>\n"
     "<camera_matrix type_id=\"opencv-matrix\">\n  <rows>3</rows>\n  <cols>3</cols>\n  <dt>d</dt>\n"
     "  <data>\n    ${fx} 0. ${cx} 0.\n    ${fy} ${cy} 0. 0. 1.</data></camera_matrix>\n"
     "<distortion_coefficients type_id=\"opencv-matrix\">\n  <rows>5</rows>\n  <cols>1</cols>\n  <dt>d</dt>\n"
     "  <data>\n    ${radtan_xml} 0.</data></distortion_coefficients>\n"
     "<avg_reprojection_error>2.1e-01</avg_reprojection_error>\n</opencv_storage>\n")

# --- predict: each file gives the EuRoC folder's rates --------------------------------------------
foreach(name radtan plain equi)
  run(0 ${CLI} predict ${name} -o ${name}.csv)
endforeach()
# The lens models matter: without them the same frames give other rates.
run(0 ${CLI} predict plain/mav0/cam0/data --fx ${fx} --fy ${fy} --cx ${cx} --cy ${cy} -o pinhole.csv)
expect_other_rows(plain.csv pinhole.csv "radtan coefficients")
run(0 ${CLI} predict equi/mav0/cam0/data --fx ${fx} --fy ${fy} --cx ${cx} --cy ${cy} -o pinhole_equi.csv)
expect_other_rows(equi.csv pinhole_equi.csv "equidistant coefficients")

run(0 ${CLI} predict radtan/mav0/cam0/data --calibration radtan/mav0/cam0/sensor.yaml -o from_sensor_yaml.csv)
expect_match("geometric rates in the body \\(IMU\\) frame")
expect_same_rows(radtan.csv from_sensor_yaml.csv "EuRoC sensor.yaml")
run(0 ${CLI} predict radtan/mav0/cam0/data --calibration camchain-imucam.yaml -o from_kalibr.csv)
expect_match("geometric rates in the body \\(IMU\\) frame")
expect_same_rows(radtan.csv from_kalibr.csv "Kalibr camchain-imucam.yaml")
run(0 ${CLI} predict equi/mav0/cam0/data --calibration camchain.yaml --calibration-camera cam1 -o from_cam1.csv)
expect_no_match("using cam0")
expect_same_rows(equi.csv from_cam1.csv "Kalibr camchain.yaml, cam1")
run(0 ${CLI} predict equi/mav0/cam0/data --calibration camchain.yaml -o from_cam0.csv)
expect_match("note: camchain.yaml holds the cameras cam0, cam1: using cam0 \\(--calibration-camera picks another\\)")
expect_other_rows(equi.csv from_cam0.csv "Kalibr camchain.yaml, cam0")
run(0 ${CLI} predict equi/mav0/cam0/data --calibration fisheye.yaml -o from_fisheye.csv)
expect_match("geometric rates in the camera frame")
expect_same_rows(equi.csv from_fisheye.csv "OpenCV YAML, fisheye")
run(0 ${CLI} predict plain/mav0/cam0/data --calibration opencv.xml -o from_xml.csv)
expect_same_rows(plain.csv from_xml.csv "OpenCV XML")
run(0 ${CLI} predict plain/mav0/cam0/data --calibration rational.yaml -o from_rational.csv)
expect_match("note: rational.yaml: the 3 distortion coefficients after k3 are zero: read as k1 k2 p1 p2 k3")
expect_same_rows(plain.csv from_rational.csv "OpenCV YAML, 8 coefficients")
# On a EuRoC folder the file replaces its sensor.yaml, with a note.
run(0 ${CLI} predict seq --calibration opencv.xml -o seq_with_xml.csv)
expect_match("note: --calibration opencv.xml replaces EuRoC sequence seq[^\n]*'s cam0/sensor.yaml")
run(0 ${CLI} predict plain --calibration opencv.xml -o plain_with_xml.csv)
expect_same_rows(plain.csv plain_with_xml.csv "--calibration on a EuRoC folder")
# A calibration of twice the frames' size is scaled, with a note; another aspect is refused.
run(0 ${CLI} predict plain/mav0/cam0/data --calibration double.yaml -o from_double.csv)
expect_match("note: --calibration double.yaml is calibrated for 376x240 images; the frames are 188x120: its intrinsics are scaled by 0.5 x 0.5")
expect_same_rows(plain.csv from_double.csv "a calibration of twice the size, scaled")
run(2 ${CLI} predict plain/mav0/cam0/data --calibration wide.yaml)
expect_match("--calibration wide.yaml is calibrated for 200x120 images; the frames are 188x120, which is not a proportional resize")

# --- --fx alone, --cx 0, --fx with --calibration ------------------------------------------------
run(0 ${CLI} predict plain/mav0/cam0/data --fx ${fx} -o fx_alone.csv)
expect_match("note: --fy not given: assumed fy = fx = ${fx} px")
expect_match("note: --cx not given: assumed the image centre, cx = 93.5 px")
expect_match("note: --cy not given: assumed the image centre, cy = 59.5 px")
run(0 ${CLI} predict plain/mav0/cam0/data --fx ${fx} --fy ${fy} --cx ${cx} --cy ${cy})
expect_no_match("not given")
# --cx 0 is a principal point on the left edge, as the file's 0 is (the centre was taken before).
run(0 ${CLI} predict plain/mav0/cam0/data --calibration cx0.yaml -o cx0_file.csv)
run(0 ${CLI} predict plain/mav0/cam0/data --calibration opencv.xml --cx 0 -o cx0_flag.csv)
expect_match("note: --cx 0 replaces opencv.xml's cx ${cx}")
expect_same_rows(cx0_file.csv cx0_flag.csv "--cx 0 with --calibration")
expect_other_rows(from_xml.csv cx0_flag.csv "--cx 0 with --calibration")
run(0 ${CLI} predict plain/mav0/cam0/data --fx ${fx} --cx 0 -o cx0_alone.csv)
expect_no_match("--cx not given")
expect_other_rows(fx_alone.csv cx0_alone.csv "--fx --cx 0")
run(2 ${CLI} predict plain/mav0/cam0/data --cx 0)
expect_match("--cx and --cy need a focal length: give --fx \\(and --fy\\), or --calibration FILE")
# On a EuRoC sequence the principal point alone is not used, and says so.
run(0 ${CLI} predict plain --cx 0 -o plain_cx0.csv)
expect_match("note: --cx/--cy without --fx or --calibration are not used: EuRoC sequence plain[^\n]*'s cam0/sensor.yaml gives the camera")
expect_same_rows(plain.csv plain_cx0.csv "--cx alone on a EuRoC sequence")
run(2 ${CLI} predict plain/mav0/cam0/data)
expect_match("give --calibration FILE \\(EuRoC sensor.yaml, Kalibr camchain, OpenCV YAML/XML\\) or --fx")

# --- eval: the file's extrinsic, as --camchain gives it ---------------------------------------
set(imu --imu radtan/mav0/imu0/data.csv)
foreach(frame "" "--camera-frame")
  run(0 ${CLI} eval radtan.csv radtan --json ${frame})
  rmse_of(reference "${output}")
  foreach(calibration camchain-imucam.yaml radtan/mav0/cam0/sensor.yaml)
    run(0 ${CLI} eval from_kalibr.csv radtan/mav0/cam0/data ${imu} --calibration ${calibration} --json ${frame})
    rmse_of(with_file "${output}")
    if(NOT with_file STREQUAL reference)
      message(FATAL_ERROR "eval --calibration ${calibration} ${frame}: RMSE ${with_file}, the EuRoC path gives ${reference}")
    endif()
  endforeach()
endforeach()
run(0 ${CLI} eval from_kalibr.csv radtan/mav0/cam0/data ${imu} --calibration camchain-imucam.yaml)
expect_match("note: IMU to camera rotation from camchain-imucam.yaml \\(cam0\\)")
# An OpenCV file has no extrinsic: the camera frame is the IMU's (identity T_BS here).
run(0 ${CLI} eval plain.csv plain --json)
rmse_of(reference "${output}")
run(0 ${CLI} eval from_xml.csv plain/mav0/cam0/data --imu plain/mav0/imu0/data.csv --calibration opencv.xml --json)
rmse_of(with_file "${output}")
if(NOT with_file STREQUAL reference)
  message(FATAL_ERROR "eval --calibration opencv.xml: RMSE ${with_file}, the EuRoC path gives ${reference}")
endif()
run(2 ${CLI} eval from_kalibr.csv radtan/mav0/cam0/data ${imu} --calibration camchain-imucam.yaml
    --camchain camchain-imucam.yaml)
expect_match("--calibration camchain-imucam.yaml holds a camera-IMU extrinsic, and --camchain gives one too")

# A EuRoC sequence's rotation is its T_BS, in eval as in predict.
run(2 ${CLI} eval radtan.csv radtan --calibration camchain-imucam.yaml)
expect_match("camchain-imucam.yaml \\(cam0\\): radtan is a EuRoC sequence, whose camera rotation comes from mav0/cam0/sensor.yaml's T_BS")

# --- calibrate-time predicts with the file --------------------------------------------------
run(0 ${CLI} calibrate-time radtan/mav0/cam0/data ${imu} --calibration camchain-imucam.yaml --range 0.02)
expect_match("no rates file given: predicting 7 pairs")
expect_match("time_offset_s")
expect_match("apply it with: inertialnet eval RATES.csv radtan/mav0/cam0/data --imu radtan/mav0/imu0/data.csv --calibration camchain-imucam.yaml --time-offset")

# --- A video: the same file reads the same way (make_test_video: 188x120 frames at 20 Hz) ----------
if(MAKE_VIDEO)
  run(0 ${MAKE_VIDEO} .)
  file(WRITE "${WORK}/video.xml"
       "<?xml version=\"1.0\"?>\n<opencv_storage>\n<image_width>188</image_width>\n<image_height>120</image_height>\n"
       "<camera_matrix type_id=\"opencv-matrix\">\n  <rows>3</rows>\n  <cols>3</cols>\n  <dt>d</dt>\n"
       "  <data>150. 0. 0. 0. 150. 60. 0. 0. 1.</data></camera_matrix>\n"
       "<distortion_coefficients type_id=\"opencv-matrix\">\n  <rows>5</rows>\n  <cols>1</cols>\n  <dt>d</dt>\n"
       "  <data>0. 0. 0. 0. 0.</data></distortion_coefficients>\n</opencv_storage>\n")
  run(0 ${CLI} predict clip.avi --calibration video.xml --max-pairs 8 -o video_file.csv)
  run(0 ${CLI} predict clip.avi --fx 150 --fy 150 --cx 0 --cy 60 --max-pairs 8 -o video_flags.csv)
  expect_same_rows(video_file.csv video_flags.csv "a video with --calibration")
endif()

# --- Refused, naming file and key -----------------------------------------------------------
file(WRITE "${WORK}/bad_kalibr.yaml"
     "cam0:\n  camera_model: pinhole\n  intrinsics: [114.6, 114.3, 91.4]\n  resolution: [188, 120]\n")
run(2 ${CLI} predict plain/mav0/cam0/data --calibration bad_kalibr.yaml)
expect_match("inertialnet: error: bad_kalibr.yaml: cam0.intrinsics should be \\[fu, fv, pu, pv\\], found 3 numbers")
file(READ "${WORK}/opencv.xml" xml)
string(REPLACE "<image_width>188</image_width>" "<image_width>-5</image_width>" bad_xml "${xml}")
file(WRITE "${WORK}/bad.xml" "${bad_xml}")
run(2 ${CLI} predict plain/mav0/cam0/data --calibration bad.xml)
expect_match("inertialnet: error: bad.xml: image_width is -5; it should be a whole number of pixels")
opencv_yaml(bad_rational.yaml 188 120 ${fx} ${cx} 8 "${radtan_d}, 0., 0.02, 0., 0." "")
run(2 ${CLI} predict plain/mav0/cam0/data --calibration bad_rational.yaml)
expect_match("bad_rational.yaml: distortion_coefficients has 8 values with non-zero terms after k3")
opencv_yaml(bad_focal.yaml 188 120 -114.6 ${cx} 5 "${radtan_d}, 0." "")
run(2 ${CLI} predict plain/mav0/cam0/data --calibration bad_focal.yaml)
expect_match("bad_focal.yaml \\(camera_matrix, distortion_coefficients\\): camera focal lengths must be positive")
run(2 ${CLI} predict plain/mav0/cam0/data --calibration camchain.yaml --calibration-camera cam3)
expect_match("camchain.yaml has no camera cam3; its cameras: cam0, cam1")
run(2 ${CLI} predict plain/mav0/cam0/data --calibration opencv.xml --calibration-camera cam1)
expect_match("--calibration-camera cam1 picks a camera of a Kalibr camchain; opencv.xml is not one")
run(2 ${CLI} predict plain/mav0/cam0/data --calibration-camera cam1 --fx 100)
expect_match("--calibration-camera requires --calibration")
run(2 ${CLI} predict plain/mav0/cam0/data --calibration absent.yaml)
expect_match("--calibration: File does not exist: absent.yaml")
