# SPDX-License-Identifier: Apache-2.0
# Every source file of the repository states its licence in an SPDX line near its top (REUSE's
# convention): C++, OpenCL, Python, shell and CMake files under the folders below. Data, corpora
# and documents are not sources and are left out.
#   cmake -DROOT=<source dir> -P licence_headers.cmake
set(missing "")
set(count 0)
foreach(folder src include kernels_cl tools tests python bench examples cmake .ci)
  file(GLOB_RECURSE files LIST_DIRECTORIES false
       "${ROOT}/${folder}/*.cpp" "${ROOT}/${folder}/*.hpp" "${ROOT}/${folder}/*.h" "${ROOT}/${folder}/*.cl"
       "${ROOT}/${folder}/*.py" "${ROOT}/${folder}/*.pyi" "${ROOT}/${folder}/*.sh" "${ROOT}/${folder}/*.cmake"
       "${ROOT}/${folder}/*.cmake.in" "${ROOT}/${folder}/CMakeLists.txt" "${ROOT}/${folder}/run")
  foreach(file IN LISTS files)
    if(file MATCHES "/tests/(data|fuzz/corpus|fuzz/regressions)/" OR file MATCHES "/__pycache__/")
      continue()
    endif()
    file(READ "${file}" head LIMIT 400)
    math(EXPR count "${count} + 1")
    if(NOT head MATCHES "SPDX-License-Identifier: Apache-2.0")
      string(APPEND missing "\n  ${file}")
    endif()
  endforeach()
endforeach()
file(READ "${ROOT}/CMakeLists.txt" head LIMIT 400)
if(NOT head MATCHES "SPDX-License-Identifier: Apache-2.0")
  string(APPEND missing "\n  ${ROOT}/CMakeLists.txt")
endif()
if(missing)
  message(FATAL_ERROR "no 'SPDX-License-Identifier: Apache-2.0' line in the first 400 characters of:${missing}")
endif()
if(count LESS 300)
  message(FATAL_ERROR "only ${count} source files found under ${ROOT}: the globs no longer match the tree")
endif()
message(STATUS "${count} source files state their licence")
