# SPDX-License-Identifier: Apache-2.0
# ROS bags as sequences (predict, eval, calibrate-time): a synthetic EuRoC sequence converted into
# bags by an independent writer (tests/support/write_bag.py, PyPI rosbags) in every lossless image
# encoding must give the rates of the same frames as an image folder with the same intrinsics —
# the same pixels, so the same rates, compared row by row as text — and eval on a bag with its IMU
# topic the RMSE of the EuRoC folder. Then the bad cases: a missing topic or one of another type
# (exit 2 listing the bag's topics with their types), an empty bag, a Bayer image, an IMU that
# starts after the images (handled as the `--imu FILE` path handles the same samples).
#   cmake -DCLI=<inertialnet> -DPYTHON=<interpreter with rosbags> -DWORK=<scratch dir> -P ros_bags.cmake
include(${CMAKE_CURRENT_LIST_DIR}/run_helpers.cmake)
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")
set(write_bag ${PYTHON} ${CMAKE_CURRENT_LIST_DIR}/../support/write_bag.py seq)

run(0 ${CLI} synth seq --frames 12 --size 188x120 --seed 3)
intrinsics_flags(intrinsics seq/mav0/cam0/sensor.yaml)

run(0 ${CLI} predict seq/mav0/cam0/data ${intrinsics} -o folder.csv)
rates_lines_of(reference folder.csv)

# Every lossless encoding, through the three ROS 1 chunk compressions, with the intrinsics from
# the bag's CameraInfo; one with padded rows (step > width · bytes per pixel).
set(compressions none bz2 lz4)
set(k 0)
# (8UC1, 8UC3 and 16UC1, other names of mono8, bgr8 and mono16, are in test_ros1_bags.)
foreach(encoding mono8 mono16 mono16-be rgb8 bgr8 rgba8 bgra8 compressed-png)
  math(EXPR c "${k} % 3")
  list(GET compressions ${c} compression)
  math(EXPR k "${k} + 1")
  run(0 ${write_bag} ${encoding}.bag --encoding ${encoding} --compression ${compression} --camera-info)
  run(0 ${CLI} predict ${encoding}.bag -o ${encoding}.csv)
  expect_match("Camera calibration from /cam0/camera_info")
  expect_match("geometric rates in the camera frame")
  rates_lines_of(rows ${encoding}.csv)
  if(NOT rows STREQUAL reference)
    message(FATAL_ERROR "${encoding} (${compression} chunks): the bag's rates differ from the image folder's")
  endif()
endforeach()
run(0 ${write_bag} padded.bag --encoding rgb8 --row-padding 3 --camera-info)
run(0 ${CLI} predict padded.bag --image-topic /cam0/image_raw --camera-info-topic /cam0/camera_info -o padded.csv)
rates_lines_of(rows padded.csv)
if(NOT rows STREQUAL reference)
  message(FATAL_ERROR "rgb8 with padded rows: the bag's rates differ from the image folder's")
endif()
# Without CameraInfo the intrinsics are given as for a folder; the same rates again.
run(0 ${write_bag} bare.bag)
run(2 ${CLI} predict bare.bag)
expect_match("has no CameraInfo; give --calibration FILE")
run(0 ${CLI} predict bare.bag ${intrinsics} -o bare.csv)
rates_lines_of(rows bare.csv)
if(NOT rows STREQUAL reference)
  message(FATAL_ERROR "a bag without CameraInfo, with --fx …: the rates differ from the image folder's")
endif()
# (The ROS 2 storages, through the same frame source with CDR messages: ros2_bags.cmake.)

# eval: the bag with its IMU topic and the IMU-camera rotation of cam0/sensor.yaml (as for an
# image folder with --imu) gives the EuRoC folder's RMSE.
run(0 ${CLI} predict seq -o euroc.csv)
run_json(document ${CLI} eval euroc.csv seq --json)
rmse_of(reference_rmse "${document}")
run_json(document ${CLI} eval mono8.csv mono8.bag --imu-topic /imu0 --T-cam-imu seq/mav0/cam0/sensor.yaml --json)
rmse_of(bag_rmse "${document}")
expect_same_rmse("${reference_rmse}" "${bag_rmse}" "eval on a ROS 1 bag")
run(0 ${CLI} eval mono8.csv mono8.bag --T-cam-imu seq/mav0/cam0/sensor.yaml)
expect_match("The sensor_msgs/Imu topic /imu0 of the bag is read")
# calibrate-time predicts from the bag itself (CameraInfo) and finds the offset the EuRoC path finds.
run(0 ${CLI} calibrate-time seq)
string(REGEX MATCH "[^\n]*offset[^\n]*" euroc_offset "${output}")
run(0 ${CLI} calibrate-time mono8.bag --T-cam-imu seq/mav0/cam0/sensor.yaml)
string(REGEX MATCH "[^\n]*offset[^\n]*" bag_offset "${output}")
if(NOT euroc_offset OR NOT euroc_offset STREQUAL bag_offset)
  message(FATAL_ERROR "calibrate-time on the bag: '${bag_offset}', on the EuRoC folder: '${euroc_offset}'")
