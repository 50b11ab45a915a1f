// Atomic whole-file writes: stream into a fresh temporary next to the target,
// then rename(2) it over the target. Readers therefore see either the old file
// or the complete new one, and a failed write leaves nothing behind.
//
// No fsync: the guarantee is about failures in this process (errors, full
// disk, exceptions), not about power loss, and an fsync per output file would
// cost more than the write itself on some filesystems.
#include "tessera/io/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <random>
#include <streambuf>
#include <vector>

#include "tessera/cells.hpp"

namespace tessera::io {
namespace {

namespace fs = std::filesystem;

[[noreturn]] void cannot_write(const std::string& path, const std::string& reason) {
  throw InputError("cannot write " + path + ": " + reason);
}

/// An output streambuf over a file descriptor that remembers the errno of the
/// first failed write (std::ofstream only reports "failed", never why).
class FdBuf : public std::streambuf {
 public:
  explicit FdBuf(int fd) : fd_(fd), buf_(1 << 16) { setp(buf_.data(), buf_.data() + buf_.size()); }
  int error() const { return err_; }

 protected:
  int_type overflow(int_type ch) override {
    if (!drain()) return traits_type::eof();
    if (!traits_type::eq_int_type(ch, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(ch);
      pbump(1);
    }
    return traits_type::not_eof(ch);
  }
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    // Large blocks bypass the buffer.
    if (n >= static_cast<std::streamsize>(buf_.size())) {
      if (!drain() || !write_all(s, static_cast<std::size_t>(n))) return 0;
      return n;
    }
    return std::streambuf::xsputn(s, n);
  }
  int sync() override { return drain() ? 0 : -1; }

 private:
  bool drain() {
    const std::size_t n = static_cast<std::size_t>(pptr() - pbase());
    setp(buf_.data(), buf_.data() + buf_.size());
    return write_all(buf_.data(), n);
  }
  bool write_all(const char* p, std::size_t n) {
    if (err_) return false;
    while (n > 0) {
      const ssize_t w = ::write(fd_, p, n);
      if (w < 0) {
        if (errno == EINTR) continue;
        err_ = errno;
        return false;
      }
      p += w;
      n -= static_cast<std::size_t>(w);
    }
    return true;
  }

  int fd_;
  std::vector<char> buf_;
  int err_ = 0;
};

/// The temporaries of the writes in progress, kept where a signal handler may
/// read them: fixed slots of plain characters, no allocation and no locks (an
/// async-signal-safe reader can take neither). A writer claims a free slot,
/// copies its temporary's name in and arms it; the handler claims an armed slot
/// before reading it, so a writer never reuses a name that is being read.
class PendingTemporaries {
 public:
  static constexpr int kSlots = 64;

  /// Arm a slot with `name`; returns its index, or -1 when none is free or the
  /// name does not fit (the write then goes untracked; nothing else changes).
  int arm(const std::string& name) noexcept {
    if (name.size() >= sizeof(Slot::name)) return -1;
    for (int i = 0; i < kSlots; ++i) {
      int expected = kFree;
      if (!slots_[i].state.compare_exchange_strong(expected, kFilling, std::memory_order_acquire)) continue;
      std::memcpy(slots_[i].name, name.c_str(), name.size() + 1);
      slots_[i].state.store(kArmed, std::memory_order_release);
      return i;
    }
    return -1;
  }

  /// Give the slot back once its temporary is renamed or removed. A slot that
  /// a handler is removing stays taken: the process is about to die.
  void disarm(int i) noexcept {
    if (i < 0) return;
    int expected = kArmed;
    slots_[i].state.compare_exchange_strong(expected, kFree, std::memory_order_release);
  }

  int remove_all() noexcept {
    int removed = 0;
    for (Slot& slot : slots_) {
      int expected = kArmed;
      if (slot.state.compare_exchange_strong(expected, kRemoving, std::memory_order_acquire))
        removed += ::unlink(slot.name) == 0;
    }
    return removed;
  }

