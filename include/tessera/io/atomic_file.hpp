// Whole-file writes that never leave a partial file behind.
#pragma once

#include <cstddef>
#include <functional>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

namespace tessera::io {

/// Write `path` by streaming into `path.tmp-XXXX` in the same directory and
/// renaming it over `path` once complete. On any failure (directory missing,
/// not writable, disk full, exception from `fill`) the temporary is removed,
/// `path` is untouched, and tessera::InputError("cannot write PATH: reason") is thrown.
/// An existing `path` keeps its permission bits; one that is not a regular
/// file or a link (a FIFO, a device) or is protected (protect_from_writes)
/// is refused. Within an OutputGroup the rename waits for its commit.
/// `-` is standard output, written in place: not atomically (a pipe cannot
/// be renamed over), so a failure leaves what was written.
void write_file_atomic(const std::string& path, const std::function<void(std::ostream&)>& fill);
void write_file_atomic(const std::string& path, std::string_view bytes);

/// Fail early (before a long computation) if `path` cannot be created:
/// its directory must exist and be writable, and an existing `path` must be
/// one write_file_atomic may replace (`-`, standard output, passes).
/// Throws InputError.
void check_writable(const std::string& path);

/// Protect the file `path` (if it exists as a regular file; compared by
/// device and inode, so any spelling or link of it counts) from
/// check_writable and write_file_atomic, which refuse it with "cannot write
/// PATH: it is ROLE, which this run reads". Empty unless a program adds to
/// it: the tessera command lists its inputs (the points, --labels,
/// --radii, ...), so that a slip such as `voronoi p.npy --cell-table p.npy`
/// cannot replace what it read. `-` is standard input: the file it is
/// redirected from, if it is one. Add before writing (not thread-safe).
void protect_from_writes(const std::string& path, const std::string& role);

/// Files a reader opens beyond the one it was given (an image header's
/// detached data: NRRD's `data file`, MetaImage's `ElementDataFile`, a NIfTI
/// pair's `.img`) are noted with note_file_read, which protects them
/// (protect_from_writes) only once protect_files_read(true) was called: the
/// tessera command does; a library user (Python) reads and writes as it likes.
void protect_files_read(bool on);
void note_file_read(const std::string& path, const std::string& role);

/// Outputs written together: while one lives on this thread,
/// write_file_atomic leaves each complete file under its temporary name, and
/// commit() renames them all over their targets in the order written. A
/// failure before the commit (a full disk in the third file, an exception,
/// Ctrl-C) therefore leaves every target as it was, where the files written
/// before it had already replaced theirs: a new points file beside the old
/// labels. Destroyed uncommitted, it removes the temporaries (as does
/// remove_pending_temporaries on a signal). A group made while another
/// lives on the thread joins it: the outermost commits. A rename failing in
/// the commit (rare: each temporary is in its target's folder) leaves the
/// targets before it replaced, and says so. Standard output ("-") is
/// written at once.
class OutputGroup {
 public:
  OutputGroup();
  ~OutputGroup();
  OutputGroup(const OutputGroup&) = delete;
  OutputGroup& operator=(const OutputGroup&) = delete;
  void commit();

 private:
  friend void write_file_atomic(const std::string& path, const std::function<void(std::ostream&)>& fill);
  struct Staged {
    std::string tmp, path;
    int slot;
  };
  void discard_from(std::size_t k) noexcept;
  OutputGroup* outer_;
  std::vector<Staged> staged_;
};

/// A file of this process's own in the temporary directory ($TMPDIR, else
/// /tmp), named tessera-NAME.tmp-XXXXXX then `suffix`, written by `fill`
/// (InputError "cannot write ..." on failure, nothing left behind). It is
/// removed when the object dies, and by remove_pending_temporaries() on a
/// fatal signal. The tessera command reads standard input ("-") through one.
class TemporaryFile {
 public:
  TemporaryFile(const std::string& name, const std::string& suffix, const std::function<void(std::ostream&)>& fill);
  ~TemporaryFile();
  TemporaryFile(const TemporaryFile&) = delete;
  TemporaryFile& operator=(const TemporaryFile&) = delete;
  const std::string& path() const { return path_; }

 private:
  void remove() noexcept;
  std::string path_;
  int slot_ = -1;
};

/// Unlink the temporary of every write_file_atomic now in progress (and
/// every live TemporaryFile), in any thread. Async-signal-safe (it calls
/// only unlink(2)), so a program's handler for SIGTERM or SIGINT can call it
/// before the process dies: a run killed while writing then leaves neither
/// a partial file nor its temporary. The library
/// installs no signal handler itself; the tessera command does (main.cpp).
/// Best effort: up to 64 concurrent writes are tracked, and a write completing
/// at the same moment may lose its temporary name's unlink to ENOENT, harmlessly.
/// Returns how many temporaries it unlinked.
int remove_pending_temporaries() noexcept;

}  // namespace tessera::io
