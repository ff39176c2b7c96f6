# SPDX-License-Identifier: MIT
# Builds ODE 0.16.2 from Debian's source package with rheofeed's patches (patches/*.patch, in
# order) into the build tree, at configure time, and wraps it in the imported target ODE::ODE.
# Used by rheofeed's own build only (RHEOFEED_ODE=patched, the default); not installed.
#
# The source is what `.ci/deps` unpacked with `apt-get source ode` (RHEOFEED_ODE_SOURCE_DIR,
# default <repo>/.deps/ode-0.16.2); nothing is downloaded here. The build uses the features of
# Debian's package (debian/rules: double precision, libccd from the system for every collider
# except box-cylinder, trimesh with OPCODE and its new collider, the threading interface with the
# built-in implementation, debug checks on: no dNODEBUG), as a static library (position
# independent) so that it cannot be confused at run time with the system's libode.so.
#
# Configure-time build: cmake/ODE.cmake then probes the library like any other ODE (double
# precision) and the top-level CMakeLists checks that the patch is in (ODE_EXT_friction_cone).
# The result is kept in <build>/_deps/ode-patched and rebuilt only when the source folder, the
# patches, the compiler or these settings change (a stamp file holds their hash).
include_guard(GLOBAL)

set(RHEOFEED_ODE_SOURCE_DIR "${PROJECT_SOURCE_DIR}/.deps/ode-0.16.2" CACHE PATH
    "ODE 0.16.2 source from Debian (apt-get source ode; .ci/deps unpacks it here)")

function(_rheofeed_build_patched_ode)
  set(src "${RHEOFEED_ODE_SOURCE_DIR}")
  if(NOT EXISTS "${src}/ode/src/quickstep.cpp" OR NOT EXISTS "${src}/CMakeLists.txt")
    message(FATAL_ERROR
      "RHEOFEED_ODE=patched needs Debian's ODE 0.16.2 source in RHEOFEED_ODE_SOURCE_DIR "
      "('${src}' has no ode/src/quickstep.cpp): run `bash .ci/deps` (it adds a deb-src entry and "
      "runs apt-get source ode there), pass -DRHEOFEED_ODE_SOURCE_DIR=<unpacked ode-0.16.2>, or "
      "configure with -DRHEOFEED_ODE=system to use the stock libode-dev (no friction cone)")
  endif()
  file(GLOB patches "${PROJECT_SOURCE_DIR}/patches/*.patch")
  list(SORT patches)
  find_program(RHEOFEED_PATCH_PROGRAM patch)
  if(NOT RHEOFEED_PATCH_PROGRAM)
    message(FATAL_ERROR "RHEOFEED_ODE=patched needs the program 'patch' (Debian package patch)")
  endif()

  set(root "${CMAKE_BINARY_DIR}/_deps/ode-patched")
  set(prefix "${root}/install")
  # The ODE build's settings (Debian's features; -O2 -g as Debian's CFLAGS, debug checks kept:
  # ODE's CMake defines dNODEBUG for every configuration but Debug).
  set(ode_args
    -DCMAKE_BUILD_TYPE=Debug "-DCMAKE_C_FLAGS_DEBUG=-O2 -g" "-DCMAKE_CXX_FLAGS_DEBUG=-O2 -g"
    -DCMAKE_C_COMPILER=${CMAKE_C_COMPILER} -DCMAKE_CXX_COMPILER=${CMAKE_CXX_COMPILER}
    -DBUILD_SHARED_LIBS=OFF -DCMAKE_POSITION_INDEPENDENT_CODE=ON -DODE_DOUBLE_PRECISION=ON
    -DODE_WITH_DEMOS=OFF -DODE_WITH_TESTS=OFF -DODE_WITH_OPCODE=ON -DODE_WITH_GIMPACT=OFF
    -DODE_WITH_OU=OFF -DODE_NO_THREADING_INTF=OFF -DODE_NO_BUILTIN_THREADING_IMPL=OFF
    -DODE_WITH_LIBCCD=ON -DODE_WITH_LIBCCD_SYSTEM=ON -DODE_WITH_LIBCCD_BOX_CYL=OFF
    -DCMAKE_INSTALL_PREFIX=${prefix} -DCMAKE_INSTALL_LIBDIR=lib)
  if(CMAKE_C_COMPILER_LAUNCHER)
    list(APPEND ode_args -DCMAKE_C_COMPILER_LAUNCHER=${CMAKE_C_COMPILER_LAUNCHER})
  endif()
  if(CMAKE_CXX_COMPILER_LAUNCHER)
    list(APPEND ode_args -DCMAKE_CXX_COMPILER_LAUNCHER=${CMAKE_CXX_COMPILER_LAUNCHER})
  endif()

  # What the build depends on: the source's own version, the patches' text and the settings.
  set(fingerprint "${src}\n${ode_args}\n")
  file(SHA256 "${src}/ode/src/quickstep.cpp" h)
  string(APPEND fingerprint "${h}\n")
  foreach(p IN LISTS patches)
    file(SHA256 "${p}" h)
    string(APPEND fingerprint "${p} ${h}\n")
  endforeach()
  string(SHA256 fingerprint "${fingerprint}")
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${patches})

  set(stamp "${root}/stamp")
  set(old "")
  if(EXISTS "${stamp}" AND EXISTS "${prefix}/lib/libode.a")
    file(READ "${stamp}" old)
  endif()
  if(NOT old STREQUAL fingerprint)
    list(LENGTH patches n)
    message(STATUS "Building the patched ODE (${n} patches from patches/) in ${root} ...")
    file(REMOVE_RECURSE "${root}")
    file(MAKE_DIRECTORY "${root}")
    file(COPY "${src}/" DESTINATION "${root}/src" PATTERN debian EXCLUDE PATTERN .pc EXCLUDE)
    foreach(p IN LISTS patches)
      execute_process(COMMAND ${RHEOFEED_PATCH_PROGRAM} -p1 --batch --forward --quiet -i "${p}"
                      WORKING_DIRECTORY "${root}/src" RESULT_VARIABLE rc OUTPUT_VARIABLE out
                      ERROR_VARIABLE out)
      if(NOT rc EQUAL 0)
        message(FATAL_ERROR "patch ${p} does not apply to ${src} (copied to ${root}/src):\n${out}")
      endif()
    endforeach()
    foreach(step configure build install)
      if(step STREQUAL "configure")
        set(cmd ${CMAKE_COMMAND} -S "${root}/src" -B "${root}/build" ${ode_args})
      elseif(step STREQUAL "build")
        include(ProcessorCount)
        ProcessorCount(jobs)
        if(jobs EQUAL 0)
          set(jobs 2)
        endif()
        set(cmd ${CMAKE_COMMAND} --build "${root}/build" -j ${jobs})
      else()
        set(cmd ${CMAKE_COMMAND} --install "${root}/build")
      endif()
      execute_process(COMMAND ${cmd} RESULT_VARIABLE rc OUTPUT_FILE "${root}/${step}.log"
                      ERROR_FILE "${root}/${step}.err")
      if(NOT rc EQUAL 0)
        file(READ "${root}/${step}.err" err)
        message(FATAL_ERROR "patched ODE: ${step} failed (exit ${rc}); log ${root}/${step}.log:\n"
                            "${err}")
      endif()
    endforeach()
    file(WRITE "${stamp}" "${fingerprint}")
    message(STATUS "Building the patched ODE - done (${prefix})")
  endif()

  # ODE::ODE: the static library, its headers (before /usr/include, where a stock libode-dev may
  # also be), and what libode.a needs (libccd, threads, the C++ runtime through the C++ linker).
  find_library(RHEOFEED_CCD_LIBRARY ccd)
  if(NOT RHEOFEED_CCD_LIBRARY)
    message(FATAL_ERROR "the patched ODE links the system libccd: install libccd-dev")
  endif()
  find_package(Threads REQUIRED)
  # A C program (the C API test, the configure probes) links with the C linker, which does not
  # add the C++ runtime libode.a needs.
  set(cxx_runtime "")
  foreach(lib IN LISTS CMAKE_CXX_IMPLICIT_LINK_LIBRARIES)
    if(NOT lib IN_LIST CMAKE_C_IMPLICIT_LINK_LIBRARIES)
      list(APPEND cxx_runtime "$<$<LINK_LANGUAGE:C>:${lib}>")
    endif()
  endforeach()
  add_library(ODE::ODE STATIC IMPORTED GLOBAL)
  set_target_properties(ODE::ODE PROPERTIES
    IMPORTED_LOCATION "${prefix}/lib/libode.a"
    INTERFACE_INCLUDE_DIRECTORIES "${prefix}/include"
    INTERFACE_LINK_LIBRARIES "${RHEOFEED_CCD_LIBRARY};Threads::Threads;m;${cxx_runtime}"
    IMPORTED_LINK_INTERFACE_LANGUAGES CXX)
  set(RHEOFEED_ODE_PC_VERSION "0.16.2 (patched: ${prefix})" PARENT_SCOPE)
