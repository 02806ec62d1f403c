// describe_parts.h — what describe.cpp shares with the files that describe one part of an asset
// each (describe_graph.cpp): the JSON type, its text helpers (hex16 is describe.h's, which
// ossa-diff shares), and the part describers. Internal to tools/inspect; describe.h is the interface.
#pragma once
#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include <ossa/loader/asset.h>
#include "tools/inspect/describe.h"

namespace ossa::inspect::parts {

using json = nlohmann::ordered_json;

using inspect::hex16;  // describe.h

/// A flatbuffers string, or "" for an absent one.
inline std::string str(const flatbuffers::String* s) { return s ? std::string(s->c_str(), s->size()) : std::string(); }

/// An animation graph: parameters, layers, state machines (states, transitions with their
/// conditions in infix form), blend spaces, slots and montages (with their lengths). O(graph size).
json describe_graph(const fb::Graph& g);

}  // namespace ossa::inspect::parts
