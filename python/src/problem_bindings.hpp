#pragma once
// abuopt.BatchProblem (problem_bindings.cpp): registered from module.cpp.
#include <pybind11/pybind11.h>

namespace abuopt::python {

void register_problem_bindings(pybind11::module_& m);

}  // namespace abuopt::python
