// Terminal progress bar and Ctrl-C handling for the tessera command.
#pragma once

#include <chrono>
#include <csignal>
#include <string>
#include <utility>

#include "tessera/cells.hpp"  // tessera::Cancelled

namespace tessera::cli {

/// True when stderr is a terminal (a progress bar would be seen, not logged).
bool stderr_is_terminal();

/// A one-line progress bar redrawn in place on stderr.
///
/// Contract: update() may be called as often as the engine likes; it redraws at
/// most every 100 ms, and only once the run has lasted `delay` (short runs show
/// nothing). finish() (or the destructor) erases the line so later output starts
/// clean. A disabled bar does nothing at all.
class ProgressBar {
 public:
  ProgressBar(std::string label, bool enabled,
              std::chrono::milliseconds delay = std::chrono::milliseconds(500));
  ~ProgressBar();
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  void update(double fraction);
  void finish();

 private:
  using clock = std::chrono::steady_clock;
  void draw(double fraction, double elapsed);

  std::string label_;
  bool enabled_;
  bool drawn_ = false;
  clock::time_point start_, last_draw_;
  std::chrono::milliseconds delay_;
  int last_permille_ = -1;
};

/// While alive, the first SIGINT (Ctrl-C) only sets a flag, which the progress
/// callback turns into tessera::Cancelled so the run stops between batches and
/// no output is written; a second SIGINT goes to the handler that was there
/// before (normally the one of install_fatal_signal_cleanup, which ends the
/// process). The previous handler is restored on destruction.
/// Install, for the whole run, handlers of SIGINT, SIGTERM and SIGHUP that
/// remove the temporaries of the outputs being written
/// (io::remove_pending_temporaries), print one error line and end the process
/// by the same signal (exit status 128 + signal to a shell). Without them a run
/// killed while writing, e.g. by `timeout`, left its `OUTPUT.tmp-XXXXXX` behind.
void install_fatal_signal_cleanup();

class InterruptGuard {
 public:
  InterruptGuard();
  ~InterruptGuard();
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;

  static bool interrupted();

 private:
  struct sigaction previous_ {};
  bool installed_ = false;
};

/// Runs `compute(progress)`, a library call given `progress` as its progress
/// callback, with a progress bar labelled `label` (when `show_progress`) and
/// Ctrl-C cancellation: the callback throws tessera::Cancelled once Ctrl-C was
/// pressed, so the library stops between batches. A Ctrl-C after the last
/// callback still cancels, so an interrupted run never writes output.
template <class Compute>
auto run_cancellable(std::string label, bool show_progress, Compute&& compute) {
  ProgressBar bar(std::move(label), show_progress);
  InterruptGuard guard;
  auto result = std::forward<Compute>(compute)([&bar](double f) {
    if (InterruptGuard::interrupted()) throw Cancelled();
    bar.update(f);
  });
  bar.finish();
  if (InterruptGuard::interrupted()) throw Cancelled();
  return result;
}

}  // namespace tessera::cli
