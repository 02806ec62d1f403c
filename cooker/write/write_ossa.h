// write_ossa.h — serialize a cooked scene into .ossa bytes (FlatBuffers), deterministically.
//
// Tables are created in a fixed order from ordered containers, vertex/index/texture byte vectors are
// aligned to 16 with ForceVectorAlignment (flatc 2.0.8 parses force_align on vectors but does not
// generate it), and nothing time- or address-dependent is written. The result verifies with
// ossa::verify_buffer.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "cooker/clip/clip_compress.h"
#include "cooker/model/graph_def.h"
#include "cooker/model/input_log.h"
#include "cooker/mesh/mesh_build.h"
#include "cooker/model/source_scene.h"

namespace ossa::cook {

struct WriteProvenance {
  std::string source_name;            // file name only
  uint64_t source_hash = 0;           // input_hash of the source file
  std::string options;                // canonical option string
  std::vector<InputFile> inputs;      // every file read, relative to the input's directory, sorted
  uint64_t cook_key = 0;              // cook_key(inputs, options)
  std::vector<std::string> warnings;  // the cook's, paths relative to the input's directory
};

struct WriteOptions {
  bool include_skeleton = true;      // false for clip-only files cooked against --skeleton
  std::span<const GraphDef> graphs;  // animation graphs (a character cooked from a graph file)
};

/// Serializes. `clips` are the compressed forms of scene.clips (same order); they are tagged with
/// the hash of scene.skeleton. O(output size).
std::vector<uint8_t> write_ossa(const SourceScene& scene, std::span<const CookedMesh> meshes,
                                std::span<const CompressedClip> clips, const WriteProvenance& provenance,
                                const WriteOptions& options);

}  // namespace ossa::cook
