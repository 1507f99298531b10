# SPDX-License-Identifier: Apache-2.0
# Writes the shell completions and the man page that `inertialnet` generates from its own option
# definitions into a share/ tree (run by the build; `cmake --install` copies them).
#   cmake -DCLI=<inertialnet> -DOUT=<share dir> -P generate_docs.cmake
foreach(job "bash-completion/completions/inertialnet;completion;bash"
            "zsh/site-functions/_inertialnet;completion;zsh"
            "man/man1/inertialnet.1;man")
  list(POP_FRONT job file)
  get_filename_component(folder "${OUT}/${file}" DIRECTORY)
  file(MAKE_DIRECTORY "${folder}")
  execute_process(COMMAND ${CLI} ${job} OUTPUT_FILE "${OUT}/${file}" RESULT_VARIABLE code)
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "inertialnet ${job} failed (${code})")
  endif()
endforeach()
