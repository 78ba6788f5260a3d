#pragma once
// Registration functions of the module's parts that live outside module.cpp; PYBIND11_MODULE
// (module.cpp) calls each once.
#include <pybind11/pybind11.h>

namespace abuopt::python {

// First of all: an ImportError naming the interpreter the module was built for when NumPy is
// missing (the module returns NumPy arrays), and __version__ / __git_commit__ (module_extras.cpp).
void register_module_extras(pybind11::module_& m);

// abuopt.Archive: reading an evaluation archive of optimize, sweep and pareto (archive_bindings.cpp).
void register_archive(pybind11::module_& m);

// abuopt.optimize, abuopt.sweep, abuopt.pareto and their result types (study_bindings.cpp).
void register_studies(pybind11::module_& m);

}  // namespace abuopt::python
