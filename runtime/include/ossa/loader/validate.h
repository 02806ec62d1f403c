// validate.h — the semantic invariants of a .ossa file that FlatBuffers' verifier cannot see.
//
// The verifier proves every offset and vector lies inside the buffer; this proves the data means
// something a reader can act on without further checks: parents[i] < i, all per-joint arrays the
// same length, the stored hash equals the recomputed one, layouts inside the stride with known
// formats, vertex/index byte sizes consistent with counts, indices < vertex_count, submeshes inside
// the index range with valid materials, joint slots < slot count and slots -> joints < joint count,
// compressed clips (format v2) that a sampler can decode without a single check: sample rate > 0,
// 1..65536 frames, duration = (frames - 1) / rate; constant and animated channels each sorted by
// (joint, channel), disjoint, joints < the clip's joint count, known channels; every animated
// channel with >= 2 keys whose frames lie inside key_frames, strictly increase from 0 to the last
// frame, whose bits are 1..19 or 32, whose dropped rotation component is 0..3, and whose packed
// keys lie inside key_values before its 8 padding bytes; finite ranges, raw-float keys finite,
// rotation components inside [-1, 1] (up to rounding); constants finite, rotation constants
// normalizable; root motion one finite sample
// per frame. Runs after verification; never reads out of bounds.
//
// Also checked, because a reader relies on them: pose values (bind translations and scales,
// clip constants, ranges and raw keys) within 1e7 so pose arithmetic cannot overflow; metres_per_unit finite and > 0;
// joint names non-empty; bind pose and inverse binds finite, rotations normalizable (also for keys); vertex stride a
// multiple of 4 and attribute offsets aligned to their component size (so CPU decoding reads aligned data); Joints uses
// an integer format and nothing else does; Position has >= 3 components and is present when there are vertices; Joints
// needs Weights, joint slots and every slot < slot count (and Weights needs Joints); a mesh with joint slots needs a
// skeleton in the same file; a clip bound (by hash) to the file's skeleton has its joint count; submesh index counts
// are multiples of 3 and materials < max(1, material count); textures have a known role and embedded data or a path;
// vertex, index and texture bytes are 16-byte aligned in memory; a cooked texture has a known encoding, sides
// of 1..kMaxTextureSide, 1 to a full chain of mip levels and exactly that chain's bytes (texture.h); a mesh's cloth
// (format v9) passes check_cloth (ossa/anim/cloth.h) against the mesh's vertex count and the skeleton's joint count.
#pragma once
#include <cstddef>
#include <string_view>

#include <ossa/format/ossa_generated.h>
#include <ossa/format/result.h>

namespace ossa {

/// Semantic checks over a verified File. `name` prefixes messages, which also name the mesh,
/// clip, joint or field at fault. O(joints + keys + indices + vertices*joint-slot checks).
/// `buffer_size`, the size of the verified buffer holding `file`, bounds the work on a crafted
/// file whose tables share one big vector many times (FlatBuffers tables form a DAG): the checks
/// scan at most ~4 x buffer_size bytes of vector data and reject a file that would need more,
/// which a file without shared vectors never does. 0 = no bound (trusted callers only).
/// verify_buffer passes it. Vertex/index/texture data must be 16-byte aligned in memory.
Status validate_file(const fb::File& file, std::string_view name, size_t buffer_size = 0);

/// Procedural graph nodes (format v6): joints per spring chain, legs per foot placement or lock node.
inline constexpr uint32_t kMaxSpringJoints = 64;
inline constexpr uint32_t kMaxFootLegs = 8;

/// The graph checks (validate_graph.cpp), run by validate_file for each of File.graphs: every index
/// in range (parameters, clips, joints, nodes, machines, states), parameter types fit their uses,
/// nodes children first with one referrer each and at most kMaxGraphDepth levels deep, each
/// machine played by one node, finite numbers, sane durations, conditions well formed with a stack
/// of at most 16. `budget` (bytes of vector data still allowed to be scanned) is charged.
inline constexpr uint32_t kMaxGraphDepth = 64;
Status validate_graph(const fb::Graph& graph, size_t index, std::string_view name, uint64_t& budget);

}  // namespace ossa
