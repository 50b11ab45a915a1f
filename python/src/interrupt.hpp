// Long computations from Python: the GIL released, Ctrl-C honoured.
//
// The front end takes a progress callback that it calls from the calling
// thread between batches of generators, and lets it throw tessera::Cancelled to
// stop (include/tessera/cells.hpp). From Python, that callback takes the GIL
// for a moment and runs PyErr_CheckSignals(): a pending SIGINT runs Python's
// handler, which sets KeyboardInterrupt (or whatever a user handler raises),
// and the callback cancels the run. Once the GIL is back, the pending Python
// exception is raised as is.
#pragma once

#include <functional>
#include <utility>

#include <pybind11/pybind11.h>

#include "tessera/cells.hpp"

namespace tessera::python {

namespace py = pybind11;

/// The progress callback to pass to a front-end call made from Python, while
/// the GIL is held. Python runs signal handlers only in the main thread, so
/// elsewhere this returns an empty function: no GIL round trips, and the
/// engine then skips its progress chunking altogether.
std::function<void(double)> interrupt_check();

/// Run `work()` with the GIL released and return its result. Cancellation by
/// interrupt_check() comes back as the Python exception the signal handler set
/// (KeyboardInterrupt for Ctrl-C); other C++ exceptions propagate unchanged to
/// the module's translators.
template <class Work>
auto without_gil(Work&& work) -> decltype(work()) {
  try {
    py::gil_scoped_release release;
    return std::forward<Work>(work)();
  } catch (const tessera::Cancelled&) {
    // The release guard is gone here: the GIL is held again.
    if (PyErr_Occurred()) throw py::error_already_set();
    throw;  // no Python error pending: the translator raises KeyboardInterrupt
  }
}

}  // namespace tessera::python
