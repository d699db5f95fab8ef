// _Lockstep: `sandbox run --lockstep` in-process, ticked from Python. Each
// step hands the loop (app::SandboxLoop, stepped: BeginSteps, Step, Finish)
// its inputs as if they had arrived on LCM, runs the tick on the calling
// thread with the GIL released, and returns every message the tick published
// (RunHooks::published). The loop is the program's own: outputs, files and
// recordings are those of `sandbox run --replay` on the same inputs.

#include <pybind11/stl.h>

#include <cstdint>
#include <memory>
#include <mutex>
#include <sstream>
#include <streambuf>
#include <string>
#include <tuple>
#include <vector>

#include "app/command_line.h"
#include "app/run_options.h"
#include "app/sandbox_loop.h"
#include "python/lcm_access.h"

namespace py = pybind11;

namespace sandbox::python {
namespace {

using Message = std::tuple<std::string, py::bytes>;

// A text stream several threads may write and read (the loop's error
// stream: the frame threads write to it too).
class SharedText : public std::streambuf {
 public:
  std::string str() {
    std::lock_guard<std::mutex> lock(mutex_);
    return text_;
  }

 protected:
  int overflow(int c) override {
    if (c == traits_type::eof()) return traits_type::not_eof(c);
    std::lock_guard<std::mutex> lock(mutex_);
    text_.push_back(char(c));
    return c;
  }
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    std::lock_guard<std::mutex> lock(mutex_);
    text_.append(s, std::size_t(n));
    return n;
  }

 private:
  std::mutex mutex_;
  std::string text_;
};

class Lockstep {
 public:
  explicit Lockstep(std::vector<std::string> args) {
    for (const char* refused : {"--replay", "--view", "--lcm-url", "--lockstep"}) {
      for (const std::string& arg : args) {
        if (arg == refused) {
          throw py::value_error(std::string(refused) +
                                " is not for a stepped run (its inputs are step()'s, in-process)");
        }
      }
    }
    args.insert(args.end(), {"--lockstep", "--lcm-url", "memq://", "--realtime", "off"});
    std::ostringstream usage_error;
    const auto parsed = app::ParseArgs(args, "run", app::kRunValueOptions, app::kRunFlags,
                                       "(the options of sandbox run --help)\n", usage_error);
    if (!parsed) throw py::value_error(usage_error.str().substr(0, usage_error.str().find('\n')));
    app::RunOptions options;
    try {
      options = app::ParseRunOptions(*parsed);
    } catch (const app::UsageError& error) {
      throw py::value_error(error.what());
    }
    app::RunHooks hooks;
    hooks.route_signals = false;
    hooks.published = [this](const std::string& channel, const void* data, unsigned size) {
      const auto* bytes = static_cast<const std::uint8_t*>(data);
      published_.emplace_back(channel, std::vector<std::uint8_t>(bytes, bytes + size));
    };
    py::gil_scoped_release release;
    loop_ = std::make_unique<app::SandboxLoop>(options, std::move(hooks), out_, err_);
    loop_->BeginSteps();
  }

  ~Lockstep() {
    try {
      Close();
    } catch (...) {  // a destructor does not throw; close() says it
    }
  }

  std::vector<std::tuple<std::string, std::string>> Robots() const {
    std::vector<std::tuple<std::string, std::string>> robots;
    const app::LoadedLevel& loaded = loop_->loaded_level();
    for (std::size_t r = 0; r < loaded.level.robots.size(); ++r) {
      robots.emplace_back(loaded.level.robots[r].name, loaded.bridges[r].channel_prefix);
    }
    return robots;
  }
  std::vector<std::string> Actors() const {
    std::vector<std::string> names;
    for (const scene::Actor& actor : loop_->level().actors) {
      if (actor.movable) names.push_back(actor.name);
    }
    return names;
  }
  std::string LevelName() const { return loop_->level().name; }

  // One tick: the inputs in, the tick's outputs back (channel, bytes).
  std::tuple<std::int64_t, std::vector<Message>> Step(
      const std::vector<std::tuple<std::string, py::bytes>>& inputs) {
    std::lock_guard<std::mutex> lock(step_mutex_);  // (taken with the GIL held: no deadlock)
    if (closed_ || loop_->ended()) throw py::value_error("the run has ended");
    std::vector<bridge::LogEvent> events;
    events.reserve(inputs.size());
    for (const auto& [channel, data] : inputs) {
      const std::string_view bytes = data;
      events.push_back({channel, std::vector<std::uint8_t>(bytes.begin(), bytes.end())});
    }
    const std::size_t said_before = err_text_.str().size();
    published_.clear();
    bool ticked = false;
    {
      py::gil_scoped_release release;
      ticked = loop_->Step(events);
    }
    if (!ticked) {
      const std::string said = err_text_.str().substr(said_before);
      throw py::value_error(
          "the inputs gave no robot a pose it accepted (a lock-step tick needs one: its time is "
          "the pose's utime)" +
          (said.empty() ? std::string() : ":\n" + said));
    }
    std::vector<Message> outputs;
    outputs.reserve(published_.size());
    for (const auto& [channel, data] : published_) {
      outputs.emplace_back(channel,
                           py::bytes(reinterpret_cast<const char*>(data.data()), data.size()));
    }
    published_.clear();
    return {tick_++, std::move(outputs)};
  }

  // Ends the run: files closed, the summary returned (what sandbox run prints).
  std::string Close() {
    std::lock_guard<std::mutex> lock(step_mutex_);
    if (!closed_) {
      closed_ = true;
      py::gil_scoped_release release;
      code_ = loop_->Finish();
    }
    return out_.str();
  }
  int exit_code() const { return code_; }
  std::string messages() { return err_text_.str(); }

 private:
  std::ostringstream out_;
  SharedText err_text_;
  std::ostream err_{&err_text_};
  std::unique_ptr<app::SandboxLoop> loop_;
  std::mutex step_mutex_;  // one step (or the close) at a time, whichever thread
  std::vector<std::pair<std::string, std::vector<std::uint8_t>>> published_;
  std::int64_t tick_{0};
  bool closed_{false};
  int code_{0};
};

}  // namespace

void BindLockstep(py::module_& module) {
  py::class_<Lockstep>(module, "_Lockstep",
                       "sandbox run --lockstep in-process, stepped (sandbox.Lockstep is the "
                       "interface).")
      .def(py::init<std::vector<std::string>>(), py::arg("args"))
      .def_property_readonly("robots", &Lockstep::Robots, "[(name, channel prefix)]")
      .def_property_readonly("actors", &Lockstep::Actors, "the movable actors' names")
      .def_property_readonly("name", &Lockstep::LevelName)
      .def("step", &Lockstep::Step, py::arg("inputs"),
           "(tick, [(channel, bytes)]): the inputs given to the loop, one tick run")
      .def("close", &Lockstep::Close, "ends the run; its summary")
      .def_property_readonly("exit_code", &Lockstep::exit_code)
      .def_property_readonly("messages", &Lockstep::messages,
                             "what the run has said on its error stream");
}

}  // namespace sandbox::python
