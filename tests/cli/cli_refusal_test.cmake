# SPDX-License-Identifier: MIT
# Runs a demo binary with a bad command line and checks that it is refused before anything runs:
# exit code 2, a message on stderr matching EXPECT (a regular expression), and no run or
# calibration started. Used by the ctest cases in demos/CMakeLists.txt:
#   cmake -DDEMO=<binary> -DARGS=<arguments separated by |> -DEXPECT=<regex>
#         [-DFIFO=<path of a FIFO to create first>] [-DABSENT=<path>] -P cli_refusal_test.cmake
# ABSENT: removed first, and must not exist afterwards (an output folder not even created).
# "|" separates the arguments so that an empty argument (--out "") survives: "--out|".
if(FIFO)
  file(REMOVE "${FIFO}")
  execute_process(COMMAND mkfifo "${FIFO}" RESULT_VARIABLE made)
  if(NOT made EQUAL 0)
    message(FATAL_ERROR "could not create the FIFO ${FIFO}")
  endif()
endif()
if(ABSENT)
  file(REMOVE_RECURSE "${ABSENT}")
endif()
# Each argument quoted on its own: an unquoted list expansion would drop an empty argument.
string(REPLACE "|" ";" arguments "${ARGS}")
set(quoted "")
foreach(argument IN LISTS arguments)
  string(APPEND quoted " [==[${argument}]==]")
endforeach()
# The timeout turns a hang (a FIFO read forever) into a failure instead of a stuck test.
cmake_language(EVAL CODE "execute_process(COMMAND [==[${DEMO}]==]${quoted}
  RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 60)")
if(FIFO)
  file(REMOVE "${FIFO}")
endif()
if(NOT code STREQUAL "2")
  message(FATAL_ERROR "exit code ${code}, expected 2\nstdout:\n${out}\nstderr:\n${err}")
endif()
if(NOT err MATCHES "${EXPECT}")
  message(FATAL_ERROR "stderr does not match \"${EXPECT}\":\n${err}")
endif()
if(err MATCHES "calibrating|runs at h =" OR out MATCHES "outputs in")
  message(FATAL_ERROR "a run started before the refusal:\nstdout:\n${out}\nstderr:\n${err}")
endif()
if(ABSENT AND EXISTS "${ABSENT}")
  message(FATAL_ERROR "${ABSENT} was created before the refusal\nstdout:\n${out}\nstderr:\n${err}")
endif()
message(STATUS "refused as expected: ${err}")
