# SPDX-License-Identifier: MIT
# Installs the build tree into a scratch prefix, then builds and runs a consumer project against
# it twice: through find_package(rheofeed) and through pkg-config. Run with cmake -P and
#   -DBUILD_DIR=<rheofeed build> -DSOURCE_DIR=<tests/install> -DWORK_DIR=<scratch dir>
foreach(var BUILD_DIR SOURCE_DIR WORK_DIR)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "install_test.cmake: -D${var}=... is required")
  endif()
endforeach()

function(run_step)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "step failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  message(STATUS "${out}")
endfunction()

set(prefix "${WORK_DIR}/prefix")
file(REMOVE_RECURSE "${WORK_DIR}")
run_step(${CMAKE_COMMAND} --install "${BUILD_DIR}" --prefix "${prefix}")

# 1. CMake package.
run_step(${CMAKE_COMMAND} -S "${SOURCE_DIR}/consumer" -B "${WORK_DIR}/consumer"
         -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_BUILD_TYPE=Release)
run_step(${CMAKE_COMMAND} --build "${WORK_DIR}/consumer")
run_step("${WORK_DIR}/consumer/consumer_cpp")
run_step("${WORK_DIR}/consumer/consumer_c")

# 2. pkg-config, C compiler only.
file(GLOB pc_file "${prefix}/lib*/pkgconfig/rheofeed.pc" "${prefix}/lib/*/pkgconfig/rheofeed.pc")
if(NOT pc_file)
  message(FATAL_ERROR "rheofeed.pc was not installed under ${prefix}")
endif()
get_filename_component(pc_dir "${pc_file}" DIRECTORY)
set(ENV{PKG_CONFIG_PATH} "${pc_dir}")
execute_process(COMMAND pkg-config --cflags --libs --static rheofeed
  OUTPUT_VARIABLE flags RESULT_VARIABLE rc OUTPUT_STRIP_TRAILING_WHITESPACE)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "pkg-config rheofeed failed")
endif()
separate_arguments(flags UNIX_COMMAND "${flags}")
run_step(cc "${SOURCE_DIR}/consumer/main.c" -o "${WORK_DIR}/consumer_pc" ${flags})
run_step("${WORK_DIR}/consumer_pc")