endfunction()

_rheofeed_build_patched_ode()

# The patch is in: the headers declare dContactFrictionCone (0x8000) and the library says
# ODE_EXT_friction_cone. (The tests check what it does: Plugin.FrictionCone.*.)
function(_rheofeed_check_patched_ode)
  if(RHEOFEED_ODE_PATCH_CHECKED STREQUAL "${CMAKE_BINARY_DIR}/_deps/ode-patched/stamp")
    return()
  endif()
  set(dir "${CMAKE_BINARY_DIR}/CMakeFiles/rheofeed_ode_patch_check")
  file(WRITE "${dir}/check.c" [=[
#include <ode/ode.h>
#include <stdio.h>
int main(void) {
  int ok;
  dInitODE2(0);
  ok = dCheckConfiguration("ODE_EXT_friction_cone") && dContactFrictionCone == 0x8000;
  printf("%s\n", dGetConfiguration());
  dCloseODE();
  return ok ? 0 : 1;
}
]=])
  try_run(run_result compiled "${dir}/build" "${dir}/check.c" LINK_LIBRARIES ODE::ODE
          COMPILE_OUTPUT_VARIABLE compile_out RUN_OUTPUT_VARIABLE run_out)
  if(NOT compiled OR NOT run_result EQUAL 0)
    message(FATAL_ERROR "the patched ODE in ${CMAKE_BINARY_DIR}/_deps/ode-patched lacks the "
                        "friction cone of patches/0002 (compiled: ${compiled}, exit: "
                        "${run_result}, configuration: ${run_out}):\n${compile_out}")
  endif()
  set(RHEOFEED_ODE_PATCH_CHECKED "${CMAKE_BINARY_DIR}/_deps/ode-patched/stamp" CACHE INTERNAL
      "the patched ODE was checked")
endfunction()
_rheofeed_check_patched_ode()
