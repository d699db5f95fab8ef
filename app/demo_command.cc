#include "app/demo_command.h"

#include <fcntl.h>
#include <sched.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <thread>

#include "app/command_line.h"
#include "app/defaults.h"
#include "app/run_command.h"
#include "app/sandbox_loop.h"
#include "bridge/checked_decode.h"
#include "bridge/example_flight.h"
#include "bridge/lcm_link.h"
#include "sandbox_msgs/status_t.hpp"

extern char** environ;

namespace sandbox::app {
namespace {

const char* kUsage =
    "usage: sandbox demo [--duration S] [--out DIR] [--in-process] [--web [ADDR:]PORT]\n"
    "                    [--web-control] [--record FILE] [--foxglove [ADDR:]PORT]\n"
    "  The sample level and the flying wing, flown by the example model (examples/fly_wing)\n"
    "  as a separate process over LCM inside a private network namespace (nothing reaches\n"
    "  the LAN). Face scanner on; chase, trailing and belly cameras write JPEG and an mp4\n"
    "  each; the face scan is written as PLY every second; frame statistics and their plot.\n"
    "  --duration    seconds of flight (default 20)\n"
    "  --out         where everything goes (default: sandbox-demo)\n"
    "  --in-process  no namespace: the model flies in this process over memq:// (also what\n"
    "                happens when no namespace can be made: that needs root or user namespaces)\n"
    "  --web         the browser view on this port (127.0.0.1 unless an address is given; 0:\n"
    "                any free port): the model then flies in-process, as the namespace's\n"
    "                ports are out of the browser's reach (docs/reference/web.md)\n"
    "  --web-control the page may steer the cameras (pan, tilt, zoom, overlay)\n"
    "  --record      every message the run publishes to FILE: MCAP for a name ending in\n"
    "                .mcap (with the inputs and Foxglove's schemas), else an LCM log\n"
    "  --foxglove    a live Foxglove WebSocket server on this port, as sandbox run --foxglove\n";

bool InNamespace() {
  const char* flag = std::getenv("SANDBOX_IN_NETNS");
  return flag != nullptr && std::string(flag) == "1";
}

bool CanMakeNamespace() {
  return std::system((std::string(kNetnsRunScript) + " true > /dev/null 2>&1").c_str()) == 0;
}

// Runs this program again inside a private network namespace; returns only on failure.
void ReExecInNamespace(const std::vector<std::string>& args) {
  char self[4096];
  const ssize_t length = readlink("/proc/self/exe", self, sizeof(self) - 1);
  if (length <= 0) return;
  self[length] = '\0';
  std::vector<std::string> argv_strings = {kNetnsRunScript, self, "demo"};
  argv_strings.insert(argv_strings.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& s : argv_strings) argv.push_back(s.data());
  argv.push_back(nullptr);
  execv(kNetnsRunScript, argv.data());
}

// The example model as a child process, its output in `log_file`.
pid_t StartFlyWing(double duration_s, const std::string& log_file) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log_file.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  std::ostringstream seconds;
  seconds << duration_s;
  std::vector<std::string> argv_strings = {kFlyWingBinary, "--duration", seconds.str(), "--rate",
                                           "100"};
  std::vector<char*> argv;
  for (std::string& s : argv_strings) argv.push_back(s.data());
  argv.push_back(nullptr);
  // Started from the loop's thread, which may run at real-time priority: the
  // model runs at normal priority.
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSCHEDULER);
  posix_spawnattr_setschedpolicy(&attributes, SCHED_OTHER);
  const sched_param normal{};
  posix_spawnattr_setschedparam(&attributes, &normal);
  pid_t pid = -1;
  const int error = posix_spawn(&pid, kFlyWingBinary, &actions, &attributes, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attributes);
  if (error != 0)
    throw CommandError(std::string("cannot start the example model ") + kFlyWingBinary);
  return pid;
}