endif()
# The command it suggests names the topics given.
run(0 ${CLI} calibrate-time mono8.bag --image-topic /cam0/image_raw --imu-topic /imu0 --T-cam-imu seq/mav0/cam0/sensor.yaml)
expect_match("apply it with: inertialnet eval RATES.csv mono8.bag [^\n]*--image-topic /cam0/image_raw --imu-topic /imu0")

# An IMU that starts after the images (at the third frame): the bag and the `--imu FILE` path
# with the same samples give the same RMSE.
run(0 ${write_bag} late.bag --imu-late --imu-csv late_imu.csv --camera-info)
run_json(document ${CLI} eval mono8.csv late.bag --T-cam-imu seq/mav0/cam0/sensor.yaml --json)
rmse_of(late_bag "${document}")
run_json(document ${CLI} eval folder.csv seq/mav0/cam0/data --imu late_imu.csv --T-cam-imu seq/mav0/cam0/sensor.yaml --json)
rmse_of(late_file "${document}")
expect_same_rmse("${late_file}" "${late_bag}" "eval on a bag whose IMU starts after the images")

# Topics missing, of another type, or not chosen: exit 2, the bag's topics listed with their types.
set(listed "/cam0/image_raw \\(sensor_msgs/Image, 12 messages\\)" "/imu0 \\(sensor_msgs/Imu, [0-9]+ messages\\)"
           "/cam0/camera_info \\(sensor_msgs/CameraInfo, 12 messages\\)")
run(2 ${CLI} predict mono8.bag --image-topic /cam1/image_raw)
expect_match("has no topic /cam1/image_raw \\(--image-topic\\)")
foreach(topic ${listed})
  expect_match("${topic}")
endforeach()
run(2 ${CLI} predict mono8.bag --image-topic /imu0)
expect_match("--image-topic /imu0 is a topic of sensor_msgs/Imu")
run(2 ${CLI} eval mono8.csv mono8.bag --imu-topic /imu1)
expect_match("has no topic /imu1 \\(--imu-topic\\)")
expect_match("/imu0 \\(sensor_msgs/Imu")
run(2 ${CLI} predict mono8.bag --camera-info-topic /cam0/image_raw)
expect_match("--camera-info-topic /cam0/image_raw is a topic of sensor_msgs/Image")
run(2 ${CLI} predict seq --image-topic /cam0/image_raw)
expect_match("--image-topic names a topic of a ROS bag")
run(2 ${CLI} predict mono8.bag --rate 20)
expect_match("--rate is for image folders and videos")

# An empty bag (topics declared, no message) and one whose images are a Bayer pattern.
run(0 ${write_bag} empty.bag --empty --camera-info)
run(2 ${CLI} predict empty.bag)
expect_match("fewer than two frames")
run(2 ${CLI} eval mono8.csv empty.bag)
expect_match("empty.bag")
run(0 ${write_bag} bayer.bag --encoding bayer_rggb8 --camera-info)
run(2 ${CLI} predict bayer.bag)
expect_match("'bayer_rggb8' \\(a raw Bayer pattern")
expect_match("mono8, mono16, rgb8, bgr8, rgba8")

# train on a bag learns what it learns from the same sequence as a EuRoC folder: the same losses and
# RMSEs every epoch (the folder's copy without ground truth, since a bag has none: both then
# correct no bias). The log's last column, seconds, is left out.
file(COPY "${WORK}/seq/" DESTINATION "${WORK}/no_ground_truth")
file(REMOVE_RECURSE "${WORK}/no_ground_truth/mav0/state_groundtruth_estimate0")
set(train_options --epochs 2 --head-size 64x48 --no-flow-cache)
run(0 ${CLI} train --train mono8.bag --val mono8.bag --T-cam-imu seq/mav0/cam0/sensor.yaml ${train_options}
    -o bag_head.safetensors --log bag_train.csv)
run(0 ${CLI} train --train no_ground_truth --val no_ground_truth ${train_options} -o euroc_head.safetensors --log euroc_train.csv)
foreach(which bag euroc)
  file(STRINGS "${WORK}/${which}_train.csv" lines)
  set(${which}_log "")
  foreach(line ${lines})
    string(REGEX REPLACE ",[^,]*$" "" line "${line}")
    list(APPEND ${which}_log "${line}")
  endforeach()
endforeach()
if(NOT bag_log STREQUAL euroc_log)
  message(FATAL_ERROR "train on the bag logged\n${bag_log}\nand on the EuRoC folder\n${euroc_log}")
endif()
run(2 ${CLI} train --train seq --val seq --image-topic /cam0/image_raw ${train_options} -o refused.safetensors)
expect_match("are for ROS bags; seq is a EuRoC sequence")
