# bench_compression_check.cmake — the bench_compression_table test: ossa-bench-compression's
# table has the shape its header comment and README promise, and --metres-per-unit is honoured.
#   cmake -DBENCH=ossa-bench-compression -DASSET=a.glb [-DBVH=mocap.bvh] -P bench_compression_check.cmake
# For ASSET (a file that states its unit) and, when it exists, BVH (which states none: read as 1 m),
# one row per clip is checked at the file's unit and at an overriding --metres-per-unit: the header
# names the columns in order, unit_m is the unit the row was measured in, raw_bytes does not depend
# on the unit, and each row held its tolerance (max_error_mm <= tolerance_mm). With --breakdown,
# each row's first comment line splits cooked_bytes into parts that must add up to it. An unusable
# unit is a usage error (exit status 2). Tables are what people paste into notes, so a column moved
# or dropped here is a change to say in docs/MEASURING.md.
cmake_minimum_required(VERSION 3.25)

set(header "asset\tclip\tjoints\tunit_m\traw_bytes\tcooked_bytes\tratio\tmax_error_mm\tmean_error_mm\ttolerance_mm")

# Runs the bench on `file` with extra ARGN; sets <out_var> to its data rows (a list, one per clip).
function(bench_rows out_var file)
  execute_process(COMMAND "${BENCH}" ${ARGN} "${file}" RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "ossa-bench-compression ${ARGN} ${file} failed (${rc}): ${err}")
  endif()
  string(REPLACE ";" "," out "${out}")
  string(REPLACE "\n" ";" lines "${out}")
  list(GET lines 0 machine)
  list(GET lines 1 got_header)
  if(NOT machine MATCHES "^# cpu: ")
    message(FATAL_ERROR "first line is not the machine line: '${machine}'")
  endif()
  if(NOT got_header STREQUAL header)
    message(FATAL_ERROR "header is\n  '${got_header}'\nexpected\n  '${header}'")
  endif()
  list(SUBLIST lines 2 -1 rows)
  list(FILTER rows EXCLUDE REGEX "^$")
  list(LENGTH rows n)
  if(n EQUAL 0)
    message(FATAL_ERROR "no clip rows for ${file}")
  endif()
  set(${out_var} "${rows}" PARENT_SCOPE)
endfunction()

# Field `index` of a tab-separated row.
function(field out_var row index)
  string(REPLACE "\t" ";" cells "${row}")
  list(LENGTH cells n)
  if(NOT n EQUAL 10)
    message(FATAL_ERROR "row has ${n} fields, not 10: '${row}'")
  endif()
  list(GET cells ${index} value)
  set(${out_var} "${value}" PARENT_SCOPE)
endfunction()

# Checks every row of `rows` was measured in `unit` and held its tolerance; sets <raw_var> to the
# first row's raw_bytes.
function(check_rows raw_var rows unit)
  foreach(row IN LISTS rows)
    field(got_unit "${row}" 3)
    field(max_error "${row}" 7)
    field(tolerance "${row}" 9)
    if(NOT got_unit STREQUAL unit)
      message(FATAL_ERROR "unit_m is '${got_unit}', expected '${unit}': '${row}'")
    endif()
    if(max_error GREATER tolerance)
      message(FATAL_ERROR "max_error_mm ${max_error} exceeds tolerance_mm ${tolerance}: '${row}'")
    endif()
  endforeach()
  list(GET rows 0 first)
  field(raw "${first}" 4)
  set(${raw_var} "${raw}" PARENT_SCOPE)
endfunction()

function(check_asset file file_unit override)
  bench_rows(own "${file}")
  check_rows(raw_own "${own}" "${file_unit}")
  bench_rows(overridden "${file}" --metres-per-unit ${override})
  check_rows(raw_overridden "${overridden}" "${override}")
  if(NOT raw_own EQUAL raw_overridden)
    message(FATAL_ERROR "raw_bytes changed with the unit: ${raw_own} vs ${raw_overridden}")
  endif()
  message(STATUS "${file}: unit ${file_unit} and --metres-per-unit ${override} checked")
endfunction()

check_asset("${ASSET}" 1 0.01)  # glTF is in metres
if(DEFINED BVH AND EXISTS "${BVH}")
  check_asset("${BVH}" 1 0.056444)  # CMU's unit: 1/0.45 inch
else()
  message(STATUS "no BVH at '${BVH}': the unit-less case is not checked (../shared/assets absent)")
endif()

# --breakdown: each row is followed by three "# CLIP: " lines, the first of which splits the row's
# cooked_bytes into the stored vectors; the parts must add up to the column.
function(check_breakdown file)
  execute_process(COMMAND "${BENCH}" --breakdown "${file}" RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "ossa-bench-compression --breakdown ${file} failed (${rc}): ${err}")
  endif()
  string(REPLACE ";" "," out "${out}")
  string(REPLACE "\n" ";" lines "${out}")
  list(FILTER lines EXCLUDE REGEX "^$")
  list(LENGTH lines n)
  set(i 2)  # after the machine line and the header
  set(rows 0)
  while(i LESS n)
    list(GET lines ${i} row)
    field(clip "${row}" 1)
    field(cooked "${row}" 5)
    math(EXPR last "${i} + 3")
    if(last GREATER_EQUAL n)
      message(FATAL_ERROR "row '${row}' is not followed by three breakdown lines")
    endif()
    math(EXPR i "${i} + 1")
    list(GET lines ${i} parts)
    set(vectors "constants [0-9]+ x [0-9]+ = ([0-9]+) B \\+ channel records [0-9]+ x [0-9]+ = ([0-9]+) B")
    string(APPEND vectors " \\+ key_frames [0-9]+ x 2 = ([0-9]+) B \\+ key_values ([0-9]+) B = ([0-9]+) B")
    if(NOT parts MATCHES "^# ${clip}: ${vectors}$")
      message(FATAL_ERROR "first breakdown line of '${clip}' is '${parts}'")
    endif()
    math(EXPR sum "${CMAKE_MATCH_1} + ${CMAKE_MATCH_2} + ${CMAKE_MATCH_3} + ${CMAKE_MATCH_4}")
    if(NOT sum EQUAL CMAKE_MATCH_5 OR NOT sum EQUAL cooked)
      message(FATAL_ERROR
              "'${clip}': parts add up to ${sum}, the line says ${CMAKE_MATCH_5}, cooked_bytes is ${cooked}")
    endif()
    math(EXPR i "${i} + 1")
    list(GET lines ${i} groups)
    math(EXPR i "${i} + 1")
    list(GET lines ${i} bits)
    if(NOT groups MATCHES "^# ${clip}: keyed at every frame: " OR
       NOT bits MATCHES "^# ${clip}: bits per key \\(bits:channels\\): translation ")
      message(FATAL_ERROR "breakdown of '${clip}' is\n  ${groups}\n  ${bits}")
    endif()
    math(EXPR i "${i} + 1")
    math(EXPR rows "${rows} + 1")
  endwhile()
  if(rows EQUAL 0)
    message(FATAL_ERROR "--breakdown printed no rows for ${file}")
  endif()
endfunction()
check_breakdown("${ASSET}")

foreach(bad 0 -1 abc 1e9)
  execute_process(COMMAND "${BENCH}" --metres-per-unit ${bad} "${ASSET}" RESULT_VARIABLE rc OUTPUT_QUIET ERROR_QUIET)
  if(NOT rc EQUAL 2)
    message(FATAL_ERROR "--metres-per-unit ${bad}: exit status ${rc}, expected 2 (usage)")
  endif()
endforeach()
