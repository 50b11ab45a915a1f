// Atomic writes: success, overwrite, and failures that leave nothing behind.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>

#include <stdexcept>
#include <string>

#include "io/io_test_util.hpp"
#include "tessera/io/atomic_file.hpp"

using namespace tessera_test;
using tessera::io::check_writable;
using tessera::io::remove_pending_temporaries;
using tessera::io::write_file_atomic;

TEST(AtomicFile, WritesAndOverwrites) {
  TempDir dir;
  const std::string p = dir.file("out.txt");
  write_file_atomic(p, std::string_view("hello"));
  EXPECT_EQ(read_all(p), "hello");
  write_file_atomic(p, [](std::ostream& os) { os << "second " << 2; });
  EXPECT_EQ(read_all(p), "second 2");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"out.txt"});  // no temporaries left
}

TEST(AtomicFile, LargeWrite) {
  TempDir dir;
  const std::string p = dir.file("big.bin");
  std::string big(3 << 20, 'x');
  big[12345] = 'y';
  write_file_atomic(p, [&](std::ostream& os) {
    os << 'a';
    os.write(big.data(), static_cast<std::streamsize>(big.size()));
    os << 'b';
  });
  EXPECT_EQ(read_all(p), "a" + big + "b");
}

TEST(AtomicFile, MissingDirectoryFailsAndLeavesNothing) {
  TempDir dir;
  const std::string p = (dir.path() / "no_such_dir" / "out.csv").string();
  auto msg = input_error([&] { write_file_atomic(p, std::string_view("data")); });
  EXPECT_EQ(msg.rfind("cannot write " + p + ": ", 0), 0u) << msg;
  EXPECT_FALSE(fs::exists(dir.path() / "no_such_dir"));
  EXPECT_TRUE(dir.entries().empty());
  msg = input_error([&] { check_writable(p); });
  EXPECT_NE(msg.find("does not exist"), std::string::npos) << msg;
}

TEST(AtomicFile, ExceptionInFillKeepsOldFile) {
  TempDir dir;
  const std::string p = dir.file("keep.txt");
  write_file_atomic(p, std::string_view("original"));
  auto msg = input_error([&] {
    write_file_atomic(p, [](std::ostream& os) {
      os << std::string(200000, 'z');
      throw std::runtime_error("boom");
    });
  });
  EXPECT_EQ(msg, "cannot write " + p + ": boom");
  EXPECT_EQ(read_all(p), "original");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"keep.txt"});
}

TEST(AtomicFile, CancelledPassesThrough) {
  TempDir dir;
  const std::string p = dir.file("c.txt");
  EXPECT_THROW(write_file_atomic(p, [](std::ostream&) { throw tessera::Cancelled(); }), tessera::Cancelled);
  EXPECT_TRUE(dir.entries().empty());
}

TEST(AtomicFile, DirectoryTargetRejected) {
  TempDir dir;
  fs::create_directory(dir.path() / "sub");
  const std::string p = dir.file("sub");
  auto msg = input_error([&] { write_file_atomic(p, std::string_view("x")); });
  EXPECT_NE(msg.find("is a directory"), std::string::npos) << msg;
  msg = input_error([&] { check_writable(p); });
  EXPECT_NE(msg.find("is a directory"), std::string::npos) << msg;
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"sub"});
}

TEST(AtomicFile, CheckWritable) {
  TempDir dir;
  EXPECT_NO_THROW(check_writable(dir.file("fine.csv")));
  // A regular file used as the directory.
  write_file_atomic(dir.file("plain"), std::string_view("x"));
  auto msg = input_error([&] { check_writable(dir.file("plain") + "/out.csv"); });
  EXPECT_NE(msg.find("not a directory"), std::string::npos) << msg;
  // A read-only directory (root bypasses permissions, so only check as non-root).
  if (::geteuid() != 0) {
    fs::create_directory(dir.path() / "ro");
    fs::permissions(dir.path() / "ro", fs::perms::owner_read | fs::perms::owner_exec);
    const std::string p = (dir.path() / "ro" / "out.csv").string();
    msg = input_error([&] { check_writable(p); });
    EXPECT_NE(msg.find("not writable"), std::string::npos) << msg;
    msg = input_error([&] { write_file_atomic(p, std::string_view("x")); });
    EXPECT_NE(msg.find("Permission denied"), std::string::npos) << msg;
    fs::permissions(dir.path() / "ro", fs::perms::owner_all);
    EXPECT_TRUE(fs::is_empty(dir.path() / "ro"));
  }
}

