// See signal_cleanup.hpp.
#include "signal_cleanup.hpp"

#include <csignal>
#include <iterator>  // std::size
#include <mutex>

#include <signal.h>

#include "tessera/io/atomic_file.hpp"

namespace tessera::python {

namespace {

constexpr int signals[] = {SIGTERM, SIGHUP};

// Async-signal-safe only: unlink (inside remove_pending_temporaries), raise.
// SA_RESETHAND has restored the default action, so the re-raised signal ends
// the process as it would have without this handler (a parent sees the same
// status). Nothing is printed: the default action prints nothing either.
void on_fatal_signal(int sig) {
  io::remove_pending_temporaries();
  ::raise(sig);
}

std::mutex guard_mutex;
int writers = 0;                    // writes under way, under guard_mutex
bool installed[std::size(signals)];  // ours is in place for signals[k]

}  // namespace

SignalCleanupDuringWrite::SignalCleanupDuringWrite() {
  const std::lock_guard<std::mutex> lock(guard_mutex);
  if (writers++ != 0) return;
  struct sigaction sa {};
  sa.sa_handler = on_fatal_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESETHAND;
  for (std::size_t k = 0; k < std::size(signals); ++k) {
    struct sigaction old {};
    // Only the default action is replaced: a script's handler (which Python
    // runs after the write returns, the file complete) or an ignored signal
    // stays as it is.
    installed[k] = ::sigaction(signals[k], nullptr, &old) == 0 && old.sa_handler == SIG_DFL &&
                   ::sigaction(signals[k], &sa, nullptr) == 0;
  }
}

SignalCleanupDuringWrite::~SignalCleanupDuringWrite() {
  const std::lock_guard<std::mutex> lock(guard_mutex);
  if (--writers != 0) return;
  struct sigaction dfl {};
  dfl.sa_handler = SIG_DFL;
  sigemptyset(&dfl.sa_mask);
  for (std::size_t k = 0; k < std::size(signals); ++k) {
    if (!installed[k]) continue;
    // Back to the default, unless someone replaced ours meanwhile (a C
    // extension in another thread): theirs stays.
    struct sigaction now {};
    if (::sigaction(signals[k], nullptr, &now) == 0 && now.sa_handler == on_fatal_signal)
      ::sigaction(signals[k], &dfl, nullptr);
    installed[k] = false;
  }
}

}  // namespace tessera::python
