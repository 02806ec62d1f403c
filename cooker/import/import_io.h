// import_io.h — the file system Assimp sees while the cooker imports: every file an importer
// opens is read whole through read_input (input_log.h), so it is hashed into the cook key, and
// every file it looks for and misses is recorded absent. Writes are refused: an import reads.
//
// Why not Assimp's DefaultIOSystem: it reads behind the cooker's back (a glTF's .bin, an OBJ's
// .mtl), which left those files out of the cache key. Serving each file from memory costs one
// copy of a source the importer reads whole anyway.
//
// Relative paths resolve against the source's folder, never the working directory, so a cook is
// the same from any directory (a LightWave scene names its objects relative to itself or to its
// content folder, and Assimp's LWS importer passes them on as they are).
#pragma once
#include <string>

#include <assimp/IOSystem.hpp>

namespace ossa::cook {

/// An Assimp::IOSystem over the files of the current input log. Assimp owns it once passed to
/// Importer::SetIOHandler.
class LoggedIOSystem : public Assimp::IOSystem {
 public:
  /// `main` is the source being imported: its bytes go through precheck_source
  /// (source_precheck.h) before the importer reads them.
  explicit LoggedIOSystem(std::string main);
  /// Why the main source was refused before the importer saw it; empty when it was not.
  const std::string& refused() const { return refused_; }
  bool Exists(const char* path) const override;
  char getOsSeparator() const override { return '/'; }
  Assimp::IOStream* Open(const char* path, const char* mode) override;
  void Close(Assimp::IOStream* stream) override;

 private:
  /// A relative path against the main source's folder, never the working directory: the importer
  /// is given the source's absolute path, so every path it builds from it is absolute, and only
  /// those a scene names as they are (LightWave's LoadObjectLayer) stay relative.
  std::string resolve(const char* path) const;

  std::string main_;    // absolute, lexically normal
  std::string folder_;  // main_'s folder
  std::string refused_;
};

}  // namespace ossa::cook
