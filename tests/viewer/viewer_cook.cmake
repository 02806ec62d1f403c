# viewer_cook.cmake — the viewer tests' fixture: cooks the repo's samples the way scripts/demo.sh
# does (characters, the Pab clips and mesh against the cooked Pab skeleton, the Pab graph into
# Pab/pab.ossa), plus float32 vertex cooks of the glTF characters, into OUT. Run as
#   cmake -DCOOK=ossa-cook -DASSETS=assets -DOUT=dir -P viewer_cook.cmake
cmake_minimum_required(VERSION 3.25)
file(REMOVE_RECURSE "${OUT}")
function(cook)
  execute_process(COMMAND "${COOK}" --quiet ${ARGN} RESULT_VARIABLE rc ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "ossa-cook ${ARGN} failed (${rc}): ${err}")
  endif()
endfunction()
cook("${ASSETS}/Pab/skeleton.fbx" "${ASSETS}/CesiumMan" "${ASSETS}/CapedMan" "${ASSETS}/Fox" "${ASSETS}/RiggedSimple"
     --root "${ASSETS}" -o "${OUT}/quantized")
cook("${ASSETS}/Pab/arnaud.fbx" "${ASSETS}/Pab/walk.fbx" "${ASSETS}/Pab/jog.fbx" "${ASSETS}/Pab/run.fbx"
     "${ASSETS}/Pab/crossarms.fbx" --skeleton "${OUT}/quantized/Pab/skeleton.ossa" --root "${ASSETS}"
     -o "${OUT}/quantized")
cook("${ASSETS}/Pab/pab.graph.json" --root "${ASSETS}" -o "${OUT}/quantized")
cook("${ASSETS}/CesiumMan" "${ASSETS}/Fox" "${ASSETS}/RiggedSimple" --float-vertices --root "${ASSETS}" -o "${OUT}/float")
# The textured characters with their textures kept as the source's PNG / JPEG bytes, and as
# uncompressed RGBA8 chains, for tests/viewer/viewer_texture_test.cpp to compare with the BC cooks above.
cook("${ASSETS}/CesiumMan" "${ASSETS}/Fox" --texture-format source --root "${ASSETS}" -o "${OUT}/source-textures")
cook("${ASSETS}/CesiumMan" "${ASSETS}/Fox" --texture-format rgba8 --root "${ASSETS}" -o "${OUT}/rgba8-textures")
