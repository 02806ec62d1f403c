# ossaCook.cmake — ossa_cook(): cooking as a build step of a game's CMake project.
#
#   find_package(ossa CONFIG REQUIRED)      # includes this file, finds ossa-cook
#   ossa_cook(characters
#     SOURCES   assets/Pab/skeleton.fbx assets/Pab/pab.graph.json assets/Fox/Fox.glb
#     OUTPUT_DIR ${CMAKE_BINARY_DIR}/cooked
#     ROOT      ${CMAKE_SOURCE_DIR}/assets)  # outputs mirror paths under ROOT (else OUTPUT_DIR/<stem>.ossa)
#   ossa_cook(clips
#     SOURCES   assets/Pab/walk.fbx assets/Pab/run.fbx
#     OUTPUT_DIR ${CMAKE_BINARY_DIR}/cooked ROOT ${CMAKE_SOURCE_DIR}/assets
#     SKELETON  ${CMAKE_BINARY_DIR}/cooked/Pab/skeleton.ossa   # cooked against this rig
#     OPTIONS   --clip-tolerance 0.05)
#   add_dependencies(game characters clips)  # or ALL; ${characters_OUTPUTS} lists the files
#
# One custom command per source, so a build re-cooks exactly the outputs whose inputs changed: each
# command writes a depfile (ossa-cook --depfile) naming every file its cook read — the source, a
# glTF's buffers, textures, event sidecars, a graph's sources, the reference rig — and Ninja or
# Make reads it back (add_custom_command DEPFILE, CMake >= 3.20, policy CMP0116 NEW so the paths
# are rewritten for the build tool). A command that runs although nothing it read changed (a file
# touched, not edited) leaves its output untouched, by its cook key, and CMake's restat makes
# the build tool see that and skip what depends on it.
#
# OSSA_COOK_EXECUTABLE names the cooker; the package config sets it to the installed ossa-cook.

if(CMAKE_VERSION VERSION_LESS 3.20)
  message(FATAL_ERROR "ossa_cook() needs CMake 3.20 or newer (add_custom_command DEPFILE with every generator)")
endif()

function(ossa_cook target)
  cmake_parse_arguments(PARSE_ARGV 1 ARG "ALL" "OUTPUT_DIR;ROOT;SKELETON" "SOURCES;OPTIONS")
  if(ARG_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "ossa_cook(${target}): unknown arguments ${ARG_UNPARSED_ARGUMENTS}")
  endif()
  if(NOT ARG_SOURCES OR NOT ARG_OUTPUT_DIR)
    message(FATAL_ERROR "ossa_cook(${target}): SOURCES and OUTPUT_DIR are required")
  endif()
  if(NOT OSSA_COOK_EXECUTABLE)
    message(FATAL_ERROR "ossa_cook(${target}): no cooker: OSSA_COOK_EXECUTABLE is not set and no ossa-cook was "
                        "found. A runtime-only package (-DOSSA_RUNTIME_ONLY=ON) installs no cooker: point "
                        "-DOSSA_COOK_EXECUTABLE=/path/to/ossa-cook at one from a full build or install, or put it "
                        "on PATH (docs/BUILD.md)")
  endif()
  get_filename_component(out_dir "${ARG_OUTPUT_DIR}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_BINARY_DIR}")
  set(common -o "${out_dir}" -q)
  set(extra_depends)
  if(ARG_ROOT)
    get_filename_component(root "${ARG_ROOT}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
    list(APPEND common --root "${root}")
  endif()
  if(ARG_SKELETON)
    get_filename_component(skeleton "${ARG_SKELETON}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_BINARY_DIR}")
    list(APPEND common --skeleton "${skeleton}")
    list(APPEND extra_depends "${skeleton}")  # orders the rig's cook first when it is an output too
  endif()

  set(outputs)
  foreach(source IN LISTS ARG_SOURCES)
    get_filename_component(src "${source}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
    # The output path ossa-cook will choose (cooker/cli/batch.h: output_stem, --root mirroring).
    get_filename_component(name "${src}" NAME)
    string(TOLOWER "${name}" lower)
    if(lower MATCHES "\\.graph\\.json$")
      string(LENGTH "${name}" n)
      math(EXPR n "${n} - 11")
      string(SUBSTRING "${name}" 0 ${n} stem)
    else()
      get_filename_component(stem "${src}" NAME_WLE)
    endif()
    set(sub "")
    if(ARG_ROOT)
      file(RELATIVE_PATH rel "${root}" "${src}")
      if(rel MATCHES "^\\.\\./")
        message(FATAL_ERROR "ossa_cook(${target}): ${src} is not inside ROOT ${root}")
      endif()
      get_filename_component(sub "${rel}" DIRECTORY)
    endif()
    if(sub)
      set(output "${out_dir}/${sub}/${stem}.ossa")
      set(depfile "${CMAKE_CURRENT_BINARY_DIR}/ossa_cook/${target}/${sub}/${stem}.d")
    else()
      set(output "${out_dir}/${stem}.ossa")
      set(depfile "${CMAKE_CURRENT_BINARY_DIR}/ossa_cook/${target}/${stem}.d")
    endif()
    cmake_policy(PUSH)
    cmake_policy(SET CMP0116 NEW)
    add_custom_command(
      OUTPUT "${output}"
      COMMAND "${OSSA_COOK_EXECUTABLE}" "${src}" ${common} --depfile "${depfile}" ${ARG_OPTIONS}
      DEPENDS "${src}" ${extra_depends}
      DEPFILE "${depfile}"
      COMMENT "ossa-cook ${name}"
      VERBATIM)
    cmake_policy(POP)
    list(APPEND outputs "${output}")
  endforeach()

  set(all)
  if(ARG_ALL)
    set(all ALL)
  endif()
  add_custom_target(${target} ${all} DEPENDS ${outputs})
  set(${target}_OUTPUTS "${outputs}" PARENT_SCOPE)
endfunction()