// A process killed while writing: its signal handler calls
// remove_pending_temporaries(), which must find the temporary of the write in
// progress (armed before the file was created) and unlink it. The child raises
// SIGTERM from inside `fill`, after 1 MB has reached the temporary.
namespace {
extern "C" void remove_and_exit(int) {
  _exit(remove_pending_temporaries() == 1 ? 3 : 4);
}
}  // namespace

TEST(AtomicFile, SignalHandlerRemovesTheTemporary) {
  TempDir dir;
  const std::string done = dir.file("done.txt"), killed = dir.file("killed.bin");
  write_file_atomic(done, std::string_view("complete"));  // finished writes stay untouched
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    std::signal(SIGTERM, remove_and_exit);
    try {
      write_file_atomic(killed, [](std::ostream& os) {
        os << std::string(1 << 20, 'k');
        os.flush();
        std::raise(SIGTERM);
      });
    } catch (...) {
    }
    _exit(5);  // the handler did not run
  }
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 3) << "4: the handler found no temporary; 5: it did not run";
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"done.txt"});
  EXPECT_EQ(read_all(done), "complete");
  EXPECT_EQ(remove_pending_temporaries(), 0);  // this process has no write in progress
}

// A TemporaryFile lies in $TMPDIR under its name and suffix, holds what its
// fill wrote, and is gone when the object dies, when its fill throws, and
// when a signal handler calls remove_pending_temporaries().
TEST(AtomicFile, TemporaryFile) {
  TempDir dir;
  const char* old = std::getenv("TMPDIR");
  const std::string saved = old != nullptr ? old : "";
  ::setenv("TMPDIR", dir.file("").c_str(), 1);
  {
    tessera::io::TemporaryFile t("stdin", ".csv", [](std::ostream& os) { os << "1,2\n"; });
    EXPECT_EQ(t.path().rfind(dir.file("tessera-stdin.tmp-"), 0), 0u) << t.path();
    EXPECT_EQ(t.path().substr(t.path().size() - 4), ".csv");
    EXPECT_EQ(read_all(t.path()), "1,2\n");
    EXPECT_EQ(dir.entries().size(), 1u);
  }
  EXPECT_TRUE(dir.entries().empty());
  EXPECT_THROW(tessera::io::TemporaryFile("x", ".txt", [](std::ostream&) { throw std::runtime_error("no"); }),
               std::runtime_error);
  EXPECT_TRUE(dir.entries().empty());
  {
    tessera::io::TemporaryFile t("x", ".npy", [](std::ostream& os) { os << "data"; });
    EXPECT_EQ(remove_pending_temporaries(), 1);
    EXPECT_TRUE(dir.entries().empty());
  }  // its own removal finds the file gone, harmlessly
  if (old != nullptr) ::setenv("TMPDIR", saved.c_str(), 1);
  else ::unsetenv("TMPDIR");
}

