# SPDX-License-Identifier: MIT
# Installs the build tree into a scratch prefix, then builds and runs applications against it:
#   consumer/c       a C-only CMake project        find_package(rheofeed), the C API
#   consumer/cxx     a C++-only CMake project      find_package(rheofeed), C++ API and scene layer
#   consumer/plugin  a plugin-only C++ project     find_package(rheofeed COMPONENTS plugin) with
#                    Eigen, nlohmann-json and assimp unfindable; also runs the README's
#                    integration example (consumer/integration.cpp)
#   pkg-config       a C program compiled with cc and plain `pkg-config --cflags --libs rheofeed`,
#                    and again with `pkg-config --static` (a fully static program, cc -static,
#                    cannot link: Debian's ode.pc lacks the -lccd that libode.a needs)
# and checks that the plugin's public headers include no Eigen, nlohmann-json or assimp header,
# that the README quotes consumer/integration.cpp exactly, and that the installed `rheofeed`
# command checks and runs a shipped scene (with meshes) from the prefix. Run with cmake -P and
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
set(consumers "${SOURCE_DIR}/consumer")
file(REMOVE_RECURSE "${WORK_DIR}")
run_step(${CMAKE_COMMAND} --install "${BUILD_DIR}" --prefix "${prefix}")

# 1. The README's integration example is consumer/integration.cpp, word for word: the fenced
#    block after the marker line.
set(readme "${SOURCE_DIR}/../../README.md")
set(marker "<!-- tests/install/consumer/integration.cpp -->")
file(READ "${readme}" readme_text)
file(READ "${consumers}/integration.cpp" snippet)
string(FIND "${readme_text}" "${marker}\n```cpp\n" at)
if(at LESS 0)
  message(FATAL_ERROR "README.md has no line '${marker}' followed by a ```cpp block")
endif()
string(LENGTH "${marker}\n```cpp\n" skip)
math(EXPR at "${at} + ${skip}")
string(SUBSTRING "${readme_text}" ${at} -1 quoted)
string(FIND "${quoted}" "```\n" end)
string(SUBSTRING "${quoted}" 0 ${end} quoted)
if(NOT quoted STREQUAL snippet)
  file(WRITE "${WORK_DIR}/readme_snippet.cpp" "${quoted}")
  message(FATAL_ERROR "README.md's integration example differs from consumer/integration.cpp "
                      "(diff ${WORK_DIR}/readme_snippet.cpp ${consumers}/integration.cpp)")
endif()

# 2. CMake consumers.
foreach(kind c cxx plugin)
  set(dir "${WORK_DIR}/${kind}")
  run_step(${CMAKE_COMMAND} -S "${consumers}/${kind}" -B "${dir}" -DCMAKE_PREFIX_PATH=${prefix}
           -DCMAKE_BUILD_TYPE=Release)
  run_step(${CMAKE_COMMAND} --build "${dir}")
endforeach()
run_step("${WORK_DIR}/c/consumer_c")
run_step("${WORK_DIR}/cxx/consumer_cpp")
run_step("${WORK_DIR}/cxx/consumer_scene")
run_step("${WORK_DIR}/plugin/consumer_plugin")
run_step("${WORK_DIR}/plugin/integration")

# 3. pkg-config, C compiler only.
file(GLOB pc_file "${prefix}/lib*/pkgconfig/rheofeed.pc" "${prefix}/lib/*/pkgconfig/rheofeed.pc")
if(NOT pc_file)
  message(FATAL_ERROR "rheofeed.pc was not installed under ${prefix}")
endif()
get_filename_component(pc_dir "${pc_file}" DIRECTORY)
set(ENV{PKG_CONFIG_PATH} "${pc_dir}")
function(pkg_config out)
  execute_process(COMMAND pkg-config ${ARGN} rheofeed OUTPUT_VARIABLE flags
    RESULT_VARIABLE rc OUTPUT_STRIP_TRAILING_WHITESPACE)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "pkg-config ${ARGN} rheofeed failed (${rc})")
  endif()
  separate_arguments(flags UNIX_COMMAND "${flags}")
  set(${out} ${flags} PARENT_SCOPE)
endfunction()
execute_process(COMMAND pkg-config --variable=libdir rheofeed OUTPUT_VARIABLE libdir
  OUTPUT_STRIP_TRAILING_WHITESPACE)
set(rpath "-Wl,-rpath,${libdir}")  # for a shared rheofeed (BUILD_SHARED_LIBS=ON)
pkg_config(flags --cflags --libs)
run_step(cc "${consumers}/main.c" -o "${WORK_DIR}/consumer_pc" ${flags} ${rpath})
run_step("${WORK_DIR}/consumer_pc")
pkg_config(flags --cflags --libs --static)
run_step(cc "${consumers}/main.c" -o "${WORK_DIR}/consumer_pc_static" ${flags} ${rpath})
run_step("${WORK_DIR}/consumer_pc_static")

# 4. The plugin's public headers (include/rheofeed/*.h*, what `COMPONENTS plugin` and pkg-config
#    give) include nothing of Eigen, nlohmann-json or assimp, also indirectly.
file(GLOB headers RELATIVE "${prefix}/include" "${prefix}/include/rheofeed/*.h"
     "${prefix}/include/rheofeed/*.hpp")
set(tu "// every top-level rheofeed header\n")
foreach(h IN LISTS headers)
  string(APPEND tu "#include <${h}>\n")
endforeach()
file(WRITE "${WORK_DIR}/plugin_headers.cpp" "${tu}")
pkg_config(flags --cflags)
execute_process(COMMAND c++ -std=c++17 -M ${flags} "${WORK_DIR}/plugin_headers.cpp"
  RESULT_VARIABLE rc OUTPUT_VARIABLE deps ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the plugin headers (${headers}) do not compile on their own:\n${err}")
endif()
string(REGEX MATCHALL "[^ \\\n]*(eigen3|Eigen|nlohmann|assimp)[^ \\\n]*" leaked "${deps}")
if(leaked)
  list(REMOVE_DUPLICATES leaked)
  list(LENGTH leaked n_leaked)
  list(SUBLIST leaked 0 3 leaked)
  message(FATAL_ERROR "the plugin headers pull in ${n_leaked} headers of other libraries, e.g. "
                      "${leaked} (compiler -M of ${WORK_DIR}/plugin_headers.cpp)")
endif()
list(LENGTH headers n_headers)
message(STATUS "${n_headers} plugin headers include no Eigen, nlohmann-json or assimp header")

# 5. The installed `rheofeed` command finds the installed scenes and meshes (share/rheofeed,
#    relative to bin/): the bowl's scene names its meshes as ../meshes/*. (`check` exits 1 on a
#    scene with hazards, which the bowl has at its rheonomic step; the belt has none.)
#    Only when the demos (and so the command) are built: -DWITH_CLI=ON.
if(WITH_CLI)
  set(rheofeed_cli "${prefix}/bin/rheofeed")
  run_step("${rheofeed_cli}" check belt_conveyor)
  run_step("${rheofeed_cli}" run bowl_feeder --duration 1.2 --no-animation --out "${WORK_DIR}/run")
  if(NOT EXISTS "${WORK_DIR}/run/ode_rheonomic.json")
    message(FATAL_ERROR "${rheofeed_cli} run bowl_feeder wrote no ${WORK_DIR}/run/ode_rheonomic.json")
  endif()
endif()
