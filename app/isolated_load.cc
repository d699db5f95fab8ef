#include "app/isolated_load.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <new>
#include <sstream>

#include "app/command_line.h"
#include "app/images.h"
#include "app/loaded_level.h"
#include "scene/manifest.h"

namespace sandbox::app {
namespace {

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kAddressSanitizer = true;  // its shadow memory needs terabytes of address space
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kAddressSanitizer = true;
#else
constexpr bool kAddressSanitizer = false;
#endif
#else
constexpr bool kAddressSanitizer = false;
#endif

// The limits the level sets (a manifest's [level] table; read here, in this
// process: it is our own parser), else the defaults.
scene::LoadLimits LimitsOf(const std::string& file) {
  std::string extension = std::filesystem::path(file).extension().string();
  for (char& c : extension) c = char(std::tolower(static_cast<unsigned char>(c)));
  return extension == ".toml" ? scene::ParseManifest(file).limits : scene::LoadLimits{};
}

std::string& LoaderProgram() {
  static std::string program;  // empty: this program
  return program;
}

std::string SignalName(int signal) {
  const char* name = strsignal(signal);
  return std::string(name != nullptr ? name : "a signal") + ", signal " + std::to_string(signal);
}

}  // namespace

void SetIsolatedLoader(const std::string& program) { LoaderProgram() = program; }

void CheckLoadsInIsolation(const std::string& file, const scene::AssetConversion& conversion) {
  const scene::LoadLimits limits = LimitsOf(file);
  std::string self = LoaderProgram();
  if (self.empty()) {
    char path[4096];
    const ssize_t length = readlink("/proc/self/exe", path, sizeof(path) - 1);
    if (length <= 0) throw scene::LevelError(file + ": cannot find this program to load it apart");
    self.assign(path, std::size_t(length));
  }
  std::vector<std::string> argv_strings = {self, "__load-level", file};
  if (conversion.up)
    argv_strings.insert(argv_strings.end(), {"--up", scene::ToString(*conversion.up)});
  if (conversion.unit_scale_m) {
    std::ostringstream scale;
    scale.precision(17);
    scale << *conversion.unit_scale_m;
    argv_strings.insert(argv_strings.end(), {"--unit-scale", scale.str()});
  }
  std::vector<char*> argv;
  for (std::string& s : argv_strings) argv.push_back(s.data());
  argv.push_back(nullptr);

  int out[2];
  if (pipe2(out, O_CLOEXEC) != 0) throw scene::LevelError(file + ": cannot make a pipe");
  const pid_t child = fork();
  if (child < 0) throw scene::LevelError(file + ": cannot start a process to load it");
  if (child == 0) {
    // Only async-signal-safe calls between fork and exec.
    dup2(out[1], STDOUT_FILENO);
    const rlim_t cpu_s = rlim_t(limits.max_import_s);
    const rlimit cpu{cpu_s, cpu_s + 1};
    setrlimit(RLIMIT_CPU, &cpu);
    if (!kAddressSanitizer) {
      const rlim_t bytes = rlim_t(limits.max_import_mb) << 20;
      const rlimit memory{bytes, bytes};
      setrlimit(RLIMIT_AS, &memory);
    }
    execv(argv[0], argv.data());
    _exit(127);
  }
  close(out[1]);

  // What the child says, line by line, until it ends (or takes twice its CPU
  // time in wall time: then it is waiting on something and is killed).
  std::string said, reading, reader = "assimp", error;
  bool started = false;
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::seconds(2 * limits.max_import_s + 10);
  bool timed_out = false;
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      timed_out = true;
      kill(child, SIGKILL);
      break;
    }
    pollfd wait_for{out[0], POLLIN, 0};
    if (poll(&wait_for, 1, int(std::min<long long>(left.count(), 1000))) < 0 && errno != EINTR) {
      break;
    }
    char buffer[4096];
    const ssize_t n = read(out[0], buffer, sizeof(buffer));
    if (n == 0) break;  // the child has ended
    if (n < 0) continue;
    said.append(buffer, std::size_t(n));
    for (std::size_t end; (end = said.find('\n')) != std::string::npos; said.erase(0, end + 1)) {
      const std::string line = said.substr(0, end);
      if (line == "started") started = true;
      if (const std::size_t tab = line.find('\t');
          line.rfind("reading ", 0) == 0 && tab != std::string::npos) {
        reader = line.substr(8, tab - 8);
        reading = line.substr(tab + 1);
      }
      if (line.rfind("error ", 0) == 0) error = line.substr(6);
    }
  }
  close(out[0]);
  int status = 0;
  while (waitpid(child, &status, 0) < 0 && errno == EINTR) {
  }
  const std::string where = reading.empty() ? file : reading;
  if (timed_out) {
    throw scene::LevelError(where + ": loading it did not end within " +
                            std::to_string(2 * limits.max_import_s + 10) + " s");
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return;
  if (WIFEXITED(status) && !error.empty()) throw scene::LevelError(error);
  if (!started) {
    throw scene::LevelError(file + ": the process that loads it apart could not start (" +
                            (WIFSIGNALED(status)
                                 ? SignalName(WTERMSIG(status))
                                 : "exit code " + std::to_string(WEXITSTATUS(status))) +
                            "); [level] max_import_mb = " + std::to_string(limits.max_import_mb) +
                            " may be below what the program itself needs (about 600)");
  }
  if (WIFSIGNALED(status) && WTERMSIG(status) == SIGXCPU) {
    throw scene::LevelError(where + ": importing it took more than " +
                            std::to_string(limits.max_import_s) +
                            " s of CPU ([level] max_import_s in a level manifest)");
  }
  if (WIFSIGNALED(status)) {
    throw scene::LevelError(
        where + ": " + reader + " crashed reading it (" + SignalName(WTERMSIG(status)) +
        "); the file is corrupt or shows a bug of " + reader +
        " (docs/explanation/reliability.md), or reading it needed more than its [level] "
        "max_import_mb = " +
        std::to_string(limits.max_import_mb));
  }
  throw scene::LevelError(where + ": loading it apart failed (exit code " +
                          std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) + ")");
}