// An OutputGroup renames its files at commit, all together: a failure in one
// (here an exception while the second is written) leaves every target as it
// was, and no temporary; a group made inside another joins it.
TEST(AtomicFile, OutputGroupIsAllOrNothing) {
  TempDir dir;
  const std::string a = dir.file("points.npy"), b = dir.file("points_labels.npy");
  write_file_atomic(a, std::string_view("old points"));
  write_file_atomic(b, std::string_view("old labels"));
  auto msg = input_error([&] {
    tessera::io::OutputGroup group;
    write_file_atomic(a, std::string_view("new points"));
    EXPECT_EQ(read_all(a), "old points");  // not renamed before the commit
    write_file_atomic(b, [](std::ostream&) { throw std::runtime_error("disk full"); });
    group.commit();
  });
  EXPECT_NE(msg.find("disk full"), std::string::npos) << msg;
  EXPECT_EQ(read_all(a), "old points");
  EXPECT_EQ(read_all(b), "old labels");
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"points.npy", "points_labels.npy"}));
  {
    tessera::io::OutputGroup group;
    write_file_atomic(a, std::string_view("new points"));
    {
      tessera::io::OutputGroup inner;  // joins the outer group
      write_file_atomic(b, std::string_view("new labels"));
      inner.commit();
    }
    EXPECT_EQ(read_all(b), "old labels");
    group.commit();
  }
  EXPECT_EQ(read_all(a), "new points");
  EXPECT_EQ(read_all(b), "new labels");
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"points.npy", "points_labels.npy"}));
  {  // destroyed uncommitted: the temporaries go, the targets stay
    tessera::io::OutputGroup group;
    write_file_atomic(a, std::string_view("third"));
  }
  EXPECT_EQ(read_all(a), "new points");
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"points.npy", "points_labels.npy"}));
}

// A replaced file keeps its permissions (a private one stayed readable by all
// under umask 022); a FIFO or a protected input is refused, by any spelling;
// a name within 11 bytes of NAME_MAX still gets its temporary.
TEST(AtomicFile, WhatAReplacedFileKeepsAndWhatIsRefused) {
  TempDir dir;
  const std::string p = dir.file("private.csv");
  write_file_atomic(p, std::string_view("one"));
  ASSERT_EQ(::chmod(p.c_str(), 0600), 0);
  write_file_atomic(p, std::string_view("two"));
  EXPECT_EQ(fs::status(p).permissions() & fs::perms::mask, fs::perms::owner_read | fs::perms::owner_write);
  // None at all (it came back 0644: 0 meant "no file"). Replacing needs
  // only the folder's permission.
  ASSERT_EQ(::chmod(p.c_str(), 0), 0);
  write_file_atomic(p, std::string_view("three"));
  EXPECT_EQ(fs::status(p).permissions() & fs::perms::mask, fs::perms::none);
  ASSERT_EQ(::chmod(p.c_str(), 0600), 0);

  const std::string fifo = dir.file("pipe.npy");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  auto msg = input_error([&] { check_writable(fifo); });
  EXPECT_NE(msg.find("is not a regular file (a FIFO)"), std::string::npos) << msg;
  msg = input_error([&] { write_file_atomic(fifo, std::string_view("x")); });
  EXPECT_NE(msg.find("a FIFO"), std::string::npos) << msg;
  EXPECT_TRUE(fs::is_fifo(fifo));

  const std::string input = dir.file("points.npy");
  write_file_atomic(input, std::string_view("the points"));
  tessera::io::protect_from_writes(input, "the INPUT");
  const std::string other_spelling = (dir.path() / "." / "points.npy").string();
  msg = input_error([&] { check_writable(other_spelling); });
  EXPECT_NE(msg.find("it is the INPUT, which this run reads"), std::string::npos) << msg;
  msg = input_error([&] { write_file_atomic(input, std::string_view("a table")); });
  EXPECT_NE(msg.find("the INPUT"), std::string::npos) << msg;
  EXPECT_EQ(read_all(input), "the points");

  const long name_max = ::pathconf(dir.path().c_str(), _PC_NAME_MAX);
  const std::string longest = dir.file(std::string(static_cast<std::size_t>(name_max > 0 ? name_max : 255) - 4, 'n') + ".npy");
  check_writable(longest);
  write_file_atomic(longest, std::string_view("long"));
  EXPECT_EQ(read_all(longest), "long");
  EXPECT_EQ(dir.entries().size(), 4u);  // private.csv, pipe.npy, points.npy and the long one: no temporaries
}
