// open_beneath.h — opening a file by path so that the path cannot lead outside a set of folders,
// however its links change while it is opened: the read sandbox's primitive (input_log.h), and the
// viewer's for textures a cooked file names by path.
//
// Why not "resolve, check, then open": between the check and the open another process can swap a
// file inside the tree for a symlink to a secret, and the open follows it (a texture race embedded
// a secret in 56-74 of 550 cooks). Here the path is resolved and opened in one step from a
// descriptor of the allowed folder, and every later check reads the opened descriptor (fstat),
// never the path again:
// - openat2(RESOLVE_BENEATH | RESOLVE_NO_MAGICLINKS) where the kernel has it (Linux 5.6; probed
//   once at run time, ENOSYS or a seccomp refusal falls back): the kernel refuses any step that
//   leaves the folder, `..` and symlinks included.
// - Otherwise, and for what RESOLVE_BENEATH refuses but the sandbox allows (an absolute symlink
//   into the tree, a link from the tree into an --allow-dir folder), a walk of our own: one
//   component at a time with openat(O_PATH | O_NOFOLLOW) from the descriptor of the folder above,
//   `..` taken from our own stack of descriptors, and each symlink read (readlinkat on the link's
//   own descriptor) and resolved again by the same rules. Nothing is opened by a path the process
//   did not check itself.
// Non-regular files are seen through an O_PATH descriptor (no driver's open runs, no FIFO blocks)
// and refused; a regular file is then opened for reading by the same resolution and must be the
// same inode. A regular file with more than one link is refused unless allowed: a hard link is
// another name for the same bytes, which may lie outside (`ln /secret tree/x.png`), and no check of
// the path can tell; see docs/COOKING-SECURITY.md.
//
// Linux only (the cooker and viewer are not ported; the runtime's loader has its own platform
// layer). Test hook: OSSA_TEST_NO_OPENAT2=1 in the environment makes the probe answer "absent", so
// the walk can be tested on any kernel.
#pragma once
#include <sys/stat.h>

#include <filesystem>
#include <string>
#include <vector>

namespace ossa::cook {

/// The folders reads may reach, each held open (an O_PATH descriptor) for as long as this lives:
/// resolution starts from these descriptors, so renaming a folder's ancestors cannot redirect it.
class ReadRoots {
 public:
  struct Root {
    std::filesystem::path given;      // absolute, lexically normal, as named
    std::filesystem::path canonical;  // symlinks resolved (paths may be named either way)
    int fd = -1;                      // -1: the folder could not be opened (nothing beneath exists)
  };
  explicit ReadRoots(const std::vector<std::filesystem::path>& dirs);
  ~ReadRoots();
  ReadRoots(const ReadRoots&) = delete;
  ReadRoots& operator=(const ReadRoots&) = delete;
  const std::vector<Root>& roots() const { return roots_; }

 private:
  std::vector<Root> roots_;
};

enum class OpenOutcome {
  kOpened,      // fd is the file (regular), st its fstat
  kAbsent,      // no such file (error: ENOENT, ENOTDIR, or ENAMETOOLONG: no such name can exist)
  kOutside,     // the path, or a link on the way, leads outside every root
  kNotRegular,  // a directory, FIFO, device or socket (st says which); never opened for reading
  kHardLinked,  // a regular file with st.st_nlink > 1, and hard links are not allowed
  kError,       // anything else (error: errno, e.g. ELOOP, EACCES, ENAMETOOLONG)
};

struct OpenedFile {
  OpenOutcome outcome = OpenOutcome::kError;
  int fd = -1;        // kOpened only: O_RDONLY | O_NONBLOCK | O_CLOEXEC; the caller closes it
  struct stat st {};  // kOpened, kNotRegular, kHardLinked
  int error = 0;      // kAbsent, kError
};

/// Opens `path` for reading if it resolves, from one of `roots`, to a regular file beneath one of
/// them. `roots` null: no limit (the path is opened as the system would), and hard links are read.
/// `for_reading` false: resolves and checks only (kOpened with fd -1), opening nothing for reading.
/// Relative paths are taken from the current directory; `..` is applied to the path as written
/// before links are followed. O(components + links followed), at most 40 links.
OpenedFile open_beneath(const ReadRoots* roots, const std::filesystem::path& path, bool for_reading,
                        bool allow_hard_links);

/// The hard-link rule again, on a file open_beneath opened and the caller has read: true when it
/// still has one link and the name it was opened by is still linked. A rename over a hard link
/// drops the link count before it unlinks the name, so open_beneath's one look can fall between
/// the two and see one link and a live name; once the rename is done the name reads as unlinked
/// for good. Reading first and looking again after makes that window the whole read. O(1).
bool sole_name_now(int fd);

/// "a directory", "a FIFO", "a device", "a socket", "not a regular file": what `st` is, for messages.
const char* file_kind(const struct stat& st);

/// Whether this process resolves with openat2 (false: the walk). Probed once; for tests and -v.
bool have_openat2();

/// Tests: `walk` true makes later resolutions use the walk, as on a kernel without openat2; false
/// probes again.
void force_walk_for_testing(bool walk);

}  // namespace ossa::cook
