#include "app/live_view.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <opencv2/highgui.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace sandbox::app {

std::optional<ViewKey> KeyFromCode(int code) {
  switch (code) {
    case 'c':
    case 'C':
    case '\t':
      return ViewKey::kNextCamera;
    case 'a':
    case 'A':
    case 0xff51:
      return ViewKey::kPanLeft;  // 0xff51..54: X11 arrows
    case 'd':
    case 'D':
    case 0xff53:
      return ViewKey::kPanRight;
    case 'w':
    case 'W':
    case 0xff52:
      return ViewKey::kTiltUp;
    case 's':
    case 'S':
    case 0xff54:
      return ViewKey::kTiltDown;
    case '+':
    case '=':
      return ViewKey::kZoomIn;
    case '-':
    case '_':
      return ViewKey::kZoomOut;
    case 'o':
    case 'O':
      return ViewKey::kToggleOverlay;
    case ' ':
    case 'p':
    case 'P':
      return ViewKey::kPause;
    case 'q':
    case 'Q':
    case 27:
      return ViewKey::kQuit;
    default:
      return std::nullopt;
  }
}

void ViewControls::Apply(ViewKey key, int num_cameras) {
  const double step = 5.0 * M_PI / 180.0, max_tilt = 80.0 * M_PI / 180.0;
  switch (key) {
    case ViewKey::kNextCamera:
      camera = num_cameras > 0 ? (camera + 1) % num_cameras : 0;
      break;
    case ViewKey::kPanLeft:
      steer.pan_rad += step;
      break;
    case ViewKey::kPanRight:
      steer.pan_rad -= step;
      break;
    case ViewKey::kTiltUp:
      steer.tilt_rad = std::min(steer.tilt_rad + step, max_tilt);
      break;
    case ViewKey::kTiltDown:
      steer.tilt_rad = std::max(steer.tilt_rad - step, -max_tilt);
      break;
    case ViewKey::kZoomIn:
      steer.zoom = std::min(steer.zoom * 1.25, 16.0);
      break;
    case ViewKey::kZoomOut:
      steer.zoom = std::max(steer.zoom / 1.25, 1.0);
      break;
    case ViewKey::kToggleOverlay:
      overlay = !overlay;
      break;
    case ViewKey::kPause:
      paused = !paused;
      break;
    case ViewKey::kQuit:
      quit = true;
      break;
  }
}

LiveView::LiveView(const std::string& title) : title_(title) {
  const char* x11 = std::getenv("DISPLAY");
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  if ((x11 == nullptr || *x11 == '\0') && (wayland == nullptr || *wayland == '\0')) {
    throw std::runtime_error(
        "--view needs a display: DISPLAY is not set (headless runs write "
        "frames with --out instead)");
  }
}

void LiveView::Show(const render::Frame& frame, const std::string& caption) {
  std::lock_guard<std::mutex> lock(mutex_);
  pending_ = frame;
  pending_caption_ = caption;
  has_pending_ = true;
}

std::vector<ViewKey> LiveView::TakeKeys() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<ViewKey> keys;
  keys.swap(keys_);
  return keys;
}

void LiveView::RunWindow(const std::atomic<bool>& stop) {
  try {
    cv::namedWindow(title_, cv::WINDOW_AUTOSIZE);
  } catch (const cv::Exception& e) {
    throw std::runtime_error(std::string("--view: cannot open a window: ") + e.what());
  }
  cv::Mat bgr;
  while (!stop) {
    render::Frame frame;
    std::string caption;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (has_pending_) {
        frame.width = pending_.width;
        frame.height = pending_.height;
        frame.rgb.swap(pending_.rgb);
        caption.swap(pending_caption_);
        has_pending_ = false;
      }
    }
    if (!frame.rgb.empty()) {
      const cv::Mat rgb(frame.height, frame.width, CV_8UC3, frame.rgb.data());
      cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
      cv::putText(bgr, caption, {8, 20}, cv::FONT_HERSHEY_SIMPLEX, 0.5, {255, 255, 255}, 1,
                  cv::LINE_AA);
      cv::imshow(title_, bgr);
      ++shown_;
    }
    const int code = cv::waitKeyEx(15);  // also runs the window's events
    if (code < 0) continue;
    if (const std::optional<ViewKey> key = KeyFromCode(code & 0xffff)) {
      std::lock_guard<std::mutex> lock(mutex_);
      keys_.push_back(*key);
    }
  }
  cv::destroyAllWindows();
}

}  // namespace sandbox::app