 private:
  enum : int { kFree, kFilling, kArmed, kRemoving };
  struct Slot {
    std::atomic<int> state{kFree};
    char name[4096]{};  // PATH_MAX on Linux
  };
  static_assert(std::atomic<int>::is_always_lock_free, "a signal handler may only use lock-free atomics");
  Slot slots_[kSlots];
};

// constinit: no guard variable, which a signal handler could not take.
constinit PendingTemporaries g_pending;
PendingTemporaries& pending() { return g_pending; }

/// What streaming into a file descriptor came to: the errno of the first
/// failed write, or a stream left bad by `fill` itself.
struct FillResult {
  int error = 0;
  bool stream_bad = false;
  bool ok() const { return error == 0 && !stream_bad; }
  std::string why() const { return error != 0 ? std::strerror(error) : "stream error"; }
};

/// Stream `fill` into `fd` (left open); exceptions from `fill` pass through.
FillResult fill_fd(int fd, const std::function<void(std::ostream&)>& fill) {
  FdBuf buf(fd);
  std::ostream os(&buf);
  fill(os);
  os.flush();
  return {buf.error(), !os};
}

/// Create `path.tmp-XXXXXX` (then `suffix`) exclusively (mode 0666 less the
/// umask, like a plain new file). Returns its fd, sets `tmp` and arms `slot`
/// with it; throws on failure. The name is armed before the file exists, so
/// no moment of the file's life is hidden from remove_pending_temporaries().
/// A file name too long for that (within 11 bytes of the folder's limit,
/// NAME_MAX) is cut short in the temporary's name: legal names of 245-255
/// bytes failed with "File name too long" after the whole computation.
int create_temp(const std::string& path, std::string& tmp, int& slot, const std::string& suffix = {}) {
  static std::atomic<unsigned> counter{0};
  static const char kAlnum[] = "abcdefghijklmnopqrstuvwxyz0123456789";
  std::random_device rd;
  std::mt19937 gen(rd() ^ (static_cast<unsigned>(::getpid()) << 16) ^ counter.fetch_add(1));
  std::string stem = path;
  {
    const fs::path p(path);
    const fs::path dir = p.parent_path().empty() ? fs::path(".") : p.parent_path();
    const long limit = ::pathconf(dir.c_str(), _PC_NAME_MAX);
    const std::size_t name_max = limit > 0 ? static_cast<std::size_t>(limit) : 255;
    const std::size_t extra = 11 + suffix.size();  // ".tmp-XXXXXX" and the suffix
    const std::string name = p.filename().string();
    if (name.size() + extra > name_max && name_max > extra)
      stem = (p.parent_path() / name.substr(0, name_max - extra)).string();
  }
  for (int attempt = 0; attempt < 100; ++attempt) {
    tmp = stem + ".tmp-";
    for (int k = 0; k < 6; ++k) tmp += kAlnum[gen() % (sizeof kAlnum - 1)];
    tmp += suffix;
    slot = pending().arm(tmp);
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) return fd;
    const int err = errno;
    pending().disarm(slot);
    slot = -1;
    if (err != EEXIST) cannot_write(path, std::strerror(err));
  }
  cannot_write(path, "could not create a unique temporary file");
}

/// The files no write may replace (protect_from_writes), by device and inode.
struct Protected {
  dev_t dev;
  ino_t ino;
  std::string role;
};
std::vector<Protected>& protected_files() {
  static std::vector<Protected> files;
  return files;
}

/// What writing `path` must not do: replace a protected file, or a file that
/// is not a regular one (a FIFO, a device: renaming over it would take it
/// away from whoever uses it). A link is replaced, not followed (its target
/// is left as it is), as rename(2) does; so is a regular file. Returns the
/// existing regular file's permission bits for the new one to keep, or -1
/// (none there, or a link).
int check_target(const std::string& path) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0) return -1;  // not there (or unreadable: the write says why)
  if (S_ISDIR(st.st_mode)) cannot_write(path, "is a directory");
  if (!S_ISREG(st.st_mode) && !S_ISLNK(st.st_mode))
    cannot_write(path, std::string("is not a regular file (") +
                           (S_ISFIFO(st.st_mode)   ? "a FIFO"
                            : S_ISSOCK(st.st_mode) ? "a socket"
                                                   : "a device") +
                           "), which a file written in its place would replace");
  struct stat target {};
  if (::stat(path.c_str(), &target) != 0) return -1;  // a dangling link
  if (S_ISDIR(target.st_mode)) cannot_write(path, "is a directory");
  for (const Protected& p : protected_files())
    if (p.dev == target.st_dev && p.ino == target.st_ino)
      cannot_write(path, "it is " + p.role + ", which this run reads; an output may not replace it (give another name)");
  return S_ISREG(st.st_mode) ? static_cast<int>(st.st_mode & 07777) : -1;
}

/// The group whose renames wait for its commit on this thread (OutputGroup).
thread_local OutputGroup* t_group = nullptr;

}  // namespace

void protect_from_writes(const std::string& path, const std::string& role) {
  struct stat st {};
  if (path.empty()) return;
  // Standard input redirected from a file (`joggle - -o p.npy < p.npy`): that file.
  if (path == "-" ? ::fstat(STDIN_FILENO, &st) != 0 : ::stat(path.c_str(), &st) != 0) return;
  if (S_ISREG(st.st_mode)) protected_files().push_back({st.st_dev, st.st_ino, role});
}

namespace {
std::atomic<bool> g_protect_read_files{false};
}  // namespace

void protect_files_read(bool on) { g_protect_read_files.store(on, std::memory_order_relaxed); }

void note_file_read(const std::string& path, const std::string& role) {
  if (g_protect_read_files.load(std::memory_order_relaxed)) protect_from_writes(path, role);
}

