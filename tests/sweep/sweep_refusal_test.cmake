# SPDX-License-Identifier: MIT
# A bad sweep spec is refused before any job starts: exit code 2, a message on stderr matching
# EXPECT (it names the spec's entry), and the sweep folder OUT not even created.
#   cmake -DRHEOFEED=<binary> -DSPEC=<spec file> -DOUT=<folder> -DEXPECT=<regex>
#         -P sweep_refusal_test.cmake
file(REMOVE_RECURSE "${OUT}")
execute_process(COMMAND "${RHEOFEED}" sweep "${SPEC}" --out "${OUT}" RESULT_VARIABLE code
                OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 120)
set(report "stdout:\n${out}\nstderr:\n${err}")
if(NOT code STREQUAL "2")
  message(FATAL_ERROR "exit code ${code}, expected 2\n${report}")
endif()
if(NOT err MATCHES "${EXPECT}")
  message(FATAL_ERROR "stderr does not match \"${EXPECT}\"\n${report}")
endif()
if(EXISTS "${OUT}")
  message(FATAL_ERROR "the sweep folder ${OUT} was created before the refusal\n${report}")
endif()
message(STATUS "refused as expected: ${err}")
