#include "progress.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "tessera/io/atomic_file.hpp"

namespace tessera::cli {

bool stderr_is_terminal() { return ::isatty(STDERR_FILENO) == 1; }

ProgressBar::ProgressBar(std::string label, bool enabled, std::chrono::milliseconds delay)
    : label_(std::move(label)), enabled_(enabled), start_(clock::now()), last_draw_(start_),
      delay_(delay) {}

ProgressBar::~ProgressBar() { finish(); }

void ProgressBar::update(double fraction) {
  if (!enabled_) return;
  if (!(fraction >= 0)) fraction = 0;  // also catches NaN
  fraction = std::min(fraction, 1.0);
  const auto now = clock::now();
  if (now - start_ < delay_) return;
  const int permille = static_cast<int>(fraction * 1000);
  // Throttle: at most every 100 ms, and only when something visible changed
  // (the percentage, or the elapsed seconds once a second has passed).
  if (drawn_ && now - last_draw_ < std::chrono::milliseconds(100)) return;
  if (drawn_ && permille == last_permille_ && now - last_draw_ < std::chrono::seconds(1)) return;
  last_draw_ = now;
  last_permille_ = permille;
  draw(fraction, std::chrono::duration<double>(now - start_).count());
}

void ProgressBar::draw(double fraction, double elapsed) {
  constexpr int kWidth = 30;
  const int filled = static_cast<int>(std::lround(fraction * kWidth));
  char bar[kWidth + 1];
  for (int i = 0; i < kWidth; ++i) bar[i] = i < filled ? '#' : '.';
  bar[kWidth] = '\0';
  char eta[32] = "";
  const double left = fraction > 0.02 ? elapsed * (1 - fraction) / fraction : 0;
  if (left >= 1) std::snprintf(eta, sizeof eta, ", ~%.0f s left", left);
  // \r + erase-to-end-of-line so a shorter line leaves no remnants.
  std::fprintf(stderr, "\r\033[K%s [%s] %5.1f%% (%.1f s%s)", label_.c_str(), bar, fraction * 100,
               elapsed, eta);
  std::fflush(stderr);
  drawn_ = true;
}

void ProgressBar::finish() {
  if (!drawn_) return;
  std::fputs("\r\033[K", stderr);
  std::fflush(stderr);
  drawn_ = false;
}

namespace {

/// Only async-signal-safe calls below: unlink (inside
/// remove_pending_temporaries), write, sigaction, raise.
void write_stderr(const char* text) {
  const ssize_t ignored = ::write(STDERR_FILENO, text, std::strlen(text));
  (void)ignored;  // nothing to do about a failed error message
}

void on_fatal_signal(int sig) {
  const int removed = io::remove_pending_temporaries();
  write_stderr(sig == SIGINT    ? "tessera: error: interrupted"
               : sig == SIGTERM ? "tessera: error: terminated (SIGTERM)"
                                : "tessera: error: hung up (SIGHUP)");
  write_stderr(removed > 0 ? "; unfinished output removed\n" : "\n");
  // SA_RESETHAND has restored the default action: re-raise so the parent sees
  // the process end by this signal, as it would have without the handler.
  ::raise(sig);
}

volatile std::sig_atomic_t g_interrupted = 0;
struct sigaction g_before_guard {};  // the handler an InterruptGuard replaced

void on_sigint(int) {
  g_interrupted = 1;
  ::sigaction(SIGINT, &g_before_guard, nullptr);  // the next Ctrl-C ends the run
}

}  // namespace

void install_fatal_signal_cleanup() {
  struct sigaction sa {};
  sa.sa_handler = on_fatal_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESETHAND;
  for (const int sig : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction old {};
    // A signal ignored by whoever started us (nohup, a shell's background job)
    // stays ignored.
    if (::sigaction(sig, nullptr, &old) == 0 && old.sa_handler == SIG_IGN) continue;
    ::sigaction(sig, &sa, nullptr);
  }
}

InterruptGuard::InterruptGuard() {
  g_interrupted = 0;
  struct sigaction sa {};
  sa.sa_handler = on_sigint;
  sigemptyset(&sa.sa_mask);
  // g_before_guard is set before on_sigint can run, so it never reads it half-written.
  if (::sigaction(SIGINT, nullptr, &g_before_guard) != 0) return;
  // Ignored by whoever started us (a shell's background job, nohup): it
  // stays ignored here too, as it is while writing (install_fatal_signal_cleanup).
  if (g_before_guard.sa_handler == SIG_IGN) return;
  installed_ = ::sigaction(SIGINT, &sa, &previous_) == 0;
}

InterruptGuard::~InterruptGuard() {
  if (installed_) ::sigaction(SIGINT, &previous_, nullptr);
}

bool InterruptGuard::interrupted() { return g_interrupted != 0; }

}  // namespace tessera::cli
