# SPDX-License-Identifier: MIT
# The error-vs-cost study's core (rheofeed study SCENE and the feeder_study binary), a static
# library of the demos and of the `rheofeed` command. Included from demos/CMakeLists.txt and
# demos/cli/CMakeLists.txt; defined once, whichever comes first.
include(${CMAKE_CURRENT_LIST_DIR}/builtin_scenes.cmake)
if(NOT TARGET rheofeed_study)
  add_library(rheofeed_study STATIC ${CMAKE_CURRENT_LIST_DIR}/study.cpp)
  target_include_directories(rheofeed_study PUBLIC ${CMAKE_CURRENT_LIST_DIR}/..)
  target_link_libraries(rheofeed_study PUBLIC rheofeed::output rheofeed_builtin_scenes)
endif()
