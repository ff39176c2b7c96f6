# SPDX-License-Identifier: MIT
# Runs one `rheofeed` command line and checks what it did. Used by the ctest cases "Cli.*" of
# demos/cli/CMakeLists.txt:
#   cmake -DCMD=<program|arg|arg...> [-DCODE=<exit code, default 0>] [-DOUT_MATCH=<regex>]
#         [-DERR_MATCH=<regex>] [-DERR_NOT_MATCH=<regex>] [-DLAST_LINE=<regex>]
#         [-DFILES=<file|file...>] [-DMAKE_DIRS=<dir|dir...>] [-DCOPY_TO=<path>]
#         [-DSCENE_FROM=<scene file> -DSCENE_TO=<path> [-DSCENE_DRIFT_TABLE=<name>]] -P cli_test.cmake
# "|" separates the arguments. LAST_LINE must match the last non-empty line of stdout; every
# file of FILES must exist afterwards (and be removed before). COPY_TO: the program is first
# copied there (a binary moved away from its share/ folder) and that copy is run. SCENE_FROM and
# SCENE_TO: the scene file is first written to SCENE_TO with its top-level "drift_table" set to
# SCENE_DRIFT_TABLE, or removed when that is empty or not given.
string(REPLACE "|" ";" command "${CMD}")
if(COPY_TO)
  list(GET command 0 program)
  get_filename_component(folder "${COPY_TO}" DIRECTORY)
  file(REMOVE_RECURSE "${folder}")
  file(MAKE_DIRECTORY "${folder}")
  file(COPY_FILE "${program}" "${COPY_TO}")
  list(REMOVE_AT command 0)
  list(INSERT command 0 "${COPY_TO}")
endif()
string(REPLACE "|" ";" files "${FILES}")
foreach(f IN LISTS files)
  file(REMOVE "${f}")
endforeach()
# MAKE_DIRS: folders the command needs to exist (a test must not depend on another test, or on
# the order ctest runs them in, to have made them).
string(REPLACE "|" ";" make_dirs "${MAKE_DIRS}")
foreach(d IN LISTS make_dirs)
  file(MAKE_DIRECTORY "${d}")
endforeach()
if(SCENE_FROM)
  file(READ "${SCENE_FROM}" scene)
  if(NOT scene MATCHES "\n  \"drift_table\": \"[^\"]*\",")
    message(FATAL_ERROR "${SCENE_FROM} has no top-level \"drift_table\" member to replace")
  endif()
  if(SCENE_DRIFT_TABLE)
    string(REGEX REPLACE "\n  \"drift_table\": \"[^\"]*\","
           "\n  \"drift_table\": \"${SCENE_DRIFT_TABLE}\"," scene "${scene}")
  else()
    string(REGEX REPLACE "\n  \"drift_table\": \"[^\"]*\"," "" scene "${scene}")
  endif()
  get_filename_component(folder "${SCENE_TO}" DIRECTORY)
  file(MAKE_DIRECTORY "${folder}")
  file(WRITE "${SCENE_TO}" "${scene}")
endif()
set(quoted "")
foreach(argument IN LISTS command)
  string(APPEND quoted " [==[${argument}]==]")
endforeach()
cmake_language(EVAL CODE "execute_process(COMMAND ${quoted}
  RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 600)")
if(NOT DEFINED CODE)
  set(CODE 0)
endif()
set(report "command: ${CMD}\nstdout:\n${out}\nstderr:\n${err}")
if(NOT code STREQUAL "${CODE}")
  message(FATAL_ERROR "exit code ${code}, expected ${CODE}\n${report}")
endif()
if(DEFINED OUT_MATCH AND NOT out MATCHES "${OUT_MATCH}")
  message(FATAL_ERROR "stdout does not match \"${OUT_MATCH}\"\n${report}")
endif()
if(DEFINED ERR_MATCH AND NOT err MATCHES "${ERR_MATCH}")
  message(FATAL_ERROR "stderr does not match \"${ERR_MATCH}\"\n${report}")
endif()
if(DEFINED ERR_NOT_MATCH AND err MATCHES "${ERR_NOT_MATCH}")
  message(FATAL_ERROR "stderr matches \"${ERR_NOT_MATCH}\"\n${report}")
endif()
if(DEFINED LAST_LINE)
  string(STRIP "${out}" stripped)
  string(REGEX REPLACE "^.*\n" "" last "${stripped}")
  if(NOT last MATCHES "${LAST_LINE}")
    message(FATAL_ERROR "the last line \"${last}\" does not match \"${LAST_LINE}\"\n${report}")
  endif()
endif()
foreach(f IN LISTS files)
  if(NOT EXISTS "${f}")
    message(FATAL_ERROR "${f} was not written\n${report}")
  endif()
endforeach()
message(STATUS "${report}")
