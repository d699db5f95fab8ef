// The `sandbox` program: one subcommand per job.

#include <iostream>
#include <string>
#include <vector>

#include "app/bench_frames_command.h"
#include "app/convert_command.h"
#include "app/demo_command.h"
#include "app/info_command.h"
#include "app/isolated_load.h"
#include "app/pose_command.h"
#include "app/render_command.h"
#include "app/run_command.h"
#include "app/scan_command.h"
#include "app/topics_command.h"
#include "app/view_command.h"

namespace {

const char* kUsage =
    "usage: sandbox COMMAND [ARGS]\n"
    "commands:\n"
    "  demo [--duration S]     the sample level flown by the example model: frames, video, scans,\n"
    "                          statistics (start here)\n"
    "  bench-frames            frame durations: {empty, sample level} x {robot, + scanner,\n"
    "                          + overlay}, 3 runs of 500 frames, a table and plots\n"
    "  info [LEVEL] [--json]   actors, robots, triangles, bounds, load time and memory of a level\n"
    "  pose [LEVEL] --out M.ply  a robot posed from the command line, as a mesh and bone frames\n"
    "  scan [LEVEL] --at X,Y,Z --out F  one sensor once at a pose, as CSV or PLY\n"
    "  run [LEVEL]             the loop: LCM inputs, sensors, outputs at a fixed rate\n"
    "  render [LEVEL] --camera C --at X,Y,Z --out F  one camera frame (OSMesa)\n"
    "  topics                  the LCM channels heard: type, count, rate, size\n"
    "  view LOG                a recorded flight in the browser: replayed, then played back\n"
    "  convert IN OUT          a recording from an LCM log to MCAP (Foxglove's format) or back\n"
    "LEVEL: a level manifest (.toml), a scene file, or a robot description (.urdf, .sdf)\n"
    "run 'sandbox COMMAND --help' for a command's options\n";

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
    std::cout << kUsage;
    return args.empty() ? 2 : 0;
  }
  const std::vector<std::string> rest(args.begin() + 1, args.end());
  try {
    if (args[0] == "demo") return sandbox::app::RunDemo(rest, std::cout, std::cerr);
    if (args[0] == "bench-frames") return sandbox::app::RunBenchFrames(rest, std::cout, std::cerr);
    if (args[0] == "info") return sandbox::app::RunInfo(rest, std::cout, std::cerr);
    if (args[0] == "pose") return sandbox::app::RunPose(rest, std::cout, std::cerr);
    if (args[0] == "scan") return sandbox::app::RunScan(rest, std::cout, std::cerr);
    if (args[0] == "run") return sandbox::app::RunLoop(rest, std::cout, std::cerr);
    if (args[0] == "render") return sandbox::app::RunRender(rest, std::cout, std::cerr);
    if (args[0] == "topics") return sandbox::app::RunTopics(rest, std::cout, std::cerr);
    if (args[0] == "view") return sandbox::app::RunView(rest, std::cout, std::cerr);
    if (args[0] == "convert") return sandbox::app::RunConvert(rest, std::cout, std::cerr);
    // The child of an isolated load (--isolate); not for users.
    if (args[0] == "__load-level") return sandbox::app::RunLoadLevelChild(rest, std::cout);
  } catch (const std::exception& error) {
    std::cerr << "sandbox " << args[0] << ": " << error.what() << "\n";
    return 1;
  }
  std::cerr << "sandbox: unknown command '" << args[0] << "'\n" << kUsage;
  return 2;
}
