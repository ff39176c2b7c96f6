# SPDX-License-Identifier: MIT
# The installed CMake package of rheofeed is made of components, each with its own export file
# and its own dependency lookups, so that a consumer pays only for what it uses:
#   find_package(rheofeed COMPONENTS plugin)   # needs ODE only
#
#   rheofeed_package_component(<name> TARGETS <target>... [COMPONENTS <component>...]
#                              [PACKAGES <package>...])
# installs <target>s in the export set of component <name>. COMPONENTS are the components these
# targets link (declared before this one), PACKAGES the external packages their exported link
# interface names (known to rheofeedConfig.cmake.in: ODE, Eigen3, nlohmann_json, assimp, Qhull,
# TinyGLTF, Threads).
# A new library joins an existing component (add it to TARGETS) or gets a component of its own.
#
#   rheofeed_package_install()
# after the last component: writes rheofeedConfig.cmake (the component table is substituted into
# cmake/rheofeedConfig.cmake.in), the version file and the pkg-config file(s).
include_guard(GLOBAL)
include(CMakePackageConfigHelpers)
include(GNUInstallDirs)

set(RHEOFEED_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/rheofeed)
set(RHEOFEED_PACKAGE_TABLE "")
set(RHEOFEED_PACKAGE_COMPONENTS "")
set(RHEOFEED_PACKAGE_KNOWN_PACKAGES ODE Eigen3 nlohmann_json assimp Qhull TinyGLTF Threads)

