// Whole-file writes that never leave a partial file behind.
#pragma once

#include <functional>
#include <ostream>
#include <string>
#include <string_view>

namespace tessera::io {

/// Write `path` by streaming into `path.tmp-XXXX` in the same directory and
/// renaming it over `path` once complete. On any failure (directory missing,
/// not writable, disk full, exception from `fill`) the temporary is removed,
/// `path` is untouched, and tessera::InputError("cannot write PATH: reason") is thrown.
/// `-` is standard output, written in place: not atomically (a pipe cannot
/// be renamed over), so a failure leaves what was written.
void write_file_atomic(const std::string& path, const std::function<void(std::ostream&)>& fill);
void write_file_atomic(const std::string& path, std::string_view bytes);

/// Fail early (before a long computation) if `path` cannot be created:
/// its directory must exist and be writable (`-`, standard output, passes).
/// Throws InputError.
void check_writable(const std::string& path);

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
