# SPDX-License-Identifier: MIT
# Plugin.StockOde.PatchedOdeWithTheConeOffIsBitIdentical: runs ode_trajectories linked against
# the patched ODE (-DPATCHED=...) and against Debian's stock libode (-DSTOCK=...) and requires the
# trajectories (every line after the first) to be equal byte for byte. The first lines must show
# that the two programs really ran different libraries (only the patched one has the cone).
foreach(var PATCHED STOCK WORK_DIR)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "compare_trajectories.cmake: -D${var}=... is required")
  endif()
endforeach()
file(MAKE_DIRECTORY "${WORK_DIR}")
foreach(kind PATCHED STOCK)
  execute_process(COMMAND "${${kind}}" RESULT_VARIABLE rc OUTPUT_FILE "${WORK_DIR}/${kind}.txt"
                  ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${${kind}} failed (${rc}):\n${err}")
  endif()
  file(STRINGS "${WORK_DIR}/${kind}.txt" lines)
  list(LENGTH lines n_${kind})
  list(GET lines 0 config_${kind})
  list(REMOVE_AT lines 0)
  list(JOIN lines "\n" body_${kind})
endforeach()
if(NOT config_PATCHED MATCHES " ODE_EXT_friction_cone " OR config_STOCK MATCHES "friction_cone")
  message(FATAL_ERROR "the two programs did not run a patched and a stock ODE:\n"
                      "  patched: ${config_PATCHED}\n  stock:   ${config_STOCK}")
endif()
if(n_PATCHED LESS 100)
  message(FATAL_ERROR "only ${n_PATCHED} lines of trajectories (${WORK_DIR}/PATCHED.txt)")
endif()
if(NOT body_PATCHED STREQUAL body_STOCK)
  message(FATAL_ERROR "the patched ODE with the cone off differs from the stock ODE: compare "
                      "${WORK_DIR}/PATCHED.txt and ${WORK_DIR}/STOCK.txt")
endif()
math(EXPR n "${n_PATCHED} - 1")
message(STATUS "${n} lines of trajectories (hex floats) identical: ${config_PATCHED} vs "
               "${config_STOCK}")
