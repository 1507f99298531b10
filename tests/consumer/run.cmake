# SPDX-License-Identifier: Apache-2.0
# Installs the build tree into a scratch prefix, then configures, builds and runs the consumer.
file(REMOVE_RECURSE "${WORK_DIR}")
execute_process(COMMAND ${CMAKE_COMMAND} --install "${BUILD_DIR}" --prefix "${WORK_DIR}/prefix"
                RESULT_VARIABLE code)
if(code)
  message(FATAL_ERROR "cmake --install failed (${code})")
endif()
if(NOT EXISTS "${WORK_DIR}/prefix/share/doc/inertialnet/LICENSE")
  message(FATAL_ERROR "the install has no share/doc/inertialnet/LICENSE")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -S "${SOURCE_DIR}/tests/consumer" -B "${WORK_DIR}/build"
                        "-DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix" -DCMAKE_BUILD_TYPE=Release
                RESULT_VARIABLE code)
if(code)
  message(FATAL_ERROR "configuring the consumer failed (${code})")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build "${WORK_DIR}/build" RESULT_VARIABLE code)
if(code)
  message(FATAL_ERROR "building the consumer failed (${code})")
endif()
execute_process(COMMAND "${WORK_DIR}/build/consumer" RESULT_VARIABLE code OUTPUT_VARIABLE out)
message("${out}")
if(code)
  message(FATAL_ERROR "the consumer failed (${code})")
endif()
