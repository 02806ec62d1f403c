// edit_distance.h — the Levenshtein distance behind every "did you mean" ossa prints: a mistyped
// command-line option (tools/cli/cli.h) and a misspelt key in a graph, settings or events file
// (cooker/json/json_check.h). One definition, so both suggest by the same measure.
//
// Cost: O(|a| * |b|) time, one row of |b| + 1 counters.
#pragma once
#include <algorithm>
#include <cstddef>
#include <string_view>
#include <vector>

namespace ossa {

/// Insertions, deletions and substitutions each cost 1.
inline size_t edit_distance(std::string_view a, std::string_view b) {
  // One row of the dynamic-programming table at a time.
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

}  // namespace ossa
