// _Lockstep: `sandbox run --lockstep` in-process, ticked from Python. Each
// step hands the loop (app::SandboxLoop, stepped: BeginSteps, Step, Finish)
// its inputs as if they had arrived on LCM, runs the tick on the calling
// thread with the GIL released, and returns every message the tick published
// (RunHooks::published). The loop is the program's own: outputs, files and
// recordings are those of `sandbox run --replay` on the same inputs.

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
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
#include "python/arguments.h"
#include "python/lcm_access.h"
#include "sandbox_msgs/bone_values_t.hpp"
#include "sandbox_msgs/robot_pose_t.hpp"

namespace py = pybind11;

namespace sandbox::python {
namespace {

// What a tick published: its number, one buffer holding every message (a
// read-only uint8 array that owns it: nothing copied), and where each is in
// it: (channel, offset, size).
using Published =
    std::tuple<std::int64_t, py::array_t<std::uint8_t>,
               std::vector<std::tuple<std::string, std::size_t, std::size_t>>>;

// A text stream several threads may write and read (the loop's error
// stream: the frame threads write to it too).
class SharedText : public std::streambuf {
 public:
  std::string str() {
    std::lock_guard<std::mutex> lock(mutex_);
    return text_;
  }
  std::size_t size() {
    std::lock_guard<std::mutex> lock(mutex_);
    return text_.size();
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
      published_.emplace_back(channel, arena_->size(), size);
      arena_->insert(arena_->end(), bytes, bytes + size);
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
  Published Step(
      const std::vector<std::tuple<std::string, py::bytes>>& inputs) {
    std::vector<bridge::LogEvent> events;
    events.reserve(inputs.size());
    AddEncoded(inputs, &events);
    return Tick(std::move(events));
  }

  // One tick on bone values, messages encoded by the caller and poses, in
  // that order; the bone values and poses are checked and encoded here
  // (BONES and POSE at `utime`, each channel's seq counting from 0).
  Published StepValues(
      const std::vector<std::tuple<std::string, py::handle>>& bones,
      const std::vector<std::tuple<std::string, py::bytes>>& encoded,
      const std::vector<std::tuple<std::string, py::handle, py::handle>>& poses,
      std::int64_t utime) {
    std::vector<bridge::LogEvent> events;
    events.reserve(bones.size() + encoded.size() + poses.size());
    for (const auto& [channel, values] : bones) {
      sandbox_msgs::bone_values_t message;
      message.utime = utime;
      message.seq = NextSeq(channel);
      message.values = FiniteVector(values, 0, "bones");
      message.num_values = int(message.values.size());
      events.push_back({channel, Encode(message)});
    }
    AddEncoded(encoded, &events);
    for (const auto& [channel, position, orientation] : poses) {
      const std::vector<double> p = FiniteVector(position, 3, "position");
      const std::vector<double> q = FiniteVector(orientation, 4, "orientation");
      const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
      if (std::abs(norm - 1.0) > 1e-6) {
        throw py::value_error("orientation must be a unit quaternion (w, x, y, z), its norm is " +
                              std::to_string(norm));
      }
      sandbox_msgs::robot_pose_t message;
      message.utime = utime;
      message.seq = NextSeq(channel);
      std::copy(p.begin(), p.end(), message.position);
      std::copy(q.begin(), q.end(), message.orientation);
      events.push_back({channel, Encode(message)});
    }
    return Tick(std::move(events));
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
  Published Tick(std::vector<bridge::LogEvent> events) {
    std::lock_guard<std::mutex> lock(step_mutex_);  // (taken with the GIL held: no deadlock)
    if (closed_ || loop_->ended()) throw py::value_error("the run has ended");
    const std::size_t said_before = err_text_.size();
    published_.clear();
    arena_->clear();
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
    auto* arena = arena_.release();
    arena_ = std::make_unique<std::vector<std::uint8_t>>();
    arena_->reserve(arena->size());
    const py::capsule owner(arena, [](void* p) { delete static_cast<std::vector<std::uint8_t>*>(p); });
    py::array_t<std::uint8_t> buffer({py::ssize_t(arena->size())}, {py::ssize_t(1)}, arena->data(),
                                     owner);
    py::detail::array_proxy(buffer.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
    return {tick_++, std::move(buffer), std::move(published_)};
  }

  static void AddEncoded(const std::vector<std::tuple<std::string, py::bytes>>& inputs,
                         std::vector<bridge::LogEvent>* events) {
    for (const auto& [channel, data] : inputs) {
      const std::string_view bytes = data;
      events->push_back({channel, std::vector<std::uint8_t>(bytes.begin(), bytes.end())});
    }
  }
  template <typename Type>
  static std::vector<std::uint8_t> Encode(const Type& message) {
    std::vector<std::uint8_t> data(std::size_t(message.getEncodedSize()));
    message.encode(data.data(), 0, int(data.size()));
    return data;
  }
  std::int64_t NextSeq(const std::string& channel) { return seq_[channel]++; }

  std::map<std::string, std::int64_t> seq_;  // per channel encoded here
  std::ostringstream out_;
  SharedText err_text_;
  std::ostream err_{&err_text_};
  std::unique_ptr<app::SandboxLoop> loop_;
  std::mutex step_mutex_;  // one step (or the close) at a time, whichever thread
  std::unique_ptr<std::vector<std::uint8_t>> arena_ =
      std::make_unique<std::vector<std::uint8_t>>();  // this tick's messages, one after another
  std::vector<std::tuple<std::string, std::size_t, std::size_t>> published_;  // where each is
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
           "(tick, buffer, [(channel, offset, size)]): the inputs given to the loop, one tick run")
      .def("step_values", &Lockstep::StepValues, py::arg("bones"), py::arg("encoded"),
           py::arg("poses"), py::arg("utime"),
           "(tick, buffer, [(channel, offset, size)]): bone values [(channel, values)], encoded messages "
           "[(channel, bytes)] and poses [(channel, position, orientation)] given to the loop, "
           "one tick run")
      .def("close", &Lockstep::Close, "ends the run; its summary")
      .def_property_readonly("exit_code", &Lockstep::exit_code)
      .def_property_readonly("messages", &Lockstep::messages,
                             "what the run has said on its error stream");
}

}  // namespace sandbox::python
