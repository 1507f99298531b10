# SPDX-License-Identifier: Apache-2.0
# ROS 2 bags in every form a user has them (predict, eval): the .db3 file of a rosbag2 sqlite3
# bag, its folder (metadata.yaml), the .mcap file of an MCAP bag and its folder, and MCAP with zstd
# and lz4 chunks. A synthetic EuRoC sequence is written into the bags by independent writers
# (tests/support/write_bag.py with PyPI rosbags; recompress_mcap.py with PyPI mcap for the chunk
# compressions) and each bag must give the rates of the same frames as an image folder (compared
# row by row as text) and, with its IMU topic, the EuRoC folder's RMSE. Then damaged and
# unsupported bags: exit 2 naming the file or folder. (ros_bags.cmake does the same for ROS 1
# bags and checks the topic options and messages, which are the same for every container.)
#   cmake -DCLI=<inertialnet> -DPYTHON=<interpreter with rosbags and mcap> -DWORK=<scratch dir> -P ros2_bags.cmake
include(${CMAKE_CURRENT_LIST_DIR}/run_helpers.cmake)
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")
set(write_bag ${PYTHON} ${CMAKE_CURRENT_LIST_DIR}/../support/write_bag.py seq)
set(recompress ${PYTHON} ${CMAKE_CURRENT_LIST_DIR}/recompress_mcap.py)

run(0 ${CLI} synth seq --frames 12 --size 188x120 --seed 3)
intrinsics_flags(intrinsics seq/mav0/cam0/sensor.yaml)


run(0 ${CLI} predict seq/mav0/cam0/data ${intrinsics} -o folder.csv)
rates_lines_of(reference folder.csv)
run(0 ${CLI} predict seq -o euroc.csv)
run_json(document ${CLI} eval euroc.csv seq --json)
rmse_of(reference_rmse "${document}")

# The bags: rosbag2 folders from rosbags (sqlite3; MCAP uncompressed), and the MCAP file rewritten
# with zstd and with lz4 chunks (CRCs included) by PyPI mcap.
run(0 ${write_bag} sqlite3_bag --storage sqlite3 --encoding mono8 --camera-info)
run(0 ${write_bag} mcap_bag --storage mcap --encoding mono8 --camera-info)
file(GLOB db3 RELATIVE "${WORK}" "${WORK}/sqlite3_bag/*.db3")
file(GLOB mcap RELATIVE "${WORK}" "${WORK}/mcap_bag/*.mcap")
if(NOT db3 OR NOT mcap)
  message(FATAL_ERROR "write_bag.py wrote no storage file: '${db3}', '${mcap}'")
endif()
run(0 ${recompress} ${mcap} zstd.mcap --compression zstd)
run(0 ${recompress} ${mcap} lz4.mcap --compression lz4)

set(k 0)
foreach(bag ${db3} sqlite3_bag ${mcap} mcap_bag zstd.mcap lz4.mcap)
  math(EXPR k "${k} + 1")
  run(0 ${CLI} predict ${bag} -o bag${k}.csv)
  expect_match("Camera calibration from /cam0/camera_info")
  rates_lines_of(rows bag${k}.csv)
  if(NOT rows STREQUAL reference)
    message(FATAL_ERROR "the ROS 2 bag ${bag}: the rates differ from the image folder's")
  endif()
  run_json(document ${CLI} eval bag${k}.csv ${bag} --imu-topic /imu0 --T-cam-imu seq/mav0/cam0/sensor.yaml --json)
  rmse_of(bag_rmse "${document}")
  expect_same_rmse("${reference_rmse}" "${bag_rmse}" "eval on the ROS 2 bag ${bag}")
endforeach()

# Damaged or unsupported: an MCAP file cut in half (a chunk overruns the end), an SQLite database
# without rosbag2's messages table, a folder whose metadata.yaml names two files (a split bag), a
# folder compressed by rosbag2 itself.
# (Python's statements on separate lines: a ';' would split run()'s argument list.)
set(cut_in_half "import sys\nd = open(sys.argv[1], 'rb').read()\nopen(sys.argv[2], 'wb').write(d[:len(d) // 2])")
run(0 ${PYTHON} -c "${cut_in_half}" lz4.mcap cut.mcap)
run(2 ${CLI} predict cut.mcap)
expect_match("inertialnet: error: The MCAP file \"cut.mcap\" is damaged: the Chunk record at byte [0-9]+ is [0-9]+ bytes long")
run(2 ${CLI} eval euroc.csv cut.mcap --T-cam-imu seq/mav0/cam0/sensor.yaml)
expect_match("The MCAP file \"cut.mcap\" is damaged: ")
set(drop_messages "import sqlite3, shutil, sys\nshutil.copy(sys.argv[1], sys.argv[2])\nsqlite3.connect(sys.argv[2]).execute('DROP TABLE messages')")
run(0 ${PYTHON} -c "${drop_messages}" ${db3} no_messages.db3)
run(2 ${CLI} predict no_messages.db3)
expect_match("The SQLite database \"no_messages.db3\" is not a ROS 2 bag: it lacks rosbag2's \"topics\" and \"messages\" tables")
file(COPY "${WORK}/sqlite3_bag/" DESTINATION "${WORK}/split_bag")
file(READ "${WORK}/split_bag/metadata.yaml" metadata)
get_filename_component(db3_name "${db3}" NAME)
string(REPLACE "- ${db3_name}\n" "- ${db3_name}\n  - second_0.db3\n" split_metadata "${metadata}")
file(WRITE "${WORK}/split_bag/metadata.yaml" "${split_metadata}")
run(2 ${CLI} predict split_bag)
expect_match("split_bag\" \\(its metadata.yaml\\) names 2 storage files")
file(COPY "${WORK}/sqlite3_bag/" DESTINATION "${WORK}/compressed_bag")
string(REPLACE "compression_mode: ''" "compression_mode: FILE" compressed_metadata "${metadata}")
file(WRITE "${WORK}/compressed_bag/metadata.yaml" "${compressed_metadata}")
run(2 ${CLI} predict compressed_bag)
expect_match("is compressed by rosbag2 \\(compression_mode FILE\\)")
