// _Lockstep: `sandbox run --lockstep` in-process, on a thread of its own,
// ticked from Python. Each step hands the loop its inputs (as if they had
// arrived on LCM, through RunHooks::lockstep_inputs), waits for the tick to
// end and returns every message the tick published (RunHooks::published).
// The loop is the program's own: outputs, files and recordings are those of
// `sandbox run --replay` on the same inputs.

#include <pybind11/stl.h>

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <memory>
#include <mutex>
#include <sstream>
#include <streambuf>
#include <string>
#include <thread>
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

// A text stream several threads may write and read (the loop's error stream).
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
    if (!parsed) throw py::value_error(FirstLine(usage_error.str()));
    app::RunOptions options;
    try {
      options = app::ParseRunOptions(*parsed);
    } catch (const app::UsageError& error) {
      throw py::value_error(error.what());
    }
    app::RunHooks hooks;
    hooks.route_signals = false;
    hooks.lockstep_inputs = [this](std::vector<bridge::LogEvent>* events) {
      return TakeInputs(events);
    };
    hooks.published = [this](const std::string& channel, const void* data, unsigned size) {
      const auto* bytes = static_cast<const std::uint8_t*>(data);
      std::lock_guard<std::mutex> lock(mutex_);
      published_.emplace_back(channel, std::vector<std::uint8_t>(bytes, bytes + size));
    };
    hooks.end_of_tick = [this](std::int64_t tick) {
      std::lock_guard<std::mutex> lock(mutex_);
      tick_ = tick;
      tick_ended_ = true;
      handed_ = false;
      changed_.notify_all();
    };
    {
      py::gil_scoped_release release;
      loop_ = std::make_unique<app::SandboxLoop>(options, std::move(hooks), out_, err_);
    }
    thread_ = std::thread([this] {
      try {
        code_ = loop_->Run();
      } catch (...) {
        failure_ = std::current_exception();
      }
      std::lock_guard<std::mutex> lock(mutex_);
      finished_ = true;
      changed_.notify_all();
    });
  }

  ~Lockstep() {
    try {
      Finish();
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
    std::vector<bridge::LogEvent> events;
    for (const auto& [channel, data] : inputs) {
      const std::string_view bytes = data;
      events.push_back({channel, std::vector<std::uint8_t>(bytes.begin(), bytes.end())});
    }
    std::vector<std::pair<std::string, std::vector<std::uint8_t>>> published;
    std::int64_t tick = -1;
    std::string refused;
    {
      py::gil_scoped_release release;
      std::unique_lock<std::mutex> lock(mutex_);
      if (finished_ || closing_) {
        refused = "the run has ended";
      } else {
        const std::size_t err_before = ErrSize();
        inputs_ = std::move(events);
        has_inputs_ = true;
        tick_ended_ = no_pose_ = false;
        changed_.notify_all();
        changed_.wait(lock, [this] { return tick_ended_ || no_pose_ || finished_; });
        if (tick_ended_) {
          published.swap(published_);
          tick = tick_;
        } else if (no_pose_) {
          refused = "the inputs gave no robot a pose it accepted (a lock-step tick needs one: "
                    "its time is the pose's utime)" +
                    Said(err_before);
        } else {
          refused = "the run has ended" + Said(err_before);
        }
      }
    }
    if (!refused.empty()) throw py::value_error(refused);
    std::vector<Message> outputs;
    outputs.reserve(published.size());
    for (const auto& [channel, data] : published) {
      outputs.emplace_back(channel,
                           py::bytes(reinterpret_cast<const char*>(data.data()), data.size()));
    }
    return {tick, std::move(outputs)};
  }

  // Ends the run: files closed, the summary returned (what sandbox run prints).
  std::string Close() {
    Finish();
    if (failure_) {
      std::exception_ptr failure = failure_;
      failure_ = nullptr;
      std::rethrow_exception(failure);
    }
    return out_.str();
  }
  int exit_code() const { return code_; }
  std::string messages() { return err_text_.str(); }

 private:
  static std::string FirstLine(const std::string& text) {
    return text.substr(0, text.find('\n'));
  }
  std::size_t ErrSize() { return err_text_.str().size(); }
  std::string Said(std::size_t from) {
    const std::string text = err_text_.str().substr(from);
    return text.empty() ? std::string() : ":\n" + text;
  }

  // On the loop thread: waits for step()'s inputs (false: the run ends).
  bool TakeInputs(std::vector<bridge::LogEvent>* events) {
    std::unique_lock<std::mutex> lock(mutex_);
    if (handed_) {  // the last inputs did not make a tick
      no_pose_ = true;
      changed_.notify_all();
    }
    changed_.wait(lock, [this] { return has_inputs_ || closing_; });
    if (closing_) return false;
    *events = std::move(inputs_);
    has_inputs_ = false;
    handed_ = true;
    return true;
  }

  void Finish() {
    if (!thread_.joinable()) return;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closing_ = true;
      changed_.notify_all();
    }
    py::gil_scoped_release release;
    thread_.join();
  }

  std::ostringstream out_;  // the loop thread's until it has ended
  SharedText err_text_;
  std::ostream err_{&err_text_};
  std::unique_ptr<app::SandboxLoop> loop_;
  std::thread thread_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<bridge::LogEvent> inputs_;
  bool has_inputs_{false}, handed_{false}, tick_ended_{false}, no_pose_{false};
  bool finished_{false}, closing_{false};
  std::int64_t tick_{-1};
  std::vector<std::pair<std::string, std::vector<std::uint8_t>>> published_;
  int code_{0};
  std::exception_ptr failure_;
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
