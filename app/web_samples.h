#pragma once
// The scan samples the browser view draws (docs/reference/web.md): each
// sensor's latest output as points, taken on the loop thread between ticks
// when a state with samples is due (a few a second, only with a client).
// A sensor with more samples than `max_points` keeps every k-th of them.

#include <Eigen/Core>
#include <cstddef>
#include <string>

#include "sensors/sensor.h"
#include "web/stream_state.h"

namespace sandbox::app {

web::StreamState::Samples ViewSamples(const sensors::Sensor& sensor, const std::string& robot,
                                      const Eigen::Vector3d& origin, std::size_t max_points);

}  // namespace sandbox::app
