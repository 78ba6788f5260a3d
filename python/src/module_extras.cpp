// The module's import-time check and version attributes (bindings.hpp).
#include <string>

#include "abuopt/common/provenance.hpp"
#include "bindings.hpp"

#ifndef ABUOPT_PYTHON_BUILT_FOR
#define ABUOPT_PYTHON_BUILT_FOR "the Python of the build"
#endif

namespace py = pybind11;

namespace abuopt::python {

void register_module_extras(py::module_& m) {
  // Every result holds NumPy arrays: without NumPy the module would import and fail at the first
  // call (ModuleNotFoundError from deep inside). Fail here, saying which interpreter has NumPy.
  try {
    py::module_::import("numpy");
  } catch (py::error_already_set& e) {
    if (!e.matches(PyExc_ImportError)) throw;
    const std::string running = py::module_::import("sys").attr("executable").cast<std::string>();
    throw py::import_error("abuopt needs NumPy, which this interpreter (" + running +
                           ") cannot import. The module was built for " ABUOPT_PYTHON_BUILT_FOR
                           ": run that interpreter, or install NumPy for this one (Debian: python3-numpy), "
                           "or rebuild with -DPython3_EXECUTABLE=" + running + " (docs/python.md)");
  }
  m.attr("__version__") = abuopt_version();
  m.attr("__git_commit__") = abuopt_git_commit();
}

}  // namespace abuopt::python
