# SPDX-License-Identifier: Apache-2.0
# cmake/SourceIdentity.cmake (BuildVersions::source, a batch's provenance): the identity follows
# the sources' relative paths and contents and nothing else — not their order in the list, their
# time stamps, or where the tree lies.
#   cmake -DSCRIPT=<cmake/SourceIdentity.cmake> -DWORK=<scratch dir> -P source_identity.cmake
file(REMOVE_RECURSE "${WORK}")

# identity(<var> <root> <file>...): runs the script on <root> with the files listed in that order.
function(identity var root)
  set(list "")
  foreach(name IN LISTS ARGN)
    string(APPEND list "${root}/${name}\n")
  endforeach()
  file(WRITE "${WORK}/list.txt" "${list}")
  execute_process(COMMAND ${CMAKE_COMMAND} -DROOT=${root} -DOUTPUT=${WORK}/identity.cpp -DLIST=${WORK}/list.txt
                  -P "${SCRIPT}" RESULT_VARIABLE code ERROR_VARIABLE err)
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "the script failed (${code}): ${err}")
  endif()
  file(READ "${WORK}/identity.cpp" text)
  if(NOT text MATCHES "source_identity\\(\\) { return \"([0-9a-f]+)\"; }")
    message(FATAL_ERROR "no identity in the generated source:\n${text}")
  endif()
  string(LENGTH "${CMAKE_MATCH_1}" length)
  if(NOT length EQUAL 64)
    message(FATAL_ERROR "the identity '${CMAKE_MATCH_1}' is not 64 hex digits")
  endif()
  set(${var} "${CMAKE_MATCH_1}" PARENT_SCOPE)
endfunction()
function(expect_same a b what)
  if(NOT "${a}" STREQUAL "${b}")
    message(FATAL_ERROR "${what} changed the identity: ${a} -> ${b}")
  endif()
endfunction()
function(expect_other a b what)
  if("${a}" STREQUAL "${b}")
    message(FATAL_ERROR "${what} left the identity at ${a}")
  endif()
endfunction()

set(A "${WORK}/tree a")  # a space in the path, as in a user's checkout
file(WRITE "${A}/src/layer/op.cpp" "int op() { return 1; }\n")
file(WRITE "${A}/include/op.hpp" "int op();\n")
file(WRITE "${A}/kernels_cl/op.cl" "__kernel void op() {}\n")
set(files src/layer/op.cpp include/op.hpp kernels_cl/op.cl)
identity(first "${A}" ${files})

identity(again "${A}" ${files})
expect_same("${first}" "${again}" "running it again")
file(TIMESTAMP "${WORK}/identity.cpp" written "%s")
execute_process(COMMAND ${CMAKE_COMMAND} -E sleep 1.1)
identity(again "${A}" ${files})
file(TIMESTAMP "${WORK}/identity.cpp" rewritten "%s")
expect_same("${written}" "${rewritten}" "an unchanged identity (the generated file's time stamp)")

identity(reordered "${A}" kernels_cl/op.cl src/layer/op.cpp include/op.hpp)
expect_same("${first}" "${reordered}" "listing the files in another order")

file(TOUCH "${A}/src/layer/op.cpp")
identity(touched "${A}" ${files})
expect_same("${first}" "${touched}" "touching a file without changing it")

file(COPY "${A}/" DESTINATION "${WORK}/elsewhere/b")
identity(moved "${WORK}/elsewhere/b" ${files})
expect_same("${first}" "${moved}" "the same tree in another folder")

file(WRITE "${A}/src/layer/op.cpp" "int op() { return 2; }\n")
identity(edited "${A}" ${files})
expect_other("${first}" "${edited}" "editing a source")
file(WRITE "${A}/src/layer/op.cpp" "int op() { return 1; }\n")
identity(restored "${A}" ${files})
expect_same("${first}" "${restored}" "restoring the edited source")

file(RENAME "${A}/kernels_cl/op.cl" "${A}/kernels_cl/other.cl")
identity(renamed "${A}" src/layer/op.cpp include/op.hpp kernels_cl/other.cl)
expect_other("${first}" "${renamed}" "renaming a source (same contents)")

file(WRITE "${A}/src/layer/new.cpp" "\n")
identity(added "${A}" src/layer/op.cpp include/op.hpp kernels_cl/other.cl src/layer/new.cpp)
expect_other("${renamed}" "${added}" "adding a source")
message("source identity: ${first}; the same after a rerun, reordering, touching and moving; other after editing, renaming and adding")
