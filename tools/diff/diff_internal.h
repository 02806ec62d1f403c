// diff_internal.h — what the section comparisons of ossa-diff share (not part of the library's
// interface): the context each section writes into, the unit conversions, name matching, and the
// joint mapping the skeleton and clip comparisons both use.
//
// One header for the helpers rather than one per section: each section file (diff_skeleton.cpp,
// diff_meshes.cpp, diff_clips.cpp, diff_content.cpp) is one function over the same context, and
// the joint mapping must be the same one for the bind pose and for the clips so a renamed joint is
// paired the same way in both.
#pragma once
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <ossa/format/result.h>
#include <ossa/loader/asset.h>
#include "tools/diff/diff.h"

namespace ossa::diff::internal {

/// What every section comparison reads and writes.
struct Context {
  const Asset& old_asset;
  const Asset& new_asset;
  const Asset* old_rig;  // skeleton files for clip-only sides (may be null)
  const Asset* new_rig;
  double tolerance_mm;
  DiffReport& report;

  /// Millimetres per file unit of each side (1000 * metres_per_unit).
  double old_mm() const { return 1000.0 * report.old_file.metres_per_unit; }
  double new_mm() const { return 1000.0 * report.new_file.metres_per_unit; }
  /// The probe distance in the old file's units (the measure runs in old units, new side scaled).
  double probe_old_units() const { return kProbeMetres / report.old_file.metres_per_unit; }
  /// Factor taking a length in new units to old units.
  double new_to_old() const { return report.new_file.metres_per_unit / report.old_file.metres_per_unit; }

  void add(Difference d) { report.differences.push_back(std::move(d)); }
  /// A figure over its limit.
  void add_figure(const char* section, std::string item, std::string what, double value, const char* unit, double limit,
                  std::string detail = {}) {
    add(Difference{section, std::move(item), std::move(what), value, {}, unit, limit, std::move(detail)});
  }
  /// A change without a figure (a name, a count, presence).
  void add_text(const char* section, std::string item, std::string what, std::string text, std::string detail = {}) {
    add(Difference{section, std::move(item), std::move(what), std::nullopt, std::move(text), "", std::nullopt,
                   std::move(detail)});
  }
};

/// Items of two lists paired by name: the k-th item called N on one side with the k-th called N on
/// the other (names may repeat or be empty). O(n log n).
struct NameMatch {
  std::vector<std::pair<size_t, size_t>> pairs;  // (old index, new index), in old order
  std::vector<size_t> only_old, only_new;        // indices, ascending
};
NameMatch match_by_name(const std::vector<std::string>& old_names, const std::vector<std::string>& new_names);

/// How an item is called in messages: its name, "#k" appended for the k-th repeat (k >= 1), or
/// "#index" when it has no name. Made printable (runtime/message.h).
std::string item_label(const std::vector<std::string>& names, size_t index);

/// Adds "added" / "removed" differences for unmatched items and fills the section's name lists.
void report_added_removed(Context& c, const char* section, const NameMatch& m,
                          const std::vector<std::string>& old_names, const std::vector<std::string>& new_names,
                          std::vector<std::string>& added, std::vector<std::string>& removed);

/// Joints of two rigs paired: by name first, then an unpaired joint at the same index as an
/// unpaired joint of the other rig, under the same (paired) parent, counts as renamed.
struct JointMapping {
  std::vector<int> old_to_new;               // -1: no counterpart
  std::vector<std::pair<int, int>> renamed;  // (old, new)
};
JointMapping map_joints(const SkeletonView& old_skeleton, const SkeletonView& new_skeleton);

/// "%.4g"-style number text used in details.
std::string num(double value);
/// Printable, quoted name: 'Hips'.
std::string quote_name(std::string_view name);

// The sections. Each fills its part of c.report and adds its differences.
void compare_skeletons(Context& c);
void compare_meshes(Context& c);
/// Error when a side has clips but no skeleton they bind to (clip-only file without --skeleton).
Status compare_clips(Context& c);
void compare_materials(Context& c);
void compare_graphs(Context& c);

}  // namespace ossa::diff::internal
