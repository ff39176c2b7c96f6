# SPDX-License-Identifier: MIT
# The stability matrix's cases and per-run measurement (issue 7), a static library used by the
# stability_matrix demo and the reduced matrix test (tests/validation). Included from both
# demos/CMakeLists.txt and tests/validation/CMakeLists.txt; defined once, whichever comes first,
# so that the test builds whether or not RHEOFEED_BUILD_DEMOS is on.
include(${CMAKE_CURRENT_LIST_DIR}/../common/builtin_scenes.cmake)
if(NOT TARGET rheofeed_stability_cases)
  add_library(rheofeed_stability_cases STATIC
    ${CMAKE_CURRENT_LIST_DIR}/stability_cases.cpp
    ${CMAKE_CURRENT_LIST_DIR}/stability_run.cpp)
  # Included as "stability/stability_cases.hpp".
  target_include_directories(rheofeed_stability_cases PUBLIC ${CMAKE_CURRENT_LIST_DIR}/..)
  target_link_libraries(rheofeed_stability_cases PUBLIC rheofeed::output rheofeed_builtin_scenes)
endif()