int RunLoadLevelChild(const std::vector<std::string>& args, std::ostream& out) {
  scene::LoadOptions options;
  for (std::size_t i = 1; i + 1 < args.size(); i += 2) {
    if (args[i] == "--up") options.conversion.up = scene::ParseUpAxis(args[i + 1]);
    if (args[i] == "--unit-scale") options.conversion.unit_scale_m = std::stod(args[i + 1]);
  }
  if (args.empty()) return 2;
  out << "started" << std::endl;
  std::string reading = args[0];
  options.on_file = [&out, &reading](const std::filesystem::path& file, std::string_view reader) {
    reading = file.string();
    out << "reading " << reader << '\t' << reading << std::endl;
  };
  // One line each: the parent reads lines.
  auto error_line = [&out](std::string message) {
    for (char& c : message) c = c == '\n' ? ' ' : c;
    out << "error " << message << std::endl;
  };
  try {
    const LoadedLevel loaded = LoadCheckedLevel(args[0], options);
    // The textures too, as the renderer will decode them (OpenCV, libpng, ...).
    const scene::Level& level = loaded.level;
    const render::TextureDecoder decode = OpenCvTextureDecoder(level.limits);
    for (const scene::Material& material : level.materials) {
      render::RgbaImage image;
      if (!material.base_color_texture_path.empty()) {
        options.on_file(material.base_color_texture_path, "the texture decoder (OpenCV)");
        decode(nullptr, material.base_color_texture_path, &image);
      }
      for (const int t :
           {material.base_color_texture_embedded, material.lightmap_texture_embedded}) {
        if (t < 0 || t >= int(level.textures.size())) continue;
        options.on_file(level.name + " (a texture embedded in it)", "the texture decoder (OpenCV)");
        decode(&level.textures[std::size_t(t)], "", &image);
      }
    }
    out << "ok" << std::endl;
    return 0;
  } catch (const scene::LevelError& error) {
    error_line(error.what());
  } catch (const std::bad_alloc&) {
    error_line(reading + ": importing it needed more than " +
               std::to_string(LimitsOf(args[0]).max_import_mb) +
               " MB ([level] max_import_mb in a level manifest)");
  } catch (const std::exception& error) {
    error_line(reading + ": " + error.what());
  }
  return 1;
}

}  // namespace sandbox::app
