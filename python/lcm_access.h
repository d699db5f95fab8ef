#pragma once
// LCM from Python without a Python LCM package: the project's own link
// (bridge::LcmLink, the C++ tools' URL conventions) and log reader
// (bridge::LogReader), moving raw messages, and a decoder of the sandbox's
// message types (message_decode.cc) that python/sandbox/messages.py uses.

#include <pybind11/pybind11.h>

#include <cstddef>
#include <utility>
#include <vector>

namespace sandbox::python {

// Adds _Link and _LogReader to `module`.
void BindLcm(pybind11::module_& module);
// Adds _Lockstep (lockstep_run.cc) to `module`.
void BindLockstep(pybind11::module_& module);
// Adds Message, _decode and _decode_spans (message_decode.cc) to `module`.
void BindDecode(pybind11::module_& module);
// The messages at `spans` [(offset, size)] of `buffer` (any bytes-like
// object), decoded, in that order; ValueError for bytes that are not one.
pybind11::list DecodeSpans(const pybind11::handle& buffer,
                           const std::vector<std::pair<std::size_t, std::size_t>>& spans);

}  // namespace sandbox::python
