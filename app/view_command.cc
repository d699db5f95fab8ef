#include "app/view_command.h"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>

#include "app/command_line.h"
#include "app/defaults.h"
#include "app/run_options.h"
#include "app/run_summary.h"
#include "app/sandbox_loop.h"
#include "app/stop_request.h"
#include "web/level_model.h"
#include "web/player.h"
#include "web/stream_server.h"

namespace sandbox::app {
namespace {

const char* kUsage =
    "usage: sandbox view LOG [--level LEVEL] [--web [ADDR:]PORT] [--isolate]\n"
    "  LOG       an LCM log of a run's inputs (lcm-logger, fly_wing --write-log) or a run's\n"
    "            --record log or MCAP file (its STATE messages replayed as inputs), replayed\n"
    "            in lock-step first (with a progress line), then shown in the browser view\n"
    "            with a player: play, pause, speed, a time slider, a jump to a tick\n"
    "  --level   the level it was flown in (default: the bundled sample level)\n"
    "  --web     where to serve it (default 127.0.0.1 and any free port; the address is\n"
    "            printed); docs/reference/web.md\n"
    "  --isolate read a manifest's files in a separate process first\n"
    "Keeps every tick's poses and joints, and the sensors' samples once a second of the\n"
    "log's time (about 35 MB a minute of a 100 Hz flight of the sample level).\n";

// The replayed run: each tick's state, and the ones with their samples (the
// loop sends samples once every RunHooks::web_samples_every_s).
struct Recording {
  std::vector<web::StreamState> states;   // samples dropped, see below
  std::vector<std::size_t> sample_ticks;  // ticks whose samples are kept, in order
  std::vector<web::StreamState> samples;  // the states of those ticks, with their samples

  void Add(web::StreamState&& state) {
    if (state.has_samples) {
      sample_ticks.push_back(states.size());
      samples.push_back(state);
    }
    state.has_samples = false;
    state.samples.clear();
    states.push_back(std::move(state));
  }
  // The samples shown at tick `tick`: the newest kept at or before it, or null.
  const web::StreamState* SamplesAt(std::size_t tick, std::size_t* index) const {
    const auto after = std::upper_bound(sample_ticks.begin(), sample_ticks.end(), tick);
    if (after == sample_ticks.begin()) return nullptr;
    *index = std::size_t(after - sample_ticks.begin()) - 1;
    return &samples[*index];
  }
};

}  // namespace

int RunView(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  const auto parsed = ParseArgs(args, "view", {"--level", "--web"}, {"--isolate"}, kUsage, err);
  if (!parsed) return 2;
  if (parsed->help) {
    out << kUsage;
    return 0;
  }
  if (!parsed->level) {
    err << "sandbox view: which log? (sandbox view LOG)\n" << kUsage;
    return 2;
  }
  RunOptions options;
  options.level = parsed->Value("--level", kDefaultLevel);
  options.replay_file = *parsed->level;
  options.lockstep = true;
  options.realtime = false;
  options.isolate = parsed->flags.count("--isolate") > 0;
  try {
    ParseWebAddress(parsed->Value("--web", "0"), &options);
  } catch (const UsageError& error) {
    err << "sandbox view: " << error.what() << "\n";
    return 2;
  }
  web::ServerOptions server_options;
  server_options.address = options.web_address;
  server_options.port = options.web_port;
  server_options.page_dir = SANDBOX_WEB_PAGE_DIR;
  options.web_port = -1;  // the replay serves nothing; the player below does
  try {
    Recording recording;
    RunHooks hooks;
    hooks.web_state = [&recording](web::StreamState&& state) { recording.Add(std::move(state)); };
    hooks.web_samples_every_s = 1.0;  // the usage's "once a second of the log's time"
    SandboxLoop loop(options, hooks, out, err);
    if (loop.Run() != 0) return 1;
    if (recording.states.empty()) {
      err << "sandbox view: " << options.replay_file
          << ": no pose to replay (no <robot>/POSE or <robot>/STATE of this level's robots)\n";
      return 1;
    }
    std::vector<double> times;
    for (const web::StreamState& state : recording.states) times.push_back(state.time_s);
    std::mutex mutex;  // the playhead: the server's thread commands, this one reads
    web::Playhead playhead(times);
    const auto start = std::chrono::steady_clock::now();
    auto now_s = [&start] {
      return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    };
    bool commanded = false;
    server_options.on_text = [&](const std::string& text) -> std::string {
      try {
        const web::PlayerCommand command = web::ParsePlayerCommand(text);
        std::lock_guard<std::mutex> lock(mutex);
        playhead.Apply(command, now_s());
        commanded = true;
        return "";
      } catch (const std::invalid_argument& error) {
        return error.what();
      }
    };
    web::StreamServer server(server_options);
    const web::RecordedRun recorded{options.replay_file, std::int64_t(recording.states.size()),
                                    times.back() - times.front()};
    server.SetLevel(web::LevelInfoJson(loop.level(), &recorded),
                    web::MakeLevelModel(loop.level()).glb);
    out << "sandbox view: " << recording.states.size() << " ticks of " << options.replay_file
        << " at " << server.url() << " (Ctrl-C ends)\n"
        << std::flush;

    StopRequest stop;
    SignalRoute route(stop);
    std::size_t shown = SIZE_MAX, shown_samples = SIZE_MAX;
    std::int64_t connections = 0;
    while (stop.SleepUntil(std::chrono::steady_clock::now() + std::chrono::milliseconds(5))) {
      if (!server.WantsState()) continue;
      std::size_t tick;
      web::StreamState state;
      {
        std::lock_guard<std::mutex> lock(mutex);
        tick = playhead.At(now_s());
        state = recording.states[tick];
        state.has_player = true;
        state.playing = playhead.playing();
        state.speed = playhead.speed();
        // Unchanged and nobody new: nothing to send.
        const std::int64_t seen = server.counts().connections;
        if (tick == shown && !commanded && seen == connections) continue;
        commanded = false;
        if (seen != connections) shown_samples = SIZE_MAX;  // the newcomer has none
        connections = seen;
      }
      shown = tick;
      std::size_t index = 0;
      const web::StreamState* samples = recording.SamplesAt(tick, &index);
      if (samples != nullptr && index != shown_samples) {
        shown_samples = index;
        state.has_samples = true;
        state.samples_tick = samples->samples_tick;
        state.samples_origin = samples->samples_origin;
        state.samples = samples->samples;
      }
      server.Publish([state = std::move(state)] {
        return web::EncodedState(web::EncodeState(state), web::EncodeSamples(state));
      });
    }
    out << "sandbox view: done\n";
    PrintWebCounts(server.counts(), out);
    return 0;
  } catch (const UsageError& error) {
    err << "sandbox view: " << error.what() << "\n";
    return 2;
  } catch (const std::exception& error) {
    err << "sandbox view: " << error.what() << "\n";
    return 1;
  }
}

}  // namespace sandbox::app
