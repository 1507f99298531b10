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
run(2 ${CLI} predict mixed --fx 50)
expect_match("frame 2 \\(t = 100000000 ns\\) is 64x48 but frame 1 \\(t = 50000000 ns\\) is 96x64; every frame")

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