function(rheofeed_package_component name)
  cmake_parse_arguments(PARSE_ARGV 1 arg "" "" "TARGETS;COMPONENTS;PACKAGES")
  if(arg_UNPARSED_ARGUMENTS OR NOT arg_TARGETS)
    message(FATAL_ERROR "rheofeed_package_component(${name}): bad arguments "
                        "'${arg_UNPARSED_ARGUMENTS}' (TARGETS is required)")
  endif()
  foreach(c IN LISTS arg_COMPONENTS)
    if(NOT c IN_LIST RHEOFEED_PACKAGE_COMPONENTS)
      message(FATAL_ERROR "rheofeed_package_component(${name}): component '${c}' must be "
                          "declared before it is used (declared: ${RHEOFEED_PACKAGE_COMPONENTS})")
    endif()
  endforeach()
  foreach(p IN LISTS arg_PACKAGES)
    if(NOT p IN_LIST RHEOFEED_PACKAGE_KNOWN_PACKAGES)
      message(FATAL_ERROR "rheofeed_package_component(${name}): package '${p}' has no lookup in "
                          "cmake/rheofeedConfig.cmake.in (known: ${RHEOFEED_PACKAGE_KNOWN_PACKAGES})")
    endif()
  endforeach()
  # Shared libraries find the ones they link beside themselves, wherever the prefix is.
  foreach(t IN LISTS arg_TARGETS)
    get_target_property(type ${t} TYPE)
    get_target_property(rpath ${t} INSTALL_RPATH)
    if(type STREQUAL "SHARED_LIBRARY" AND NOT rpath)
      if(APPLE)
        set_target_properties(${t} PROPERTIES INSTALL_RPATH "@loader_path")
      elseif(UNIX)
        set_target_properties(${t} PROPERTIES INSTALL_RPATH "$ORIGIN")
      endif()
    endif()
  endforeach()
  install(TARGETS ${arg_TARGETS}
    EXPORT rheofeed_${name}_targets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
    RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  install(EXPORT rheofeed_${name}_targets NAMESPACE rheofeed::
    FILE rheofeed_${name}-targets.cmake DESTINATION ${RHEOFEED_CMAKE_DIR})
  set(imported "")
  foreach(t IN LISTS arg_TARGETS)
    get_target_property(export_name ${t} EXPORT_NAME)
    if(NOT export_name)
      set(export_name ${t})
    endif()
    list(APPEND imported rheofeed::${export_name})
  endforeach()
  string(APPEND RHEOFEED_PACKAGE_TABLE
    "set(_rheofeed_${name}_targets ${imported})\n"
    "set(_rheofeed_${name}_components ${arg_COMPONENTS})\n"
    "set(_rheofeed_${name}_packages ${arg_PACKAGES})\n")
  set(RHEOFEED_PACKAGE_TABLE "${RHEOFEED_PACKAGE_TABLE}" PARENT_SCOPE)
  set(RHEOFEED_PACKAGE_COMPONENTS ${RHEOFEED_PACKAGE_COMPONENTS} ${name} PARENT_SCOPE)
endfunction()

# The C++ runtime libraries that a C linker does not add (libstdc++ and libm with GCC): what a C
# program needs on its link line besides rheofeed's static archives.
function(_rheofeed_cxx_runtime_libs out)
  set(libs "")
  foreach(lib IN LISTS CMAKE_CXX_IMPLICIT_LINK_LIBRARIES)
    if(NOT lib IN_LIST CMAKE_C_IMPLICIT_LINK_LIBRARIES AND NOT lib IN_LIST libs)
      list(APPEND libs ${lib})
    endif()
  endforeach()
  set(${out} ${libs} PARENT_SCOPE)
endfunction()

function(rheofeed_package_install)
  get_property(languages GLOBAL PROPERTY ENABLED_LANGUAGES)
  if(NOT "C" IN_LIST languages OR NOT "CXX" IN_LIST languages)
    message(FATAL_ERROR "rheofeed_package_install: C and C++ must be enabled to tell the C++ "
                        "runtime a C consumer links (enabled: ${languages})")
  endif()
  _rheofeed_cxx_runtime_libs(RHEOFEED_CXX_RUNTIME_LIBS)
  configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/rheofeedConfig.cmake.in
    ${PROJECT_BINARY_DIR}/rheofeedConfig.cmake
    INSTALL_DESTINATION ${RHEOFEED_CMAKE_DIR})
  write_basic_package_version_file(${PROJECT_BINARY_DIR}/rheofeedConfigVersion.cmake
    COMPATIBILITY SameMinorVersion)
  install(FILES
    ${PROJECT_BINARY_DIR}/rheofeedConfig.cmake
    ${PROJECT_BINARY_DIR}/rheofeedConfigVersion.cmake
    ${PROJECT_SOURCE_DIR}/cmake/ODE.cmake
    DESTINATION ${RHEOFEED_CMAKE_DIR})

  # pkg-config: rheofeed.pc is the ODE plugin with its C and C++ API (libraries rheofeed_plugin
  # and rheofeed_laws), the part a C program uses. A C linker does not add the C++ runtime: with
  # static archives a C program needs it on every link (Libs), with shared libraries the
  # libraries carry it themselves (Libs.private, for a static link).
  list(TRANSFORM RHEOFEED_CXX_RUNTIME_LIBS PREPEND "-l" OUTPUT_VARIABLE runtime_flags)
  list(JOIN runtime_flags " " runtime_flags)
  get_target_property(plugin_type rheofeed_plugin TYPE)
  if(plugin_type STREQUAL "STATIC_LIBRARY")
    set(RHEOFEED_PC_LIBS_RUNTIME "${runtime_flags}")
    set(RHEOFEED_PC_LIBS_PRIVATE "")
  else()
    set(RHEOFEED_PC_LIBS_RUNTIME "")
    set(RHEOFEED_PC_LIBS_PRIVATE "${runtime_flags}")
  endif()
  # Relocatable: the prefix is found from the .pc file's own location.
  file(RELATIVE_PATH RHEOFEED_PC_TO_PREFIX
    ${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_LIBDIR}/pkgconfig ${CMAKE_INSTALL_PREFIX})
  configure_file(${PROJECT_SOURCE_DIR}/cmake/rheofeed.pc.in ${PROJECT_BINARY_DIR}/rheofeed.pc @ONLY)
  install(FILES ${PROJECT_BINARY_DIR}/rheofeed.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
endfunction()
