// See interrupt.hpp.
#include "interrupt.hpp"

namespace tessera::python {

std::function<void(double)> interrupt_check() {
  py::module_ threading = py::module_::import("threading");
  if (!threading.attr("current_thread")().is(threading.attr("main_thread")())) return {};
  return [](double /*fraction done*/) {
    py::gil_scoped_acquire gil;
    // -1: a handler raised; its exception stays pending for without_gil().
    if (PyErr_CheckSignals() != 0) throw tessera::Cancelled();
  };
}

}  // namespace tessera::python
