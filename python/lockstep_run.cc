// _Lockstep: `sandbox run --lockstep` in-process, ticked from Python. Each
// step hands the loop (app::SandboxLoop, stepped: BeginSteps, Step, Finish)
// its inputs as if they had arrived on LCM, runs the tick on the calling
// thread with the GIL released, and returns every message the tick published
// (RunHooks::published). The loop is the program's own: outputs, files and
// recordings are those of `sandbox run --replay` on the same inputs.

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
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

// What a tick published (sandbox.Outputs): its number, one buffer holding
// every message (a read-only uint8 array that owns it: nothing copied), and
// where each is in it, by channel (channels in the order they first
// published, messages in publishing order); a channel's messages decoded
// when first asked for. A Mapping {channel: [Message, ...]}.
class Outputs {
 public:
  using Spans = std::vector<std::pair<std::size_t, std::size_t>>;
  Outputs(std::int64_t tick, py::array_t<std::uint8_t> buffer,
          std::vector<std::pair<std::string, Spans>> channels)
      : tick_(tick),
        buffer_(std::move(buffer)),
        channels_(std::move(channels)),
        decoded_(channels_.size()) {}

  std::int64_t tick() const { return tick_; }

  py::list Get(const std::string& channel) {
    const std::size_t c = Find(channel);
    if (!decoded_[c]) decoded_[c] = DecodeSpans(buffer_, channels_[c].second);
    return py::reinterpret_borrow<py::list>(decoded_[c]);
  }
  py::object GetOr(const py::handle& channel, const py::object& otherwise) {
    return Has(channel) ? py::object(Get(channel.cast<std::string>())) : otherwise;
  }
  bool Has(const py::handle& channel) const {
    if (!PyUnicode_Check(channel.ptr())) return false;
    const std::string name = channel.cast<std::string>();
    return std::any_of(channels_.begin(), channels_.end(),
                       [&](const auto& c) { return c.first == name; });
  }
  // The messages' bytes, read-only memoryviews of the one buffer.
  py::list Raw(const std::string& channel) const {
    const Spans& spans = channels_[Find(channel)].second;
    const py::memoryview whole(buffer_);
    py::list views(spans.size());
    for (std::size_t i = 0; i < spans.size(); ++i) {
      const auto [offset, size] = spans[i];
      views[i] = whole[py::slice(py::ssize_t(offset), py::ssize_t(offset + size), 1)];
    }
    return views;
  }
  py::list Channels() const {
    py::list names(channels_.size());
    for (std::size_t c = 0; c < channels_.size(); ++c) names[c] = channels_[c].first;
    return names;
  }
  py::list Values() {
    py::list values(channels_.size());
    for (std::size_t c = 0; c < channels_.size(); ++c) values[c] = Get(channels_[c].first);
    return values;
  }
  py::list Items() {
    py::list items(channels_.size());
    for (std::size_t c = 0; c < channels_.size(); ++c) {
      items[c] = py::make_tuple(channels_[c].first, Get(channels_[c].first));
    }
    return items;
  }
  std::size_t size() const { return channels_.size(); }
  std::string Repr() const {
    std::string shown;
    for (const auto& [channel, spans] : channels_) {
      shown += (shown.empty() ? "" : ", ") + channel + ": " + std::to_string(spans.size());
    }
    return "Outputs(tick " + std::to_string(tick_) + ", " + shown + ")";
  }

 private:
  std::size_t Find(const std::string& channel) const {
    for (std::size_t c = 0; c < channels_.size(); ++c) {
      if (channels_[c].first == channel) return c;
    }
    std::vector<std::string> names;
    for (const auto& c : channels_) names.push_back(c.first);
    std::sort(names.begin(), names.end());
    std::string known;
    for (const std::string& name : names) known += (known.empty() ? "" : ", ") + name;
    throw py::key_error("tick " + std::to_string(tick_) + " published nothing on '" + channel +
                        "'; it published on " + (known.empty() ? "no channel" : known));
  }

