#include "app/run_command.h"

#include <atomic>
#include <exception>
#include <thread>

#include "app/command_line.h"
#include "app/run_options.h"
#include "app/sandbox_loop.h"

namespace sandbox::app {
namespace {

const char* kUsage =
    "usage: sandbox run [LEVEL] [--rate HZ|max] [--duration S] [--lcm-url URL] [--lockstep]\n"
    "                   [--replay LOG] [--record LOG] [--out DIR] [--frames LIST] [--depth D]\n"
    "                   [--scans-every S] [--view] [--realtime auto|off] [--isolate]\n"
    "                   [--ticks N] [--no-sensors | --frames-only] [--web [ADDR:]PORT]\n"
    "                   [--web-control] [--foxglove [ADDR:]PORT]\n"
    "  LEVEL          a level (default: the bundled sample level)\n"
    "  --isolate      read a manifest's files in a separate process first: a file that crashes\n"
    "                 assimp is then an error naming it (a scene file as LEVEL always is read so)\n"
    "  --rate         loop rate in Hz (default 100); max: free running, as fast as it can\n"
    "  --duration     stop after this many seconds (default: run until Ctrl-C)\n"
    "  --ticks        stop after this many ticks (lock-step: after N poses)\n"
    "  --lcm-url      LCM URL (default: LCM's own; multicast URLs get a 4 MB receive buffer)\n"
    "  --lockstep     each tick consumes exactly one pose message (waits for it); outputs and\n"
    "                 frames are a function of the inputs alone\n"
    "  --replay       read the inputs from an LCM log or MCAP file (no network), lock-step,\n"
    "                 full speed, with a progress bar; a --record log's STATE messages (the\n"
    "                 pose and bone values a run applied) replay as inputs\n"
    "  --record       write every output message to a file: MCAP for a name ending in .mcap\n"
    "                 (zstd chunks, with the inputs and Foxglove's schemas,\n"
    "                 docs/reference/recordings.md), else an LCM log\n"
    "  --out DIR      write into DIR: ticks.csv and ticks.png (frame statistics), the robots'\n"
    "                 camera frames ([[robot.camera]]; render and encoder threads, the loop\n"
    "                 never waits for them) and, with --scans-every, scans\n"
    "  --frames       jpg (default), png, mp4, avi, an image and a video format (jpg,mp4), or\n"
    "                 none (statistics and scans only)\n"
    "  --depth        depth images (payload cameras): png (16-bit mm, default), npy or exr\n"
    "                 (float32 m)\n"
    "  --scans-every  write each face scanner's scan as DIR/scans/<sensor>_<tick>.ply every S s,\n"
    "                 with its sheet <sensor>_<tick>.png (the faces as distance images)\n"
    "  --view         a window showing the active camera (needs a display); keys: c next camera,\n"
    "                 a/d pan, w/s tilt, +/- zoom (trailing), o overlay, space pause, q quit\n"
    "  --web          serve the browser view on PORT (127.0.0.1 unless ADDR is given; 0: any\n"
    "                 free port; the address is printed): the level, robots and movable actors\n"
    "                 live in a browser, read-only (docs/reference/web.md)\n"
    "  --web-control  the browser view may steer the cameras as the live view's keys do\n"
    "                 (next camera, pan, tilt, zoom, overlay; not pause or quit)\n"
    "  --foxglove     a Foxglove WebSocket protocol server on PORT (127.0.0.1 unless ADDR is\n"
    "                 given; 0: any free port; ws://... is printed): Foxglove or Lichtblick\n"
    "                 connects live and sees poses, face scans and lidar as their schemas\n"
    "                 (docs/how-to/foxglove.md)\n"
    "  --realtime     auto (default): the loop thread at real-time priority (SCHED_FIFO) when\n"
    "                 the user may (root, CAP_SYS_NICE or ulimit -r); off: normal priority\n"
    "  --no-sensors   run no sensor (robots' STATE and STATUS are still published)\n"
    "  --frames-only  run no sensor and publish nothing: only render the cameras, beside a\n"
    "                 sandbox that scans the same pose stream (docs/how-to/distributed.md)\n"
    "Inputs per robot: <ROBOT>/POSE, /BONES, /JOINTS, /ACTORS, /CAMERA (trailing pan, tilt,\n"
    "zoom).\n"
    "Outputs: <ROBOT>/SCAN_FACE, /GROUND, /LIDAR, /RANGE, /STATE, /STATUS "
    "(docs/reference/bridge.md).\n";

}  // namespace

int RunLoop(const std::vector<std::string>& args, std::ostream& out, std::ostream& err,
            const RunHooks& hooks) {
  const auto parsed = ParseArgs(args, "run", kRunValueOptions, kRunFlags, kUsage, err);
  if (!parsed) return 2;
  if (parsed->help) {
    out << kUsage;
    return 0;
  }
  RunOptions options;
  try {
    options = ParseRunOptions(*parsed);
  } catch (const UsageError& error) {
    err << "sandbox run: " << error.what() << "\n";
    return 2;
  }
  try {
    SandboxLoop loop(options, hooks, out, err);
    LiveView* view = loop.live_view();
    if (view == nullptr) return loop.Run();
    // The window on this (the main) thread, the loop on another.
    std::atomic<bool> done{false};
    std::exception_ptr failure;
    int code = 0;
    std::thread loop_thread([&] {
      try {
        code = loop.Run();
      } catch (...) {
        failure = std::current_exception();
      }
      done = true;
    });
    try {
      view->RunWindow(done);
    } catch (...) {
      loop.RequestStop();
      loop_thread.join();
      throw;
    }
    loop_thread.join();
    if (failure) std::rethrow_exception(failure);
    return code;
  } catch (const std::exception& error) {  // scene::LevelError, CommandError, LCM, files
    err << "sandbox run: " << error.what() << "\n";
    return 1;
  }
}

}  // namespace sandbox::app
