// file_browser.cpp — see file_browser.h.
#include "viewer/file_browser.h"
#include "viewer/panel_fit.h"

#include <algorithm>
#include <cctype>
#include <system_error>

#include <imgui.h>

#include "viewer/cook_job.h"

namespace fs = std::filesystem;

namespace ossa::view {
namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

}  // namespace

std::optional<EntryKind> file_kind(const fs::path& path) {
  if (lower(path.extension().string()) == ".ossa") return EntryKind::kOssa;
  if (is_cook_source(path)) return EntryKind::kSource;
  return std::nullopt;
}

void sort_entries(std::vector<BrowserEntry>& entries) {
  std::sort(entries.begin(), entries.end(), [](const BrowserEntry& a, const BrowserEntry& b) {
    const bool fa = a.kind == EntryKind::kFolder, fb = b.kind == EntryKind::kFolder;
    if (fa != fb) return fa;
    const std::string la = lower(a.name), lb = lower(b.name);
    return la != lb ? la < lb : a.name < b.name;
  });
}

std::vector<BrowserEntry> list_folder(const fs::path& folder, std::string& error) {
  std::vector<BrowserEntry> out;
  error.clear();
  std::error_code ec;
  fs::directory_iterator it(folder, fs::directory_options::skip_permission_denied, ec);
  if (ec) {
    error = folder.string() + ": " + ec.message();
    return out;
  }
  for (const fs::directory_iterator end; it != end; it.increment(ec)) {
    if (ec) {
      error = folder.string() + ": " + ec.message();
      break;
    }
    const std::string name = it->path().filename().string();
    if (name.empty() || name.front() == '.') continue;
    std::error_code kind_ec;
    if (it->is_directory(kind_ec)) {
      out.push_back({name, EntryKind::kFolder});
    } else if (const auto kind = file_kind(it->path())) {
      out.push_back({name, *kind});
    }
  }
  sort_entries(out);
  return out;
}

void browse(FileBrowser& browser, const fs::path& folder) {
  std::error_code ec;
  fs::path absolute = fs::absolute(folder, ec);
  browser.folder = (ec ? folder : absolute).lexically_normal();
  if (browser.folder.has_relative_path() && !browser.folder.has_filename())
    browser.folder = browser.folder.parent_path();  // "a/b/" -> "a/b"
  browser.entries = list_folder(browser.folder, browser.error);
}

fs::path start_folder(const std::vector<std::string>& files, const fs::path& cwd) {
  if (!files.empty()) {
    std::error_code ec;
    const fs::path folder = fs::absolute(fs::path(files.front()), ec).parent_path();
    if (!ec && fs::is_directory(folder, ec)) return folder;
  }
  return cwd;
}

std::optional<fs::path> browser_panel(FileBrowser& browser, float* hidden) {
  std::optional<fs::path> chosen;
  ImGui::TextWrapped("%s", browser.folder.string().c_str());
  if (ImGui::SmallButton("Up") && browser.folder.has_parent_path() && browser.folder.parent_path() != browser.folder)
    browse(browser, browser.folder.parent_path());
  ImGui::SameLine();
  if (ImGui::SmallButton("Refresh")) browse(browser, browser.folder);
  ImGui::SameLine();
  ImGui::TextDisabled("%zu entries", browser.entries.size());
  if (!browser.error.empty()) ImGui::TextColored(ImVec4(1.0f, 0.4f, 0.4f, 1.0f), "%s", browser.error.c_str());
  const float rows = static_cast<float>(browser.entries.size()) + 1.5f;  // [..] and a half row of margin
  if (ImGui::BeginListBox("##files", ImVec2(-1.0f, fill_list_height(rows, 0.0f, hidden)))) {
    std::optional<fs::path> into;  // browsed after the loop: the listing is not changed while drawn
    if (ImGui::Selectable("[..]")) into = browser.folder.parent_path();
    for (const BrowserEntry& e : browser.entries) {
      const char* tag = e.kind == EntryKind::kFolder ? "[dir] " : e.kind == EntryKind::kOssa ? "" : "[cook] ";
      const std::string label = tag + e.name;
      if (ImGui::Selectable(label.c_str())) {
        if (e.kind == EntryKind::kFolder) into = browser.folder / e.name;
        else chosen = browser.folder / e.name;
      }
      if (e.kind == EntryKind::kSource && ImGui::IsItemHovered())
        ImGui::SetTooltip("cook with ossa-cook in the background, then open");
    }
    ImGui::EndListBox();
    if (into) browse(browser, *into);
  }
  return chosen;
}

}  // namespace ossa::view