// Listens to ELAHA/STATUS on the loop's own link: the heartbeat, end to end.
struct StatusListener {
  std::unique_ptr<bridge::LatestInput> input;
  std::int64_t heard{0};
  double last_rate_hz{0.0};
  void Poll(bridge::LcmLink& link) {
    if (!input) input = std::make_unique<bridge::LatestInput>(link, "ELAHA/STATUS");
    if (const std::vector<std::uint8_t>* bytes = input->TakeNewest()) {
      sandbox_msgs::status_t status;
      if (bridge::DecodeChecked(bytes->data(), bytes->size(), &status).empty()) {
        ++heard;
        last_rate_hz = status.loop_rate_hz;
      }
    }
  }
};

// The last frame listed in DIR/<camera>.csv; empty when none.
cv::Mat LastFrame(const std::filesystem::path& dir, const std::string& camera) {
  std::ifstream index(dir / (camera + ".csv"));
  std::string line, last;
  while (std::getline(index, line)) last = line;
  const std::size_t a = last.find(','), b = last.find(',', a + 1), c = last.find(',', b + 1);
  if (c == std::string::npos) return {};
  return cv::imread((dir / last.substr(b + 1, c - b - 1)).string());
}

// One picture of the run: the chase, trailing and belly cameras' last frames
// and the tick-duration plot, 640 x 480 each.
void WriteOverview(const std::filesystem::path& dir, const std::string& file) {
  std::vector<cv::Mat> tiles;
  for (const char* camera : {"chase", "trailing", "belly"}) tiles.push_back(LastFrame(dir, camera));
  tiles.push_back(cv::imread((dir / "ticks.png").string()));
  for (cv::Mat& tile : tiles) {
    if (tile.empty()) tile = cv::Mat(480, 640, CV_8UC3, cv::Scalar(60, 60, 60));
    cv::resize(tile, tile, cv::Size(640, 480), 0, 0, cv::INTER_AREA);
  }
  cv::Mat top, bottom, all;
  cv::hconcat(tiles[0], tiles[1], top);
  cv::hconcat(tiles[2], tiles[3], bottom);
  cv::vconcat(top, bottom, all);
  cv::imwrite((dir / file).string(), all);
}

}  // namespace

