// write_montage.h — the montage half of a graph's serialization (format v9): slot nodes and the
// Graph.montages vector, written from their GraphDef form (graph_def.h) one to one.
//
// Kept beside write_ossa.cpp rather than inside it so the montage tables, which grow with their
// feature, do not make the writer of everything else longer.
#pragma once
#include <flatbuffers/flatbuffers.h>

#include "cooker/model/graph_def.h"
#include <ossa/format/ossa_generated.h>

namespace ossa::cook {

/// A SlotNode table.
flatbuffers::Offset<fb::SlotNode> write_slot_node(flatbuffers::FlatBufferBuilder& fbb, const SlotDef& slot);

/// Graph.montages; a null offset when the graph has none (so files without montages stay as they were).
flatbuffers::Offset<flatbuffers::Vector<flatbuffers::Offset<fb::Montage>>> write_montages(
    flatbuffers::FlatBufferBuilder& fbb, const std::vector<MontageDef>& montages);

}  // namespace ossa::cook
