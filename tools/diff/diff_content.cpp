// diff_content.cpp — the material and graph sections of ossa-diff.
//
// Materials are matched by name and compared by their parameters and their textures (role, path,
// MIME type, and the FNV-1a 64 hash of embedded bytes: a re-encoded image is a changed image).
// Graphs are compared structurally through ossa-inspect's description of them (describe.h) — the
// parameters with types and defaults, the clips they play, node kinds and counts, state machines
// with their states, entries and transitions with conditions in readable form — so "the graphs
// are the same" means "ossa-inspect prints them the same", and each named part that changed is
// reported. Reusing that description keeps one reading of the Graph table for both tools.
#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <ossa/format/hash.h>
#include "common/message.h"
#include "tools/diff/diff_internal.h"
#include "tools/inspect/describe.h"

namespace ossa::diff::internal {
namespace {

constexpr double kParameterEpsilon = 1e-6;  // colours, shininess and opacity closer than this are equal

std::string str(const flatbuffers::String* s) { return std::string(flatbuffers::GetStringView(s)); }

std::vector<TextureFact> textures_of(const fb::Material& m) {
  std::vector<TextureFact> out;
  if (const auto* textures = m.textures()) {
    for (const fb::Texture* t : *textures) {
      TextureFact f;
      f.role = fb::EnumNameTextureRole(t->role());
      f.path = str(t->path());
      f.mime = str(t->mime());
      f.encoding = fb::EnumNameTextureEncoding(t->encoding());
      f.srgb = t->srgb();
      f.width = t->width();
      f.height = t->height();
      f.mips = t->mip_count();
      if (const auto* data = t->data()) {
        f.bytes = data->size();
        f.hash = hash_bytes(data->data(), data->size());
      }
      out.push_back(std::move(f));
    }
  }
  return out;
}

const fb::Vec3 kBlack(0.0f, 0.0f, 0.0f);  // an absent emissive colour

double vec_delta(const fb::Vec3* a, const fb::Vec3* b) {
  if (!a || !b) return a == b ? 0.0 : INFINITY;
  return std::max(
      {std::fabs(double(a->x()) - b->x()), std::fabs(double(a->y()) - b->y()), std::fabs(double(a->z()) - b->z())});
}

MaterialItem compare_material(Context& c, const std::string& label, const fb::Material& a, const fb::Material& b) {
  MaterialItem item;
  item.name = label;
  item.old_textures = textures_of(a);
  item.new_textures = textures_of(b);
  const auto changed = [&](std::string what, std::string text) {
    item.changed.push_back(what);
    c.add_text("materials", label, std::move(what), std::move(text));
  };
  const struct {
    const char* name;
    const fb::Vec3 *x, *y;
  } colours[] = {{"ambient", a.ambient(), b.ambient()},
                 {"diffuse", a.diffuse(), b.diffuse()},
                 {"specular", a.specular(), b.specular()},
                 {"emissive", a.emissive() ? a.emissive() : &kBlack, b.emissive() ? b.emissive() : &kBlack}};
  for (const auto& col : colours)
    if (vec_delta(col.x, col.y) > kParameterEpsilon)
      changed(col.name, "largest component change " + num(vec_delta(col.x, col.y)));
  if (std::fabs(a.shininess() - b.shininess()) > kParameterEpsilon)
    changed("shininess", num(a.shininess()) + " -> " + num(b.shininess()));
  if (std::fabs(a.opacity() - b.opacity()) > kParameterEpsilon)
    changed("opacity", num(a.opacity()) + " -> " + num(b.opacity()));
  const auto pbr_text = [](const fb::PbrFactors* p) {
    return p ? "metallic " + num(p->metallic()) + ", roughness " + num(p->roughness()) : std::string("none (Phong)");
  };
  if ((a.pbr() == nullptr) != (b.pbr() == nullptr) ||
      (a.pbr() && (std::fabs(a.pbr()->metallic() - b.pbr()->metallic()) > kParameterEpsilon ||
                   std::fabs(a.pbr()->roughness() - b.pbr()->roughness()) > kParameterEpsilon)))
    changed("pbr", pbr_text(a.pbr()) + " -> " + pbr_text(b.pbr()));
  const auto &ta = item.old_textures, &tb = item.new_textures;
  if (ta.size() != tb.size())
    changed("textures", std::to_string(ta.size()) + " -> " + std::to_string(tb.size()) + " textures");
  for (size_t i = 0; i < std::min(ta.size(), tb.size()); ++i) {
    const std::string which = "texture " + std::to_string(i) + " (" + ta[i].role + ")";
    if (ta[i].role != tb[i].role) changed(which + " role", ta[i].role + " -> " + tb[i].role);
    if (ta[i].path != tb[i].path) changed(which + " path", quote_name(ta[i].path) + " -> " + quote_name(tb[i].path));
    if (ta[i].mime != tb[i].mime) changed(which + " mime", quote_name(ta[i].mime) + " -> " + quote_name(tb[i].mime));
    const auto shape = [](const TextureFact& t) {
      return t.encoding + (t.srgb ? " sRGB " : " ") + std::to_string(t.width) + " x " + std::to_string(t.height) +
             ", " + std::to_string(t.mips) + " mips";
    };
    if (shape(ta[i]) != shape(tb[i])) changed(which + " encoding", shape(ta[i]) + " -> " + shape(tb[i]));
    if (ta[i].bytes != tb[i].bytes || ta[i].hash != tb[i].hash)
      changed(which + " data",
              std::to_string(ta[i].bytes) + " bytes -> " + std::to_string(tb[i].bytes) + " bytes, " +
                  detail::format("hash %016llx -> %016llx", static_cast<unsigned long long>(ta[i].hash),
                                 static_cast<unsigned long long>(tb[i].hash)));
  }
  return item;
}

using json = nlohmann::ordered_json;

std::vector<std::string> names_in(const json& list, const char* key) {
  std::vector<std::string> out;
  for (const json& e : list) out.push_back(key ? e.value(key, std::string()) : e.get<std::string>());
  return out;
}

GraphShape shape_of(const json& g) {
  GraphShape s;
  s.parameters = g["parameters"].size();
  s.clips = g["clips"].size();
  s.nodes = g["node_count"].get<size_t>();
  s.machines = g["machines"].size();
  for (const json& m : g["machines"]) {
    s.states += m["states"].size();
    s.transitions += m["transitions"].size();
  }
  return s;
}

/// Elements of a named list (by `key`), paired by name, reported when added, removed or changed.
void compare_named(const json& a, const json& b, const char* key, const std::string& kind,
                   std::vector<std::string>& changed) {
  const std::vector<std::string> na = names_in(a, key), nb = names_in(b, key);
  const NameMatch m = match_by_name(na, nb);
  for (size_t i : m.only_old) changed.push_back(kind + " " + quote_name(na[i]) + " removed");
  for (size_t k : m.only_new) changed.push_back(kind + " " + quote_name(nb[k]) + " added");
  for (const auto& [i, k] : m.pairs)
    if (a[i] != b[k]) changed.push_back(kind + " " + quote_name(na[i]) + " changed");
}

GraphItem compare_graph(Context& c, const std::string& label, const json& a, const json& b) {
  GraphItem item;
  item.name = label;
  item.old_shape = shape_of(a);
  item.new_shape = shape_of(b);
  compare_named(a["parameters"], b["parameters"], "name", "parameter", item.changed);
  if (a["clips"] != b["clips"]) item.changed.push_back("clip list changed");
  if (a["node_count"] != b["node_count"] || a["nodes"] != b["nodes"])
    item.changed.push_back("nodes " + a["nodes"].dump() + " -> " + b["nodes"].dump());
  compare_named(a["machines"], b["machines"], "name", "state machine", item.changed);
  compare_named(a.value("montages", json::array()), b.value("montages", json::array()), "name", "montage",
                item.changed);
  // Anything the named parts above do not show (the order of parameters or machines, the rig).
  if (item.changed.empty() && a != b) item.changed.push_back("structure changed");
  item.same = item.changed.empty();
  for (const std::string& what : item.changed) c.add_text("graphs", label, "structure", what);
  return item;
}

}  // namespace

void compare_materials(Context& c) {
  MaterialSection& out = c.report.materials;
  out.old_count = c.old_asset.material_count();
  out.new_count = c.new_asset.material_count();
  std::vector<std::string> old_names, new_names;
  for (size_t i = 0; i < out.old_count; ++i) old_names.push_back(str(c.old_asset.material(i).name()));
  for (size_t k = 0; k < out.new_count; ++k) new_names.push_back(str(c.new_asset.material(k).name()));
  const NameMatch m = match_by_name(old_names, new_names);
  report_added_removed(c, "materials", m, old_names, new_names, out.added, out.removed);
  for (const auto& [i, k] : m.pairs)
    out.items.push_back(
        compare_material(c, item_label(old_names, i), c.old_asset.material(i), c.new_asset.material(k)));
}

void compare_graphs(Context& c) {
  GraphSection& out = c.report.graphs;
  const json a = inspect::describe(c.old_asset, "").value("graphs", json::array());
  const json b = inspect::describe(c.new_asset, "").value("graphs", json::array());
  out.old_count = a.size();
  out.new_count = b.size();
  const std::vector<std::string> old_names = names_in(a, "name"), new_names = names_in(b, "name");
  const NameMatch m = match_by_name(old_names, new_names);
  report_added_removed(c, "graphs", m, old_names, new_names, out.added, out.removed);
  for (const auto& [i, k] : m.pairs) out.items.push_back(compare_graph(c, item_label(old_names, i), a[i], b[k]));
}

}  // namespace ossa::diff::internal
