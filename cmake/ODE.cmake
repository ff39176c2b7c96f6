# SPDX-License-Identifier: MIT
# Wraps Debian's ODE (libode-dev ships pkg-config metadata only, no CMake package)
# in the imported target ODE::ODE and refuses a single-precision build.
include_guard(GLOBAL)

find_package(PkgConfig REQUIRED)
pkg_check_modules(RHEOFEED_ODE_PC REQUIRED IMPORTED_TARGET GLOBAL ode)

if(NOT TARGET ODE::ODE)
  add_library(ODE::ODE INTERFACE IMPORTED GLOBAL)
  target_link_libraries(ODE::ODE INTERFACE PkgConfig::RHEOFEED_ODE_PC)
endif()

# Configure-time precision check: the headers must select dDOUBLE, the
# pkg-config file must say so, and the library itself must report
# "ODE_double_precision" from dCheckConfiguration().
pkg_get_variable(RHEOFEED_ODE_PRECISION ode precision)
if(RHEOFEED_ODE_PRECISION AND NOT RHEOFEED_ODE_PRECISION STREQUAL "dDOUBLE")
  message(FATAL_ERROR
    "rheofeed needs ODE built in double precision; pkg-config 'ode' says precision=${RHEOFEED_ODE_PRECISION}. "
    "Install Debian's libode-dev (double precision) or rebuild ODE with -DODE_DOUBLE_PRECISION=ON.")
endif()

if(NOT DEFINED RHEOFEED_ODE_IS_DOUBLE)
  set(_probe_dir "${CMAKE_BINARY_DIR}/CMakeFiles/rheofeed_ode_probe")
  file(WRITE "${_probe_dir}/probe.c" [=[
#include <ode/ode.h>
#include <stdio.h>
#ifndef dDOUBLE
#error "ODE headers are not double precision (dDOUBLE undefined)"
#endif
int main(void) {
  dInitODE2(0);
  int ok = dCheckConfiguration("ODE_double_precision");
  printf("%s\n", dGetConfiguration());
  dCloseODE();
  return ok ? 0 : 1;
}
]=])
  try_run(_run_result _compile_result
    "${_probe_dir}/build" "${_probe_dir}/probe.c"
    LINK_LIBRARIES PkgConfig::RHEOFEED_ODE_PC
    COMPILE_OUTPUT_VARIABLE _compile_out
    RUN_OUTPUT_VARIABLE _run_out)
  if(NOT _compile_result)
    message(FATAL_ERROR "rheofeed: could not build a program against ODE:\n${_compile_out}")
  endif()
  if(NOT _run_result EQUAL 0)
    message(FATAL_ERROR
      "rheofeed needs ODE in double precision, but dCheckConfiguration(\"ODE_double_precision\") "
      "is false for the installed library (configuration: ${_run_out})")
  endif()
  string(STRIP "${_run_out}" _run_out)
  message(STATUS "ODE ${RHEOFEED_ODE_PC_VERSION}: ${_run_out}")
  set(RHEOFEED_ODE_IS_DOUBLE TRUE CACHE INTERNAL "ODE reports double precision")
endif()
