#pragma once
// The Python class World (world.cc): a level in-process.

#include <pybind11/pybind11.h>

namespace sandbox::python {

// Adds World to `module`.
void BindWorld(pybind11::module_& module);

}  // namespace sandbox::python
