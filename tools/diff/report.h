// report.h — ossa-diff's two renderings of a DiffReport: readable text and JSON.
//
// Kept apart from the comparison (diff.h) so the figures are computed once and rendered twice,
// and so tests can check the JSON a CI job would parse without running the tool. The JSON is the
// documented interface: docs/schemas/ossa-diff.schema.json describes every field and its unit,
// and a CTest test validates real output against it; bump kJsonSchemaVersion when a field changes
// meaning or goes away (adding optional detail does not need it).
//
// Cost: linear in the size of the report (per joint bind figures and per item figures).
#pragma once
#include <string>

#include <nlohmann/json.hpp>

#include "tools/diff/diff.h"

namespace ossa::diff {

inline constexpr int kJsonSchemaVersion = 1;

/// The report as JSON: "schema", "schema_version", old, new, tolerance_mm, same, sections,
/// differences, notes (docs/DIFF.md describes each).
nlohmann::ordered_json to_json(const DiffReport& report);

/// The report as text: a header naming both files, one line per difference
/// ("clips 'walk': joint error 0.31 mm > 0.1 mm (joint 'LeftHand' at 0.4417 s)") and a verdict.
/// verbose adds every compared item's figures and the notes.
std::string to_text(const DiffReport& report, bool verbose);

/// One difference as the line to_text prints for it (without the newline).
std::string difference_line(const Difference& d);

}  // namespace ossa::diff
