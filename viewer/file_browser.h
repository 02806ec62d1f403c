// file_browser.h — the panel's file browser: folders, cooked .ossa files and the sources the
// cooker accepts, so a first-time user can find something to look at without a command line.
//
// Split in two: list_folder (and the sorting and filtering it uses) is plain std::filesystem, so
// tests/viewer/viewer_unit_test.cpp checks what is listed and in which order; browser_panel draws the
// listing with ImGui and reports a click. The listing is read when the folder changes (or on
// Refresh), never once a frame: a network folder must not stall drawing.
//
// Order: ".." first, then folders, then files, each by name ignoring case ("Fox" beside "fox"),
// so a folder of assets reads like a file manager's. Hidden entries (a leading '.') and other
// files are left out.
#pragma once
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace ossa::view {

enum class EntryKind { kFolder, kOssa, kSource };

struct BrowserEntry {
  std::string name;  // the file name, no folder
  EntryKind kind = EntryKind::kFolder;
};

/// What kind of entry `path` is by its name alone (kOssa: .ossa; kSource: is_cook_source), or
/// nullopt for a file the viewer cannot use. Folders are not told by name: list_folder asks.
std::optional<EntryKind> file_kind(const std::filesystem::path& path);

/// Folders first, then files, by case-insensitive name (ties: byte order).
void sort_entries(std::vector<BrowserEntry>& entries);

/// The folders, .ossa files and cooker sources in `folder`, sorted (sort_entries), hidden entries
/// left out. Errors (a folder that cannot be read) go to `error`, with what could be read kept.
std::vector<BrowserEntry> list_folder(const std::filesystem::path& folder, std::string& error);

struct FileBrowser {
  std::filesystem::path folder;  // absolute
  std::vector<BrowserEntry> entries;
  std::string error;
  bool open_section = false;  // the panel's "Files" section starts open (--browse)
};

/// Moves to `folder` (made absolute) and reads its listing.
void browse(FileBrowser& browser, const std::filesystem::path& folder);

/// The folder a session starts browsing in: the first opened file's folder, else `cwd`.
std::filesystem::path start_folder(const std::vector<std::string>& files, const std::filesystem::path& cwd);

/// Draws the browser (inside the panel). Returns the file clicked this frame (an .ossa to open
/// or a source to cook); a click on a folder or ".." browses into it.
/// The list fills the height the panel's section has left (panel_fit.h fill_list_height); the rows
/// it cannot show are added to `*hidden`.
std::optional<std::filesystem::path> browser_panel(FileBrowser& browser, float* hidden);

}  // namespace ossa::view
