// fbx_text.h — the opening every ASCII FBX 7.4 file the tests generate shares (header and global
// settings), so each generator writes only what makes its case: the settings' P: lines and the
// Objects and Connections after them. Assimp reads these as it reads an exporter's file.
#pragma once
#include <string>

namespace ossa::test {

/// An ASCII FBX 7.4 file's header and GlobalSettings holding `properties` (its P: lines, each
/// indented by two tabs and ending in a newline), up to where Objects begin.
inline std::string fbx_ascii_head(const std::string& properties) {
  return "; FBX 7.4.0 project file\nFBXHeaderExtension:  {\n\tFBXHeaderVersion: 1003\n\tFBXVersion: 7400\n}\n"
         "GlobalSettings:  {\n\tVersion: 1000\n\tProperties70:  {\n" +
         properties + "\t}\n}\n";
}

}  // namespace ossa::test
