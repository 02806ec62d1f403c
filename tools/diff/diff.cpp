// diff.cpp — ossa-diff's entry points (diff.h) and the helpers its sections share
// (diff_internal.h): opening the files, the file facts, name matching and the joint mapping.
//
// Files are opened with Asset::open, the loader a game uses, so "ossa-diff compared them" implies
// "the runtime loads both", and a file it refuses is reported with the loader's own message.
#include "tools/diff/diff.h"

#include <algorithm>
#include <cstdio>
#include <map>
#include <string_view>
#include <unordered_map>

#include "common/message.h"
#include "tools/diff/diff_internal.h"

namespace ossa::diff {
namespace internal {

NameMatch match_by_name(const std::vector<std::string>& old_names, const std::vector<std::string>& new_names) {
  // Per name, the queue of new indices not yet taken, in order.
  std::map<std::string_view, std::vector<size_t>> pending;
  for (size_t i = new_names.size(); i-- > 0;) pending[new_names[i]].push_back(i);
  NameMatch m;
  std::vector<bool> taken(new_names.size(), false);
  for (size_t i = 0; i < old_names.size(); ++i) {
    auto it = pending.find(old_names[i]);
    if (it == pending.end() || it->second.empty()) {
      m.only_old.push_back(i);
      continue;
    }
    const size_t k = it->second.back();
    it->second.pop_back();
    taken[k] = true;
    m.pairs.emplace_back(i, k);
  }
  for (size_t k = 0; k < new_names.size(); ++k)
    if (!taken[k]) m.only_new.push_back(k);
  return m;
}

std::string item_label(const std::vector<std::string>& names, size_t index) {
  // Strings built with += (GCC 12's false -Wrestrict on "literal" + std::string&& at -O2/-O3).
  if (names[index].empty()) {
    std::string label = "#";
    label += std::to_string(index);
    return label;
  }
  const auto repeats = std::count(names.begin(), names.begin() + static_cast<std::ptrdiff_t>(index), names[index]);
  std::string label = ossa::detail::printable(names[index]);
  return repeats > 0 ? label + "#" + std::to_string(repeats) : label;
}

void report_added_removed(Context& c, const char* section, const NameMatch& m,
                          const std::vector<std::string>& old_names, const std::vector<std::string>& new_names,
                          std::vector<std::string>& added, std::vector<std::string>& removed) {
  for (size_t i : m.only_old) {
    removed.push_back(item_label(old_names, i));
    c.add_text(section, removed.back(), "removed", "only in the old file");
  }
  for (size_t k : m.only_new) {
    added.push_back(item_label(new_names, k));
    c.add_text(section, added.back(), "added", "only in the new file");
  }
}

JointMapping map_joints(const SkeletonView& old_skeleton, const SkeletonView& new_skeleton) {
  const size_t n_old = old_skeleton.joint_count(), n_new = new_skeleton.joint_count();
  JointMapping m;
  m.old_to_new.assign(n_old, -1);
  std::vector<bool> taken(n_new, false);
  std::unordered_map<std::string_view, int> by_name;
  for (size_t k = n_new; k-- > 0;) by_name[new_skeleton.joint_name(k)] = static_cast<int>(k);  // first wins
  for (size_t i = 0; i < n_old; ++i) {
    const auto it = by_name.find(old_skeleton.joint_name(i));
    if (it != by_name.end() && !taken[static_cast<size_t>(it->second)]) {
      m.old_to_new[i] = it->second;
      taken[static_cast<size_t>(it->second)] = true;
    }
  }
  // Renames: parents come first (parents[i] < i), so a renamed parent is already paired when its
  // children are looked at, and a renamed chain is found top-down.
  const auto old_parents = old_skeleton.parents();
  const auto new_parents = new_skeleton.parents();
  for (size_t i = 0; i < n_old && i < n_new; ++i) {
    if (m.old_to_new[i] >= 0 || taken[i]) continue;
    const int p_old = old_parents[i], p_new = new_parents[i];
    const bool same_parent = p_old < 0 ? p_new < 0 : m.old_to_new[static_cast<size_t>(p_old)] == p_new;
    if (!same_parent) continue;
    m.old_to_new[i] = static_cast<int>(i);
    taken[i] = true;
    m.renamed.emplace_back(static_cast<int>(i), static_cast<int>(i));
  }
  return m;
}

std::string num(double value) { return ossa::detail::format("%.4g", value); }

std::string quote_name(std::string_view name) {
  std::string out = "'";
  out += ossa::detail::printable(name);
  out += '\'';
  return out;
}

}  // namespace internal

namespace {

FileFacts file_facts(const Asset& asset) {
  FileFacts f;
  f.path = asset.name();
  f.bytes = asset.bytes().size();
  const fb::File& file = asset.file();
  f.metres_per_unit = file.metres_per_unit();
  f.format_version = file.version();
  if (const fb::Provenance* p = file.provenance()) {
    const auto str = [](const flatbuffers::String* s) { return std::string(flatbuffers::GetStringView(s)); };
    f.source_name = str(p->source_name());
    f.cooker_version = str(p->cooker_version());
    f.options = str(p->options());
    f.source_hash = p->source_hash();
  }
  return f;
}

}  // namespace

Result<DiffReport> diff_assets(const Asset& old_asset, const Asset& new_asset, const Options& options,
                               const Asset* old_rig, const Asset* new_rig) {
  DiffReport report;
  report.old_file = file_facts(old_asset);
  report.new_file = file_facts(new_asset);
  report.tolerance_mm = options.tolerance_mm;
  internal::Context c{old_asset, new_asset, old_rig, new_rig, options.tolerance_mm, report};
  if (report.old_file.metres_per_unit != report.new_file.metres_per_unit)
    report.notes.push_back(
        ossa::detail::format("units differ (%g m per unit -> %g m per unit); lengths are compared in mm",
                             report.old_file.metres_per_unit, report.new_file.metres_per_unit));
  internal::compare_skeletons(c);
  internal::compare_meshes(c);
  if (Status s = internal::compare_clips(c); !s) return s.error();
  internal::compare_materials(c);
  internal::compare_graphs(c);
  return report;
}

Result<DiffReport> diff_files(const std::string& old_path, const std::string& new_path, const Options& options) {
  auto old_asset = Asset::open(old_path);
  if (!old_asset) return old_asset.error();
  auto new_asset = Asset::open(new_path);
  if (!new_asset) return new_asset.error();
  std::optional<Asset> old_rig, new_rig;
  if (!options.old_skeleton.empty()) {
    auto rig = Asset::open(options.old_skeleton);
    if (!rig) return rig.error();
    if (rig->skeleton().empty()) return Error{options.old_skeleton + ": has no skeleton to play clips on"};
    old_rig.emplace(std::move(rig).value());
  }
  if (!options.new_skeleton.empty()) {
    auto rig = Asset::open(options.new_skeleton);
    if (!rig) return rig.error();
    if (rig->skeleton().empty()) return Error{options.new_skeleton + ": has no skeleton to play clips on"};
    new_rig.emplace(std::move(rig).value());
  }
  return diff_assets(*old_asset, *new_asset, options, old_rig ? &*old_rig : nullptr, new_rig ? &*new_rig : nullptr);
}

}  // namespace ossa::diff
