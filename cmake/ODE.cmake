# SPDX-License-Identifier: MIT
# Wraps Debian's ODE (libode-dev ships pkg-config metadata only, no CMake package) in the
# imported target ODE::ODE and refuses a single-precision build. When ODE::ODE exists already
# (rheofeed's own build with RHEOFEED_ODE=patched: cmake/PatchedODE.cmake) only the probe runs.
# The probe also tells whether the library has rheofeed's friction-cone patch: it sets
# RHEOFEED_ODE_HAS_FRICTION_CONE (dCheckConfiguration("ODE_EXT_friction_cone")) and
# RHEOFEED_ODE_CONFIGURATION (dGetConfiguration()).
#
# Used by rheofeed's own build and by the installed rheofeedConfig.cmake, so it must work in any
# consumer project: C only, C++ only, or both (the precision probe is compiled in whichever of
# the two is enabled). Sets RHEOFEED_ODE_FOUND and, when false, RHEOFEED_ODE_NOT_FOUND_MESSAGE.
# A failure is fatal unless RHEOFEED_ODE_OPTIONAL is set (the package config sets it and reports
# the message through find_package). Safe to include more than once.

function(_rheofeed_wrap_ode)
  set(RHEOFEED_ODE_FOUND FALSE PARENT_SCOPE)
  if(NOT TARGET ODE::ODE)
    find_package(PkgConfig QUIET)
    if(NOT PKG_CONFIG_FOUND)
      set(RHEOFEED_ODE_NOT_FOUND_MESSAGE
          "rheofeed finds ODE through pkg-config (Debian's libode-dev ships ode.pc only), but "
          "pkg-config was not found: install pkg-config." PARENT_SCOPE)
      return()
    endif()
    pkg_check_modules(RHEOFEED_ODE_PC QUIET IMPORTED_TARGET GLOBAL ode)
    if(NOT RHEOFEED_ODE_PC_FOUND)
      set(RHEOFEED_ODE_NOT_FOUND_MESSAGE
          "rheofeed needs ODE: pkg-config found no module 'ode' (PKG_CONFIG_PATH: "
          "'$ENV{PKG_CONFIG_PATH}'). Install Debian's libode-dev." PARENT_SCOPE)
      return()
    endif()
    pkg_get_variable(precision ode precision)
    if(precision AND NOT precision STREQUAL "dDOUBLE")
      set(RHEOFEED_ODE_NOT_FOUND_MESSAGE
          "rheofeed needs ODE built in double precision; pkg-config 'ode' says "
          "precision=${precision} (must be dDOUBLE). Install Debian's libode-dev (double "
          "precision) or rebuild ODE with -DODE_DOUBLE_PRECISION=ON." PARENT_SCOPE)
      return()
    endif()
    add_library(ODE::ODE INTERFACE IMPORTED GLOBAL)
    target_link_libraries(ODE::ODE INTERFACE PkgConfig::RHEOFEED_ODE_PC)
  endif()

  # Configure-time precision check: the headers must select dDOUBLE and the library itself must
  # report "ODE_double_precision" from dCheckConfiguration(). The same source is valid C and
  # C++, so it is compiled as whichever language the project enabled.
  # The probe's outcome is cached per ODE (patched or system): switching RHEOFEED_ODE in a build
  # tree probes again.
  set(probe_key "${RHEOFEED_ODE}")
  if(NOT probe_key)
    set(probe_key "system")
  endif()
  if(RHEOFEED_ODE_IS_DOUBLE AND RHEOFEED_ODE_PROBE_KEY STREQUAL probe_key)
    set(RHEOFEED_ODE_FOUND TRUE PARENT_SCOPE)
    return()
  endif()
  get_property(languages GLOBAL PROPERTY ENABLED_LANGUAGES)
  if("C" IN_LIST languages)
    set(ext c)
  elseif("CXX" IN_LIST languages)
    set(ext cpp)
  else()
    # Nothing here can compile against ODE, so nothing can be built wrongly: say so, do not
    # cache, and probe again once a language is enabled.
    message(STATUS "rheofeed: neither C nor C++ is enabled (languages: '${languages}'); the "
                   "ODE precision probe is skipped")
    set(RHEOFEED_ODE_FOUND TRUE PARENT_SCOPE)
    return()
  endif()
  set(probe_dir "${CMAKE_BINARY_DIR}/CMakeFiles/rheofeed_ode_probe")
  file(WRITE "${probe_dir}/probe.${ext}" [=[
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
  if(CMAKE_CROSSCOMPILING AND NOT CMAKE_CROSSCOMPILING_EMULATOR)
    # The probe cannot run here: the header check (dDOUBLE) is all that can be done.
    try_compile(compiled "${probe_dir}/build" "${probe_dir}/probe.${ext}"
                LINK_LIBRARIES ODE::ODE OUTPUT_VARIABLE compile_out)
    set(run_result 0)
    set(run_out "not run (cross-compiling without CMAKE_CROSSCOMPILING_EMULATOR)")
  else()
    try_run(run_result compiled "${probe_dir}/build" "${probe_dir}/probe.${ext}"
            LINK_LIBRARIES ODE::ODE
            COMPILE_OUTPUT_VARIABLE compile_out RUN_OUTPUT_VARIABLE run_out)
  endif()
  if(NOT compiled)
    set(RHEOFEED_ODE_NOT_FOUND_MESSAGE
        "rheofeed: could not build a ${ext} program against ODE (probe ${probe_dir}/probe.${ext})"
        ":\n${compile_out}" PARENT_SCOPE)
    return()
  endif()
  if(NOT run_result EQUAL 0)
    set(RHEOFEED_ODE_NOT_FOUND_MESSAGE
        "rheofeed needs ODE in double precision, but dCheckConfiguration(\"ODE_double_precision\")"
        " is false for the installed library (exit code ${run_result}, configuration: "
        "${run_out})" PARENT_SCOPE)
    return()
  endif()
  string(STRIP "${run_out}" run_out)
  if(NOT rheofeed_FIND_QUIETLY)
    message(STATUS "ODE ${RHEOFEED_ODE_PC_VERSION}: ${run_out}")
  endif()
  set(RHEOFEED_ODE_IS_DOUBLE TRUE CACHE INTERNAL "ODE reports double precision")
  set(RHEOFEED_ODE_PROBE_KEY "${probe_key}" CACHE INTERNAL "which ODE the probe ran on")
  set(RHEOFEED_ODE_CONFIGURATION "${run_out}" CACHE INTERNAL "dGetConfiguration() of ODE")
  if(" ${run_out} " MATCHES " ODE_EXT_friction_cone ")
    set(RHEOFEED_ODE_HAS_FRICTION_CONE TRUE CACHE INTERNAL "ODE has dContactFrictionCone")
  else()
    set(RHEOFEED_ODE_HAS_FRICTION_CONE FALSE CACHE INTERNAL "ODE has dContactFrictionCone")
  endif()
  set(RHEOFEED_ODE_FOUND TRUE PARENT_SCOPE)
endfunction()

set(RHEOFEED_ODE_NOT_FOUND_MESSAGE "")
_rheofeed_wrap_ode()
if(NOT RHEOFEED_ODE_FOUND AND NOT RHEOFEED_ODE_OPTIONAL)
  message(FATAL_ERROR "${RHEOFEED_ODE_NOT_FOUND_MESSAGE}")
endif()
