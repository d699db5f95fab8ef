#pragma once
// The live view (`sandbox run --view`): a window (OpenCV highgui) showing the
// active camera, and the keys pressed in it. The window runs on the main
// thread (Debian's highgui is Qt, whose windows belong there) while the loop
// runs on another; Show and TakeKeys never wait, so the loop keeps its rate.
//
// Keys: c or Tab next camera; a/d (or left/right) pan and w/s (or up/down)
// tilt the trailing camera; + and - zoom; o the debug overlay; space or p
// pause; q or Esc stop.

#include <atomic>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "sensors/render/cameras.h"
#include "sensors/render/renderer.h"

namespace sandbox::app {

enum class ViewKey {
  kNextCamera,
  kPanLeft,
  kPanRight,
  kTiltUp,
  kTiltDown,
  kZoomIn,
  kZoomOut,
  kToggleOverlay,
  kPause,
  kQuit
};

// The key of a code from cv::waitKeyEx; nullopt for keys without a use.
std::optional<ViewKey> KeyFromCode(int code);

// What the keys have set.
struct ViewControls {
  int camera{0};                  // index of the active camera
  render::TrailingCommand steer;  // added to the bridge's <ROBOT>/CAMERA command
  bool overlay{false};
  bool paused{false};
  bool quit{false};

  // Pan and tilt in 5 degree steps (tilt within +-80 degrees), zoom by 1.25
  // (1 to 16), cameras in turn.
  void Apply(ViewKey key, int num_cameras);
};

class LiveView {
 public:
  // Throws std::runtime_error when there is no display (neither DISPLAY nor
  // WAYLAND_DISPLAY set). The window opens in RunWindow.
  explicit LiveView(const std::string& title);
  LiveView(const LiveView&) = delete;
  LiveView& operator=(const LiveView&) = delete;

  // Main thread: opens the window and shows frames and collects keys until
  // `stop` is set, then closes it. Throws std::runtime_error when the window
  // cannot be made.
  void RunWindow(const std::atomic<bool>& stop);

  // Any thread: the newest frame replaces one not yet shown.
  void Show(const render::Frame& frame, const std::string& caption);
  // Any thread: the keys pressed since the last call, in order.
  std::vector<ViewKey> TakeKeys();
  std::int64_t shown() const { return shown_; }

 private:
  std::string title_;
  std::mutex mutex_;
  render::Frame pending_;
  std::string pending_caption_;
  bool has_pending_{false};
  std::vector<ViewKey> keys_;
  std::atomic<std::int64_t> shown_{0};
};

}  // namespace sandbox::app
