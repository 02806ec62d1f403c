# relax_flatc_version.cmake — run as `cmake -DINPUT=flatc-output.h -DOUTPUT=installed.h -P ...`.
#
# flatc 2.0.8 ends its generated header's preamble with a static_assert that the including
# program uses FlatBuffers 2.0.8 exactly. The header is installed for games, whose FlatBuffers may
# be any 2.x patch release: what ossa.fbs needs (tables, structs, scoped enums, vectors of
# structs) is in every FlatBuffers 2.0 and later, so the check is rewritten to ask for that and
# nothing more. Fails loudly if flatc's output no longer has the expected check, so a flatc
# upgrade cannot silently change what is installed.
cmake_minimum_required(VERSION 3.25)
file(READ "${INPUT}" text)
string(CONCAT pattern "static_assert\\(FLATBUFFERS_VERSION_MAJOR == [0-9]+ &&[ \t\r\n]+"
       "FLATBUFFERS_VERSION_MINOR == [0-9]+ &&[ \t\r\n]+FLATBUFFERS_VERSION_REVISION == [0-9]+,[ \t\r\n]+"
       "\"Non-compatible flatbuffers version included\"\\);")
string(REGEX MATCH "${pattern}" found "${text}")
if(found)
  string(CONCAT relaxed "static_assert(FLATBUFFERS_VERSION_MAJOR >= 2,\n"
         "              \"ossa's schema needs FlatBuffers 2.0 or newer\");")
  string(REGEX REPLACE "${pattern}" "${relaxed}" text "${text}")
elseif(NOT text MATCHES "FLATBUFFERS_VERSION_MAJOR >= 2")
  string(FIND "${text}" "FLATBUFFERS_VERSION_REVISION" pinned)
  if(NOT pinned EQUAL -1)
    message(FATAL_ERROR "${INPUT}: flatc's version check has an unexpected form; update relax_flatc_version.cmake")
  endif()
endif()
file(WRITE "${OUTPUT}" "${text}")