int RunDemo(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  const auto parsed =
      ParseArgs(args, "demo", {"--duration", "--out", "--web", "--record", "--foxglove"},
                {"--in-process", "--web-control"}, kUsage, err);
  if (!parsed) return 2;
  if (parsed->help) {
    out << kUsage;
    return 0;
  }
  if (parsed->level) {
    err << "sandbox demo: takes no level (it flies the bundled sample level)\n" << kUsage;
    return 2;
  }
  try {
    const double duration_s = parsed->values.count("--duration")
                                  ? ParseNumber(parsed->Value("--duration"), "--duration")
                                  : 20.0;
    if (!(duration_s > 0.0 && duration_s <= 3600.0))
      throw UsageError("--duration must be above 0 and at most 3600 s");
    const std::string out_dir = parsed->Value("--out", "sandbox-demo");
    const bool web = parsed->values.count("--web") > 0;
    bool in_process = parsed->flags.count("--in-process") > 0 || web;
    if (!in_process && !InNamespace()) {
      if (CanMakeNamespace()) {
        out << "sandbox demo: into a private network namespace (scripts/netns-run)\n" << std::flush;
        ReExecInNamespace(args);
        err << "sandbox demo: cannot run " << kNetnsRunScript << "; flying in-process instead\n";
      } else {
        out << "sandbox demo: no private network namespace here (needs root or user namespaces): "
               "the example model flies in this process over memq://\n";
      }
      in_process = true;
    }
    CreateOutputFolder(out_dir);
    std::ostringstream seconds;
    seconds << duration_s;
    std::vector<std::string> run_args = {"--duration", seconds.str(), "--out",         out_dir,
                                         "--frames",   "jpg,mp4",     "--scans-every", "1"};
    if (web) run_args.insert(run_args.end(), {"--web", parsed->Value("--web")});
    if (parsed->flags.count("--web-control")) run_args.push_back("--web-control");
    for (const char* option : {"--record", "--foxglove"}) {
      if (parsed->values.count(option))
        run_args.insert(run_args.end(), {option, parsed->Value(option)});
    }
    StatusListener status;
    RunHooks hooks;
    hooks.before_close = [&status](bridge::LcmLink&) { status.input.reset(); };
    pid_t model = -1;
    if (in_process) {
      run_args.insert(run_args.end(), {"--lcm-url", "memq://"});
      // The pilot keeps its own sequence number (it outlives this block).
      hooks.before_tick = [&status, seq = std::int64_t{0}](bridge::LcmLink& link,
                                                           double wall_s) mutable {
        status.Poll(link);
        sandbox_msgs::robot_pose_t pose;
        sandbox_msgs::bone_values_t bones;
        bridge::ExampleFlight(wall_s, seq++, bridge::NowUtime(), &pose, &bones);
        std::vector<std::uint8_t> bytes(std::size_t(pose.getEncodedSize()));
        pose.encode(bytes.data(), 0, int(bytes.size()));
        link.Inject("ELAHA/POSE", bytes.data(), unsigned(bytes.size()));
        bytes.resize(std::size_t(bones.getEncodedSize()));
        bones.encode(bytes.data(), 0, int(bytes.size()));
        link.Inject("ELAHA/BONES", bytes.data(), unsigned(bytes.size()));
      };
      out << "sandbox demo: flying the example model in-process for " << duration_s << " s\n";
    } else {
      // The model takes off at the loop's first tick: the level's loading
      // (seconds on a slow machine) does not eat into its flight.
      const std::string model_log = (std::filesystem::path(out_dir) / "fly_wing.log").string();
      hooks.before_tick = [&status, &model, &out, duration_s, model_log](bridge::LcmLink& link,
                                                                         double) {
        if (model < 0) {
          model = StartFlyWing(duration_s, model_log);
          out << "sandbox demo: the example model (" << kFlyWingBinary << ", pid " << model
              << ") flies the wing over LCM for " << duration_s << " s\n"
              << std::flush;
        }
        status.Poll(link);
      };
    }
    out << std::flush;
    const int code = RunLoop(run_args, out, err, hooks);  // 0, or 3: some output lost
    if (model > 0) {  // it flies as long as the loop runs: give it a moment to finish
      int model_status = 0;
      for (int i = 0; i < 40 && waitpid(model, &model_status, WNOHANG) == 0; ++i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
      }
      if (kill(model, SIGTERM) == 0) waitpid(model, &model_status, 0);
    }
    if (code != 0 && code != SandboxLoop::kExitOutputLost) return code;
    out << "  status heartbeat: " << status.heard << " ELAHA/STATUS messages heard, last loop rate "
        << std::fixed << std::setprecision(1) << status.last_rate_hz << " Hz\n";
    const std::filesystem::path dir = std::filesystem::absolute(out_dir);
    WriteOverview(dir, "overview.jpg");
    out << "\nsandbox demo: done. Everything is in " << dir.string() << ":\n"
        << "  chase.mp4, trailing.mp4, belly.mp4   the cameras as video\n"
        << "  chase/chase_<tick>.jpg, ...          the frames, indexed by chase.csv, ...\n"
        << "  belly/belly_<tick>_depth.png         the payload camera's depth (16-bit mm)\n"
        << "  scans/scanner_<tick>.ply, .png       the face scan every second (red occupied) and\n"
        << "                                       its sheet (the six faces as distance images)\n"
        << "  ticks.csv, ticks.png                 every tick's duration, and its plot\n"
        << "  overview.jpg                         the cameras' last frames and the plot\n";
    if (model > 0) out << "  fly_wing.log                         the example model's output\n";
    return code;
  } catch (const UsageError& error) {
    err << "sandbox demo: " << error.what() << "\n";
    return 2;
  } catch (const std::exception& error) {
    err << "sandbox demo: " << error.what() << "\n";
    return 1;
  }
}

}  // namespace sandbox::app
