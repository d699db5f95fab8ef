#pragma once
// Memory figures of this process, from /proc/self/status (Linux).

namespace sandbox::app {

// Peak resident set size (VmHWM) in MiB; 0 when unknown.
double PeakResidentMiB();

}  // namespace sandbox::app
