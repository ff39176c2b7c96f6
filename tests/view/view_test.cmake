# SPDX-License-Identifier: MIT
# View.PlaywrightPlaysTheAnimation: writes a short run's page with PRODUCER into FOLDER, then
# checks it with SCRIPT (view_test.mjs) under NODE and CHROMIUM. Any missing piece fails.
foreach(tool NODE CHROMIUM)
  if(NOT ${tool} OR NOT EXISTS "${${tool}}")
    message(FATAL_ERROR "View test: ${tool} not found ('${${tool}}'); install Debian's nodejs "
                        "and chromium (.ci/deps)")
  endif()
endforeach()
file(REMOVE_RECURSE "${FOLDER}")
execute_process(COMMAND "${PRODUCER}" "${FOLDER}" RESULT_VARIABLE result)
if(NOT result EQUAL 0)
  message(FATAL_ERROR "View test: ${PRODUCER} failed (${result})")
endif()
execute_process(COMMAND "${NODE}" "${SCRIPT}" "${FOLDER}" "${CHROMIUM}" RESULT_VARIABLE result)
if(NOT result EQUAL 0)
  message(FATAL_ERROR "View test: ${SCRIPT} failed (${result})")
endif()
