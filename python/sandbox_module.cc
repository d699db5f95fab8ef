// The Python extension `sandbox._sandbox` (pybind11): World (world.cc), the
// results' types (results.cc), LCM access (lcm_access.cc), the stepped
// loop (lockstep_run.cc) and the messages' decoder (message_decode.cc). docs/reference/python.md.

#include <pybind11/pybind11.h>

#include "app/defaults.h"
#include "app/isolated_load.h"
#include "python/lcm_access.h"
#include "python/results.h"
#include "python/world.h"
#include "scene/level.h"

namespace py = pybind11;

PYBIND11_MODULE(_sandbox, module) {
  using namespace sandbox::python;
  module.doc() =
      "The sandbox in-process: a level, its robots, scans as numpy arrays "
      "(docs/reference/python.md).";
  // Scene files load first in a child process: the sandbox program, not python3.
  sandbox::app::SetIsolatedLoader(sandbox::app::kSandboxBinary);
  py::register_exception<sandbox::scene::LevelError>(module, "LevelError", PyExc_RuntimeError)
      .attr("__module__") = "sandbox";

  BindResults(module);
  BindWorld(module);
  BindLcm(module);
  BindLockstep(module);
  BindDecode(module);
}
