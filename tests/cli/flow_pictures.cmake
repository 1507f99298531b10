# SPDX-License-Identifier: Apache-2.0
# Flow without weights and flow pictures: `flow --flow dis`, `predict --save-flow --flow-format`,
# and `viz` on .flo and KITTI files (colours are checked pixel by pixel in python/tests).
#   cmake -DCLI=<inertialnet> -DWORK=<scratch dir> -P flow_pictures.cmake
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")

include(${CMAKE_CURRENT_LIST_DIR}/run_helpers.cmake)

function(expect_file path)
  if(NOT EXISTS "${WORK}/${path}")
    message(FATAL_ERROR "${path} was not written")
  endif()
endfunction()

run(0 ${CLI} synth seq --frames 3 --size 96x64 --seed 3)
file(GLOB frames "${WORK}/seq/mav0/cam0/data/*.png")
list(SORT frames)
list(GET frames 0 first)
list(GET frames 1 second)

# 1. flow without weights is DIS; every output format.
run(0 ${CLI} flow ${first} ${second} -o dis.flo --png dis.png --kitti dis_kitti.png)
expect_match("DIS")
expect_file(dis.flo)
expect_file(dis.png)
expect_file(dis_kitti.png)
run(0 ${CLI} flow ${first} ${second} --flow dis)
expect_match("no output file")
run(2 ${CLI} flow ${first} ${second} --flow flownet2)
expect_match("needs --weights")
run(2 ${CLI} flow ${first} ${second} --flow dis --model FlowNet2-C)
expect_match("takes no --weights")

# 2. predict --save-flow in each format, named by the pair's second frame.
foreach(format flo png kitti)
  run(0 ${CLI} predict seq -o rates_${format}.csv --save-flow flows_${format} --flow-format ${format})
  file(GLOB saved "${WORK}/flows_${format}/*")
  list(LENGTH saved count)
  if(NOT count EQUAL 2)
    message(FATAL_ERROR "--flow-format ${format}: ${count} files instead of 2")
  endif()
endforeach()
run(2 ${CLI} predict seq --save-flow flows_x --flow-format jpeg)
expect_match("flow-format")
run(2 ${CLI} predict seq --flow-format png)  # not silently ignored without --save-flow
expect_match("--flow-format requires --save-flow")

# 3. viz: .flo and KITTI inputs, beside the inputs or into a new folder, scales and legend.
file(GLOB kitti RELATIVE "${WORK}" "${WORK}/flows_kitti/*.png")
run(0 ${CLI} viz dis.flo ${kitti} -o pictures --legend --shared-scale)
expect_match("dis.flo -> pictures/dis_color.png")
expect_file(pictures/dis_color.png)
run(0 ${CLI} viz dis_kitti.png --max-magnitude 2)
expect_match("scale 2 px")
expect_file(dis_kitti_color.png)
run(2 ${CLI} viz seq/mav0/cam0/sensor.yaml)
expect_match("neither a Middlebury .flo file")
run(2 ${CLI} viz ${first})
expect_match("not a KITTI flow PNG")
run(2 ${CLI} viz dis.flo --max-magnitude 2 --shared-scale)

# 4. Two outputs that are one file, or an output that is an input, are refused before any work
#    (issue 20, item 9): exit 2, both named, nothing overwritten.
file(MAKE_DIRECTORY "${WORK}/other")
file(COPY_FILE "${WORK}/dis.flo" "${WORK}/other/dis.flo")
file(SHA256 "${WORK}/pictures/dis_color.png" before)
run(2 ${CLI} viz dis.flo other/dis.flo -o pictures)
expect_match("the picture of dis.flo and the picture of other/dis.flo name one file")
file(SHA256 "${WORK}/pictures/dis_color.png" after)
if(NOT before STREQUAL after)
  message(FATAL_ERROR "viz rewrote pictures/dis_color.png although it refused")
endif()
file(COPY_FILE "${WORK}/dis_kitti.png" "${WORK}/other/dis.png")
run(2 ${CLI} viz other/dis.flo other/dis.png)  # .flo and KITTI .png of one stem
expect_match("name one file \\(other/dis_color.png\\)")
file(COPY_FILE "${WORK}/dis_kitti.png" "${WORK}/other/dis_color.png")
run(2 ${CLI} viz other/dis.flo ./other/../other/dis_color.png)  # an input that is an output
expect_match("the picture of other/dis.flo \\(other/dis_color.png\\) would overwrite the input ./other/../other/dis_color.png")
run(2 ${CLI} flow ${first} ${second} -o same.png --png ./same.png)
expect_match("-o and --png name one file")
file(CREATE_LINK "${WORK}/dis.png" "${WORK}/link.png" SYMBOLIC)
run(2 ${CLI} flow ${first} ${second} --png dis.png --kitti link.png)
expect_match("--png and --kitti name one file \\(dis.png and link.png\\)")
run(2 ${CLI} flow ${first} ${second} --kitti ${second})
expect_match("--kitti \\(.*\\) would overwrite the input")