  std::int64_t tick_;
  py::array_t<std::uint8_t> buffer_;
  std::vector<std::pair<std::string, Spans>> channels_;
  std::vector<py::object> decoded_;  // null until asked for
};

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
    const app::LoadedLevel& loaded = loop_->loaded_level();
    for (std::size_t r = 0; r < loaded.level.robots.size(); ++r) {
      const std::string& prefix = loaded.bridges[r].channel_prefix;
      Robot robot;
      robot.name = loaded.level.robots[r].name;
      robot.prefix = prefix;
      robot.pose = prefix + "/POSE";
      robot.bones = prefix + "/BONES";
      robots_.push_back(std::move(robot));
    }
  }

  ~Lockstep() {
    try {
      Close();
    } catch (...) {  // a destructor does not throw; close() says it
    }
  }

  std::vector<std::tuple<std::string, std::string>> Robots() const {
    std::vector<std::tuple<std::string, std::string>> robots;
    for (const Robot& robot : robots_) robots.emplace_back(robot.name, robot.prefix);
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
  std::string WebUrl() const { return loop_->web_url(); }
  std::string FoxgloveUrl() const { return loop_->foxglove_url(); }

  // One tick: the inputs in, the tick's outputs back (channel, bytes).
  Outputs Step(const std::vector<std::tuple<std::string, py::bytes>>& inputs) {
    std::vector<bridge::LogEvent> events;
    events.reserve(inputs.size());
    AddEncoded(inputs, &events);
    return Tick(std::move(events));
  }

  // One tick of Lockstep.step(): bone values {robot: values}, messages
  // encoded by the caller [(channel, bytes)] (joints, actors) and poses
  // {robot: (position, orientation) or a position}, given to the loop in
  // that order (BONES, the encoded ones, POSE), at `utime` (None: the last
  // plus `period_us`). A robot without a pose here keeps its last one,
  // re-sent at this time. Everything is checked before the tick runs.
  Outputs StepRobots(const py::object& poses, const py::object& bones,
                     const std::vector<std::tuple<std::string, py::bytes>>& encoded,
                     const py::object& utime_value, std::int64_t period_us) {
    const std::int64_t utime =
        utime_value.is_none() ? (last_utime_ ? *last_utime_ + period_us : 0) : Utime(utime_value);
    std::vector<bridge::LogEvent> events;
    std::vector<Robot*> bones_sent;
    if (!bones.is_none()) {
      for (const auto& [robot, values] : DictArg(bones, "bones", "values")) {
        Robot& r = RobotNamed(robot);
        bones_sent.push_back(&r);
        sandbox_msgs::bone_values_t message;
        message.utime = utime;
        message.seq = r.bones_seq;
        message.values = FiniteVector(values, 0, "bones");
        message.num_values = int(message.values.size());
        events.push_back({r.bones, Encode(message)});
      }
    }
    AddEncoded(encoded, &events);
    std::vector<std::pair<std::size_t, LastPose>> sent;
    if (!poses.is_none()) {
      for (const auto& [robot, pose] : DictArg(poses, "poses", "pose")) {
        sent.emplace_back(std::size_t(&RobotNamed(robot) - robots_.data()), PoseOf(pose));
      }
    }
    for (std::size_t r = 0; r < robots_.size(); ++r) {  // the others' last poses
      const bool given =
          std::any_of(sent.begin(), sent.end(), [r](const auto& p) { return p.first == r; });
      if (!given && robots_[r].last) sent.emplace_back(r, *robots_[r].last);
    }
    if (sent.empty()) {
      throw py::value_error("the first step needs a pose for at least one robot (poses=...)");
    }
    for (const auto& [r, pose] : sent) {
      sandbox_msgs::robot_pose_t message;
      message.utime = utime;
      message.seq = robots_[r].pose_seq;
      std::copy(pose.position.begin(), pose.position.end(), message.position);
      std::copy(pose.orientation.begin(), pose.orientation.end(), message.orientation);
      events.push_back({robots_[r].pose, Encode(message)});
    }
    for (bridge::LogEvent& event : events) event.utime = utime;  // as a recording stamps them
    Outputs published = Tick(std::move(events));
    for (const auto& [r, pose] : sent) {
      robots_[r].last = pose;
      ++robots_[r].pose_seq;
    }
    for (Robot* r : bones_sent) ++r->bones_seq;
    last_utime_ = utime;
    return published;
  }

  std::optional<std::int64_t> last_utime() const { return last_utime_; }

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
  Outputs Tick(std::vector<bridge::LogEvent> events) {
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
    const py::capsule owner(arena,
                            [](void* p) { delete static_cast<std::vector<std::uint8_t>*>(p); });
    py::array_t<std::uint8_t> buffer({py::ssize_t(arena->size())}, {py::ssize_t(1)}, arena->data(),
                                     owner);
    py::detail::array_proxy(buffer.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
    std::vector<std::pair<std::string, Outputs::Spans>> channels;
    for (const auto& [channel, offset, size] : published_) {
      auto c = std::find_if(channels.begin(), channels.end(),
                            [&](const auto& known) { return known.first == channel; });
      if (c == channels.end()) c = channels.insert(channels.end(), {channel, {}});
      c->second.emplace_back(offset, size);
    }
    return Outputs(tick_++, std::move(buffer), std::move(channels));
  }

  struct LastPose {
    std::array<double, 3> position;
    std::array<double, 4> orientation;
  };
  struct Robot {
    std::string name, prefix, pose, bones;  // its name, channel prefix and input channels
    std::int64_t pose_seq{0}, bones_seq{0};
    std::optional<LastPose> last;
  };

  Robot& RobotNamed(const py::handle& name) {
    if (PyUnicode_Check(name.ptr())) {
      const std::string wanted = name.cast<std::string>();
      for (Robot& robot : robots_) {
        if (robot.name == wanted) return robot;
      }
    }
    std::string known;
    for (const Robot& robot : robots_) known += (known.empty() ? "" : ", ") + robot.name;
    throw py::key_error("no robot " + std::string(py::repr(name)) + "; the level has " +
                        (known.empty() ? std::string("none") : known));
  }

  static py::dict DictArg(const py::object& value, const char* argument, const char* what) {
    if (!PyDict_Check(value.ptr())) {
      throw py::value_error(std::string(argument) + " must be a dict {robot: " + what + "}, got " +
                            std::string(py::repr(value)));
    }
    return py::reinterpret_borrow<py::dict>(value);
  }

  // (position, orientation), or a position alone (the identity orientation).
  static LastPose PoseOf(const py::handle& pose) {
    py::object position = py::reinterpret_borrow<py::object>(pose);
    py::object orientation = py::make_tuple(1.0, 0.0, 0.0, 0.0);
    if (PySequence_Check(pose.ptr()) && PySequence_Size(pose.ptr()) == 2) {
      py::object first = py::reinterpret_borrow<py::sequence>(pose)[0];
      if (py::hasattr(first, "__len__")) {
        position = std::move(first);
        orientation = py::reinterpret_borrow<py::sequence>(pose)[1];
      }
    }
    PyErr_Clear();  // PySequence_Size of a sequence without a length
    const std::vector<double> p = FiniteVector(position, 3, "position");
    const std::vector<double> q = FiniteVector(orientation, 4, "orientation");
    const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (std::abs(norm - 1.0) > 1e-6) {
      throw py::value_error("orientation must be a unit quaternion (w, x, y, z), its norm is " +
                            std::to_string(norm));
    }
    return {{p[0], p[1], p[2]}, {q[0], q[1], q[2], q[3]}};
  }

  // Whole microseconds that fit LCM's int64, as Python's int() reads them.
  static std::int64_t Utime(const py::handle& value) {
    PyObject* number = PyNumber_Long(value.ptr());
    if (number == nullptr) {
      PyErr_Clear();
      throw py::value_error("utime must be whole microseconds, got " +
                            std::string(py::repr(value)));
    }
    const py::object owned = py::reinterpret_steal<py::object>(number);
    int overflow = 0;
    const long long utime = PyLong_AsLongLongAndOverflow(number, &overflow);
    if (overflow != 0) {
      throw py::value_error("utime must fit in 64 bits, got " + std::string(py::str(owned)));
    }
    return std::int64_t(utime);
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
  std::vector<Robot> robots_;
  std::optional<std::int64_t> last_utime_;
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
  py::class_<Outputs>(module, "Outputs",
                      "What one tick published: {channel: [Message, ...]} in publishing order (a "
                      "face scanner's six faces are six messages on one channel); `tick`. A "
                      "channel's messages are decoded when first asked for (`raw(channel)`: their "
                      "bytes, as read-only memoryviews of the tick's one buffer).")
      .def_property_readonly("tick", &Outputs::tick)
      .def("__getitem__", &Outputs::Get, py::arg("channel"))
      .def("get", &Outputs::GetOr, py::arg("channel"), py::arg("default") = py::none())
      .def("__contains__", &Outputs::Has, py::arg("channel"))
      .def("raw", &Outputs::Raw, py::arg("channel"),
           "the channel's messages undecoded: read-only memoryviews of the tick's buffer")
      .def("keys", &Outputs::Channels)
      .def("values", &Outputs::Values)
      .def("items", &Outputs::Items)
      .def("__iter__", [](const Outputs& outputs) { return py::iter(outputs.Channels()); })
      .def("__len__", &Outputs::size)
      .def("__repr__", &Outputs::Repr);
  py::class_<Lockstep>(module, "_Lockstep",
                       "sandbox run --lockstep in-process, stepped (sandbox.Lockstep is the "
                       "interface).")
      .def(py::init<std::vector<std::string>>(), py::arg("args"))
      .def_property_readonly("robots", &Lockstep::Robots, "[(name, channel prefix)]")
      .def_property_readonly("actors", &Lockstep::Actors, "the movable actors' names")
      .def_property_readonly("name", &Lockstep::LevelName)
      .def_property_readonly("web_url", &Lockstep::WebUrl,
                             "the browser view's address (--web), or ''")
      .def_property_readonly("foxglove_url", &Lockstep::FoxgloveUrl,
                             "the Foxglove WebSocket server's address (--foxglove), or ''")
      .def("step", &Lockstep::Step, py::arg("inputs"),
           "Outputs: the inputs given to the loop, one tick run")
      .def("step_robots", &Lockstep::StepRobots, py::arg("poses"), py::arg("bones"),
           py::arg("encoded"), py::arg("utime"), py::arg("period_us"),
           "Outputs: Lockstep.step()'s tick: bone values "
           "{robot: values}, encoded messages [(channel, bytes)], poses {robot: pose}, utime or "
           "None (the last plus period_us)")
      .def_property_readonly("last_utime", &Lockstep::last_utime,
                             "the last step's utime (None before)")
      .def("close", &Lockstep::Close, "ends the run; its summary")
      .def_property_readonly("exit_code", &Lockstep::exit_code)
      .def_property_readonly("messages", &Lockstep::messages,
                             "what the run has said on its error stream");
}

}  // namespace sandbox::python
