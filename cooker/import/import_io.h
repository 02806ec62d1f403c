// import_io.h — the file system Assimp sees while the cooker imports: every file an importer
// opens is read whole through read_input (input_log.h), so it is hashed into the cook key, and
// every file it looks for and misses is recorded absent. Writes are refused: an import reads.
//
// Why not Assimp's DefaultIOSystem: it reads behind the cooker's back (a glTF's .bin, an OBJ's
// .mtl), which left those files out of the cache key. Serving each file from memory costs one
// copy of a source the importer reads whole anyway.
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
  std::string main_;     // absolute, lexically normal
  std::string refused_;
};

}  // namespace ossa::cook
