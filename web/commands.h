#pragma once
// What a page may send the sandbox (docs/reference/web.md), each a JSON
// object with a `type`: player commands to `sandbox view`'s playhead, and,
// with `sandbox run --web-control`, camera commands that steer the cameras
// as the live view's keys do. Anything else is refused naming the field.

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

namespace sandbox::web {

// {"type": "player", "play": true|false, "speed": 0.01..100, "seek": TICK},
// each field but type optional.
struct PlayerCommand {
  std::optional<bool> play;
  std::optional<double> speed;
  std::optional<std::int64_t> seek;
};

// Throws std::invalid_argument naming the field for anything else: not JSON,
// another type, a field of the wrong type or out of range, an unknown field.
PlayerCommand ParsePlayerCommand(std::string_view text);

// {"type": "camera", "key": K}: K one of kCameraKeys. Returns K; throws
// std::invalid_argument as ParsePlayerCommand does.
inline constexpr const char* kCameraKeys[] = {"next_camera", "pan_left", "pan_right", "tilt_up",
                                              "tilt_down",   "zoom_in",  "zoom_out",  "overlay"};
std::string ParseCameraCommand(std::string_view text);

}  // namespace sandbox::web
