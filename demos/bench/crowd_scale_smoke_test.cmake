# SPDX-License-Identifier: MIT
# Smoke test of the scale benchmark (ctest Bench.CrowdScale.*, demos/CMakeLists.txt):
#   cmake -DBENCH=<crowd_scale_bench> -DOUT=<folder> -P crowd_scale_smoke_test.cmake
# Runs `crowd_scale_bench --quick --out OUT` and checks what it wrote, never a time: exit code 0;
# crowd_scale.csv with exactly the documented columns and one row per run (trough 20 and 40,
# bowl 10 and 20 parts, each 1 s / 0.01 s = 100 steps), every row as wide as the header;
# crowd_scale.md naming both scenes; crowd_scale.png when gnuplot is installed; no temporary
# file left beside them.
cmake_policy(SET CMP0007 NEW)  # lists keep empty elements (an empty last field)
file(REMOVE_RECURSE "${OUT}")
execute_process(COMMAND "${BENCH}" --quick --out "${OUT}"
  RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 280)
set(report "stdout:\n${out}\nstderr:\n${err}")
if(NOT code STREQUAL "0")
  message(FATAL_ERROR "exit code ${code}, expected 0\n${report}")
endif()

set(columns
  scene parts spawned mean_parts_present steps time_step_s simulated_s cpu_s wall_s cpu_per_wall
  real_time_factor cpu_ms_per_step wall_ms_per_step collision_ms_per_step contacts_ms_per_step
  solve_ms_per_step scene_layer_ms_per_step checks_ms_per_step contacts_per_part rows_per_part
  lost lost_through_fixture lost_fell lost_inside_fixture lost_left_feeder lost_other sunk exited
  local_law_cells local_law_model_runs local_law_model_cpu_s scene_check_warnings
  cpu_slope_from_previous)
list(LENGTH columns width)
file(STRINGS "${OUT}/crowd_scale.csv" lines)
list(LENGTH lines count)
if(NOT count EQUAL 5)
  message(FATAL_ERROR "crowd_scale.csv has ${count} lines, expected a header and 4 rows\n${report}")
endif()
list(GET lines 0 header)
string(REPLACE "," ";" header_fields "${header}")
if(NOT header_fields STREQUAL columns)
  message(FATAL_ERROR "crowd_scale.csv header\n  ${header}\nexpected the columns\n  ${columns}")
endif()
set(expected_runs "trough,20" "trough,40" "bowl,10" "bowl,20")
foreach(k RANGE 1 4)
  list(GET lines ${k} line)
  # A trailing empty field (the first row of a scene has no slope) is kept by the "x;" form.
  string(REPLACE "," ";" fields "${line};")
  list(LENGTH fields n)
  math(EXPR n "${n} - 1")
  if(NOT n EQUAL width)
    message(FATAL_ERROR "row ${k} has ${n} fields, the header ${width}:\n  ${line}")
  endif()
  math(EXPR e "${k} - 1")
  list(GET expected_runs ${e} run)
  list(GET fields 0 scene)
  list(GET fields 1 parts)
  list(GET fields 4 steps)
  if(NOT "${scene},${parts}" STREQUAL run)
    message(FATAL_ERROR "row ${k} is the run ${scene},${parts}, expected ${run}")
  endif()
  if(NOT steps EQUAL 100)
    message(FATAL_ERROR "row ${k} (${run}) timed ${steps} steps, expected 1 s / 0.01 s = 100")
  endif()
endforeach()

file(READ "${OUT}/crowd_scale.md" md)
foreach(title "Hopper-fed trough" "Bowl feeder" "Regenerate:")
  string(FIND "${md}" "${title}" at)
  if(at LESS 0)
    message(FATAL_ERROR "crowd_scale.md does not contain \"${title}\":\n${md}")
  endif()
endforeach()
find_program(gnuplot_program gnuplot)
if(gnuplot_program AND NOT EXISTS "${OUT}/crowd_scale.png")
  message(FATAL_ERROR "gnuplot is installed but crowd_scale.png was not written\n${report}")
endif()
file(GLOB written RELATIVE "${OUT}" "${OUT}/*")
list(REMOVE_ITEM written crowd_scale.csv crowd_scale.md crowd_scale.png)
if(written)
  message(FATAL_ERROR "files left beside the outputs: ${written}")
endif()
