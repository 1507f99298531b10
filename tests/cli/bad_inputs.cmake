# Bad inputs through the CLI: each case asserts the exit code (2 bad input, 1 runtime failure)
# and a fragment of the one-line message. Cases edit a copy of a small synthetic sequence.
#   cmake -DCLI=<inertialnet> -DWORK=<scratch dir> -P bad_inputs.cmake
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")

# run(<expected exit code> <command>...): sets `output` to stdout + stderr.
function(run expect_code)
  execute_process(COMMAND ${ARGN} WORKING_DIRECTORY "${WORK}" RESULT_VARIABLE code OUTPUT_VARIABLE out
                  ERROR_VARIABLE err TIMEOUT 300)
  message("$ ${ARGN}\n${out}${err}(exit ${code})")
  if(NOT "${code}" STREQUAL "${expect_code}")
    message(FATAL_ERROR "expected exit code ${expect_code}, got ${code}")
  endif()
  set(output "${out}${err}" PARENT_SCOPE)
endfunction()

function(expect_match regex)
  if(NOT output MATCHES "${regex}")
    message(FATAL_ERROR "output does not match '${regex}'")
  endif()
endfunction()

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
