#include "app/run_options.h"

#include <cmath>
#include <sstream>

#include "app/defaults.h"

namespace sandbox::app {
namespace {

// --frames: at most one image and one video format, or none.
void ParseFrames(const std::string& text, FramePipelineConfig* config) {
  config->image_format.clear();
  config->video_format.clear();
  if (text == "none") return;
  std::stringstream list(text);
  std::string format;
  while (std::getline(list, format, ',')) {
    std::string& slot = format == "jpg" || format == "png"   ? config->image_format
                        : format == "mp4" || format == "avi" ? config->video_format
                                                             : format;
    if (&slot == &format) {
      throw UsageError(
          "--frames must be jpg, png, mp4 or avi (or a list like jpg,mp4, or none), "
          "got '" +
          format + "'");
    }
    if (!slot.empty()) throw UsageError("--frames: one image and one video format at most");
    slot = format;
  }
  if (config->image_format.empty() && config->video_format.empty()) {
    throw UsageError("--frames: nothing to write in '" + text + "' (none writes no frames)");
  }
}

}  // namespace

const std::set<std::string> kRunValueOptions = {
    "--rate",  "--duration",    "--lcm-url",  "--replay", "--record", "--out",     "--frames",
    "--depth", "--scans-every", "--realtime", "--ticks",  "--web",    "--foxglove"};
const std::set<std::string> kRunFlags = {"--lockstep",   "--view",        "--isolate",
                                         "--no-sensors", "--frames-only", "--web-control"};

RunOptions ParseRunOptions(const ParsedArgs& args) {
  RunOptions options;
  options.level = args.level.value_or(kDefaultLevel);
  auto number = [&](const std::string& option, double fallback) {
    return args.values.count(option) ? ParseNumber(args.Value(option), option) : fallback;
  };
  if (args.Value("--rate") == "max") {
    options.rate_hz = 0.0;
  } else {
    options.rate_hz = number("--rate", 100.0);
    if (!(options.rate_hz >= kMinRateHz && options.rate_hz <= kMaxRateHz)) {
      throw UsageError("--rate must be positive (0.01 to 100000 Hz) or max, got '" +
                       args.Value("--rate") + "'");
    }
  }
  if (args.values.count("--duration")) {
    options.duration_s = number("--duration", 0.0);
    if (!(options.duration_s > 0.0)) {
      throw UsageError("--duration must be positive (leave it out to run until Ctrl-C), got '" +
                       args.Value("--duration") + "'");
    }
  }
  options.lcm_url = args.Value("--lcm-url");
  options.replay_file = args.Value("--replay");
  options.lockstep = options.replay() || args.flags.count("--lockstep") > 0;
  options.record_file = args.Value("--record");
  options.out_dir = args.Value("--out");
  ParseFrames(args.Value("--frames", "jpg"), &options.frames);
  options.frames.depth_format = args.Value("--depth", "png");
  if (options.frames.depth_format != "png" && options.frames.depth_format != "npy" &&
      options.frames.depth_format != "exr") {
    throw UsageError("--depth must be png, npy or exr, got '" + options.frames.depth_format + "'");
  }
  options.scans_every_s = number("--scans-every", 0.0);
  if (args.values.count("--scans-every") &&
      (options.out_dir.empty() || !(options.scans_every_s > 0.0))) {
    throw UsageError("--scans-every needs --out and a positive number of seconds");
  }
  options.view = args.flags.count("--view") > 0;
  options.isolate = args.flags.count("--isolate") > 0;
  const std::string realtime = args.Value("--realtime", "auto");
  if (realtime != "auto" && realtime != "off") {
    throw UsageError("--realtime must be auto or off, got '" + realtime + "'");
  }
  options.realtime = realtime == "auto";
  if (args.values.count("--ticks")) {
    const double ticks = number("--ticks", 0.0);
    if (!(ticks >= 1.0 && ticks <= 1e15 && ticks == std::floor(ticks))) {
      throw UsageError("--ticks must be a whole number of ticks, 1 or more, got '" +
                       args.Value("--ticks") + "'");
    }
    options.ticks = std::int64_t(ticks);
  }
  // Splitting the work over two sandboxes on one pose stream: one scans and
  // publishes, the other only renders (docs/how-to/distributed.md).
  options.publish = args.flags.count("--frames-only") == 0;
  options.sensors = options.publish && args.flags.count("--no-sensors") == 0;
  if (!options.publish) {
    const bool writes_frames = !options.out_dir.empty() && (!options.frames.image_format.empty() ||
                                                            !options.frames.video_format.empty());
    if (!writes_frames && !options.view) {
      throw UsageError(
          "--frames-only renders the cameras: it needs --out DIR (with --frames "
          "other than none) or --view");
    }
    if (!options.record_file.empty() || options.scans_every_s > 0.0) {
      throw UsageError("--frames-only publishes and scans nothing: no --record or --scans-every");
    }
  }
  if (!options.sensors && options.scans_every_s > 0.0) {
    throw UsageError("--no-sensors scans nothing: no --scans-every");
  }
  if (args.values.count("--web")) ParseWebAddress(args.Value("--web"), &options);
  options.web_control = args.flags.count("--web-control") > 0;
  if (options.web_control && options.web_port < 0)
    throw UsageError("--web-control steers the cameras from the browser view: it needs --web");
  if (args.values.count("--foxglove")) {
    ParseServerAddress(args.Value("--foxglove"), "--foxglove", &options.foxglove_address,
                       &options.foxglove_port);
  }
  return options;
}

void ParseWebAddress(const std::string& text, RunOptions* options) {
  ParseServerAddress(text, "--web", &options->web_address, &options->web_port);
}

void ParseServerAddress(const std::string& text, const std::string& option,
                        std::string* address_out, int* port_out) {
  const auto colon = text.rfind(':');
  const std::string port = colon == std::string::npos ? text : text.substr(colon + 1);
  std::string address = colon == std::string::npos ? "127.0.0.1" : text.substr(0, colon);
  if (address.size() > 2 && address.front() == '[' && address.back() == ']') {
    address = address.substr(1, address.size() - 2);  // [IPv6]
  }
  const bool digits = !port.empty() && port.size() <= 5 &&
                      port.find_first_not_of("0123456789") == std::string::npos;
  if (!digits || std::stoi(port) > 65535 || address.empty()) {
    throw UsageError(option +
                     " must be PORT or ADDRESS:PORT (port 0 to 65535, 0: any free one), got '" +
                     text + "'");
  }
  *address_out = address;
  *port_out = std::stoi(port);
}

}  // namespace sandbox::app