void write_file_atomic(const std::string& path, const std::function<void(std::ostream&)>& fill) {
  if (path.empty()) throw InputError("cannot write an empty path");
  if (path == "-") {
    // Standard output: written in place (a pipe cannot be renamed over).
    FillResult written;
    try {
      written = fill_fd(STDOUT_FILENO, fill);
    } catch (const Cancelled&) {
      throw;
    } catch (const std::exception& e) {
      cannot_write("standard output", e.what());
    }
    if (!written.ok()) cannot_write("standard output", written.why());
    return;
  }
  std::error_code ec;
  const int keep_mode = check_target(path);

  std::string tmp;
  int slot = -1;
  const int fd = create_temp(path, tmp, slot);
  // A file replaced keeps its permissions (as a shell's redirection, cp or
  // sed -i leave them): one made private stayed readable by all. New files
  // take 0666 less the umask.
  if (keep_mode >= 0) ::fchmod(fd, static_cast<mode_t>(keep_mode));
  // From here on every exit path must close fd and remove tmp unless renamed,
  // and disarm the slot after the file is gone (renamed or unlinked).
  auto discard = [&](int open_fd) {
    if (open_fd >= 0) ::close(open_fd);
    ::unlink(tmp.c_str());
    pending().disarm(slot);
  };
  FillResult written;
  try {
    written = fill_fd(fd, fill);
  } catch (const Cancelled&) {
    discard(fd);
    throw;  // cancellation is not a write error; let it through as itself
  } catch (const std::exception& e) {
    discard(fd);
    cannot_write(path, e.what());
  } catch (...) {
    discard(fd);
    throw;
  }
  if (!written.ok()) {
    discard(fd);
    cannot_write(path, written.why());
  }
  if (::close(fd) != 0) {
    const int err = errno;
    discard(-1);
    cannot_write(path, std::strerror(err));
  }
  if (t_group != nullptr) {  // renamed with the group's other files, at its commit
    t_group->staged_.push_back({tmp, path, slot});
    return;
  }
  fs::rename(tmp, path, ec);
  if (ec) {
    discard(-1);
    cannot_write(path, ec.message());
  }
  pending().disarm(slot);
}

OutputGroup::OutputGroup() : outer_(t_group) {
  if (outer_ == nullptr) t_group = this;
}

OutputGroup::~OutputGroup() {
  if (outer_ != nullptr) return;
  t_group = nullptr;
  discard_from(0);
}

void OutputGroup::discard_from(std::size_t k) noexcept {
  for (; k < staged_.size(); ++k) {
    ::unlink(staged_[k].tmp.c_str());
    pending().disarm(staged_[k].slot);
  }
  staged_.clear();
}

void OutputGroup::commit() {
  if (outer_ != nullptr) return;  // the outermost group commits
  t_group = nullptr;
  for (std::size_t k = 0; k < staged_.size(); ++k) {
    std::error_code ec;
    fs::rename(staged_[k].tmp, staged_[k].path, ec);
    if (ec) {
      const std::string path = staged_[k].path;
      discard_from(k);
      cannot_write(path, ec.message() + (k > 0 ? " (the outputs before it were replaced)" : ""));
    }
    pending().disarm(staged_[k].slot);
  }
  staged_.clear();
}

void write_file_atomic(const std::string& path, std::string_view bytes) {
  write_file_atomic(path, [bytes](std::ostream& os) {
    os.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  });
}

int remove_pending_temporaries() noexcept { return pending().remove_all(); }

TemporaryFile::TemporaryFile(const std::string& name, const std::string& suffix,
                             const std::function<void(std::ostream&)>& fill) {
  const char* env = std::getenv("TMPDIR");
  const fs::path dir = env != nullptr && *env != '\0' ? fs::path(env) : fs::path("/tmp");
  const std::string base = (dir / ("tessera-" + name)).string();
  const int fd = create_temp(base, path_, slot_, suffix);
  FillResult written;
  try {
    written = fill_fd(fd, fill);
  } catch (...) {
    ::close(fd);
    remove();
    throw;
  }
  if (::close(fd) != 0 && written.error == 0) written.error = errno;
  if (!written.ok()) {
    remove();
    cannot_write(base + ".tmp-*" + suffix, written.why());
  }
}

TemporaryFile::~TemporaryFile() { remove(); }

void TemporaryFile::remove() noexcept {
  if (path_.empty()) return;
  ::unlink(path_.c_str());
  pending().disarm(slot_);
  path_.clear();
}

void check_writable(const std::string& path) {
  if (path.empty()) throw InputError("cannot write an empty path");
  if (path == "-") return;  // standard output
  std::error_code ec;
  check_target(path);
  fs::path dir = fs::path(path).parent_path();
  if (dir.empty()) dir = ".";
  const auto st = fs::status(dir, ec);
  if (!fs::exists(st)) cannot_write(path, "directory '" + dir.string() + "' does not exist");
  if (!fs::is_directory(st)) cannot_write(path, "'" + dir.string() + "' is not a directory");
  if (::access(dir.c_str(), W_OK) != 0) {
    const int err = errno;
    cannot_write(path, "directory '" + dir.string() + "' is not writable (" + std::strerror(err) + ")");
  }
}

}  // namespace tessera::io
