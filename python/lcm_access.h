#pragma once
// LCM from Python without a Python LCM package: the project's own link
// (bridge::LcmLink, the C++ tools' URL conventions) and log reader
// (bridge::LogReader), moving raw messages, and a decoder of the sandbox's
// message types (message_decode.cc) that python/sandbox/messages.py uses.

#include <pybind11/pybind11.h>

namespace sandbox::python {

// Adds _Link and _LogReader to `module`.
void BindLcm(pybind11::module_& module);
// Adds _Lockstep (lockstep_run.cc) to `module`.
void BindLockstep(pybind11::module_& module);
// Adds _decode (message_decode.cc) to `module`.
void BindDecode(pybind11::module_& module);

}  // namespace sandbox::python
