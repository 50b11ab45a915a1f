// A file write from Python that a fatal signal cannot leave half-done.
//
// Files are written to OUTPUT.tmp-XXXXXX and renamed (io::write_file_atomic),
// and the library records each temporary so that a signal handler can remove
// it (io::remove_pending_temporaries), but installs no handler itself. The
// `tessera` command installs one for its whole run (apps/tessera/progress.cpp).
// A Python process is the user's: SIGTERM and SIGHUP keep their default
// action (the process ends, leaving the temporary behind) unless the script
// set a handler. So while a write is under way, and only where the action is
// still the default, a handler is put in that removes the temporaries and then
// ends the process by the same signal, as the default would have; the
// previous action is back once the last concurrent write is done. SIGINT is
// Python's own (KeyboardInterrupt once the write returns, which completes the
// file first) and is left alone.
#pragma once

namespace tessera::python {

class SignalCleanupDuringWrite {
 public:
  SignalCleanupDuringWrite();
  ~SignalCleanupDuringWrite();
  SignalCleanupDuringWrite(const SignalCleanupDuringWrite&) = delete;
  SignalCleanupDuringWrite& operator=(const SignalCleanupDuringWrite&) = delete;
};

}  // namespace tessera::python
