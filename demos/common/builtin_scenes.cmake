# SPDX-License-Identifier: MIT
# The built-in demo scenes (scenes built in code, the sources of demos/scenes/*.json and the
# test scenes of tests/scene and tests/validation): a static library for the demos and the
# tests, not installed. Included from demos/CMakeLists.txt and tests/CMakeLists.txt; defined
# once, whichever comes first, so that the tests build whether or not RHEOFEED_BUILD_DEMOS is on.
if(NOT TARGET rheofeed_builtin_scenes)
  add_library(rheofeed_builtin_scenes STATIC ${CMAKE_CURRENT_LIST_DIR}/builtin_scenes.cpp
    ${CMAKE_CURRENT_LIST_DIR}/bowl_scene.cpp)
  # Included as "common/builtin_scenes.hpp".
  target_include_directories(rheofeed_builtin_scenes PUBLIC ${CMAKE_CURRENT_LIST_DIR}/..)
  target_link_libraries(rheofeed_builtin_scenes PUBLIC rheofeed::scene)
endif()
