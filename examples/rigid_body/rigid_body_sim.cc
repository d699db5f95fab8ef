// An external physics model in miniature: one rigid body under gravity and
// the contact wrench an external module computes (<ROBOT>/WRENCH), integrated
// with a fixed step and published as the robot's pose (<ROBOT>/POSE) for the
// sandbox to show and scan. docs/how-to/contact.md explains the chain.
//
//   rigid_body --mass KG (--box-size X,Y,Z | --inertia IXX,IYY,IZZ) [options]
//
// --lockstep: each step waits for the wrench computed from the pose it
// published last (run the sandbox with --lockstep too): the run is a
// function of its inputs, two runs give identical logs. --rate HZ: steps on
// its own clock with the newest wrench it has, as a real-time model would.

#include <signal.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "examples/rigid_body/rigid_body.h"
#include "sandbox_msgs/robot_pose_t.hpp"
#include "sandbox_msgs/robot_state_t.hpp"
#include "sandbox_msgs/wrench_t.hpp"

namespace sandbox::examples {
namespace {

const char* kUsage =
    "usage: rigid_body --mass KG (--box-size X,Y,Z | --inertia IXX,IYY,IZZ) [options]\n"
    "  Publishes <ROBOT>/POSE, subscribes to <ROBOT>/WRENCH (and <ROBOT>/STATE for latency).\n"
    "  --robot NAME             channel prefix (default BOX)\n"
    "  --position X,Y,Z         start, world metres (default 0,0,1)\n"
    "  --rpy-deg R,P,Y          start orientation (default 0,0,0)\n"
    "  --velocity VX,VY,VZ      start velocity, world m/s (default 0)\n"
    "  --angular-velocity X,Y,Z start, body rad/s (default 0)\n"
    "  --dt S                   step (default 0.01: the scanner's 100 Hz)\n"
    "  --substeps N             steps of dt/N per published pose, the wrench held (default 1)\n"
    "  --duration S             simulated seconds (default 10)\n"
    "  --lockstep               wait for each pose's wrench (deterministic)\n"
    "  --rate HZ                real time at HZ poses a second, the newest wrench (default 100)\n"
    "  --latency                print the loop's latency (the sandbox not in lock-step)\n"
    "  --wait S                 lock-step: resend the pose after S without its wrench (default 2)\n"
    "  --log FILE               one CSV row per step: time, pose, velocities, wrench\n"
    "  --lcm-url URL            (default LCM's)\n";

volatile sig_atomic_t g_stop = 0;
void OnSignal(int) { g_stop = 1; }

std::int64_t NowUtime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

struct Options {
  std::string robot = "BOX", log, url;
  RigidBodyParameters body;
  bool have_mass = false, have_inertia = false;
  RigidBodyState start;
  double dt = 0.01, duration_s = 10.0, rate_hz = 100.0, wait_s = 2.0;
  int substeps = 1;
  bool lockstep = false, latency = false;
};

bool ParseVector(const std::string& text, Eigen::Vector3d* v) {
  return std::sscanf(text.c_str(), "%lf,%lf,%lf", &v->x(), &v->y(), &v->z()) == 3 && v->allFinite();
}

std::optional<Options> ParseOptions(int argc, char** argv) {
  Options o;
  o.start.p_W = Eigen::Vector3d(0, 0, 1);
  for (int i = 1; i < argc; ++i) {
    const std::string key = argv[i];
    if (key == "--lockstep" || key == "--latency") {
      (key == "--lockstep" ? o.lockstep : o.latency) = true;
      continue;
    }
    if (key == "--help") return std::nullopt;
    if (i + 1 >= argc) {
      std::fprintf(stderr, "rigid_body: %s needs a value\n", key.c_str());
      return std::nullopt;
    }
    const std::string value = argv[++i];
    char* end = nullptr;
    const double number = std::strtod(value.c_str(), &end);
    const bool positive =
        end != value.c_str() && *end == '\0' && std::isfinite(number) && number > 0;
    Eigen::Vector3d v;
    bool ok = true;
    if (key == "--robot")
      o.robot = value;
    else if (key == "--log")
      o.log = value;
    else if (key == "--lcm-url")
      o.url = value;
    else if (key == "--mass")
      ok = positive, o.body.mass_kg = number, o.have_mass = true;
    else if (key == "--dt")
      ok = positive, o.dt = number;
    else if (key == "--duration")
      ok = positive, o.duration_s = number;
    else if (key == "--rate")
      ok = positive, o.rate_hz = number;
    else if (key == "--wait")
      ok = positive, o.wait_s = number;
    else if (key == "--substeps") {
      ok = positive && number == std::floor(number) && number <= 1000;
      o.substeps = int(number);
    } else if (key == "--inertia") {
      ok = ParseVector(value, &o.body.inertia_kgm2) && o.body.inertia_kgm2.minCoeff() > 0;
      o.have_inertia = true;
    } else if (key == "--box-size") {
      ok = ParseVector(value, &v) && v.minCoeff() > 0;
      if (ok && !o.have_mass) {
        std::fprintf(stderr, "rigid_body: give --mass before --box-size\n");
        return std::nullopt;
      }
      o.body.inertia_kgm2 = BoxInertia(o.body.mass_kg, v);
      o.have_inertia = true;
    } else if (key == "--position")
      ok = ParseVector(value, &o.start.p_W);
    else if (key == "--velocity")
      ok = ParseVector(value, &o.start.v_W);
    else if (key == "--angular-velocity")
      ok = ParseVector(value, &o.start.w_B);
    else if (key == "--rpy-deg") {
      ok = ParseVector(value, &v);
      const Eigen::Vector3d r = v * (M_PI / 180.0);
      o.start.R_WB = Eigen::AngleAxisd(r.z(), Eigen::Vector3d::UnitZ()) *
                     Eigen::AngleAxisd(r.y(), Eigen::Vector3d::UnitY()) *
                     Eigen::AngleAxisd(r.x(), Eigen::Vector3d::UnitX());
    } else {
      std::fprintf(stderr, "rigid_body: unknown option %s\n", key.c_str());
      return std::nullopt;
    }
    if (!ok) {
      std::fprintf(stderr, "rigid_body: bad value for %s: '%s'\n", key.c_str(), value.c_str());
      return std::nullopt;
    }
  }
  if (!o.have_mass || !o.have_inertia) {
    std::fprintf(stderr, "rigid_body: --mass and --box-size (or --inertia) are required\n");
    return std::nullopt;
  }
  return o;
}

struct Wrench {
  std::int64_t input_seq = -1;
  Eigen::Vector3d force = Eigen::Vector3d::Zero(), torque = Eigen::Vector3d::Zero();
};

double Percentile(std::vector<double> values, double q) {
  if (values.empty()) return NAN;
  const std::size_t k = std::min(values.size() - 1, std::size_t(q * double(values.size())));
  std::nth_element(values.begin(), values.begin() + long(k), values.end());
  return values[k];
}

// The loop's latency, from the sandbox's and this process's clocks (one
// machine): the scan of pose s (the sandbox tick that applied s, its STATE's
// utime) -> s's wrench received here -> the next pose published after it
// applied by the sandbox (that pose's STATE utime).
class LatencyLog {
 public:
  void Applied(std::int64_t pose_seq, std::int64_t utime) { applied_.emplace(pose_seq, utime); }
  void WrenchReceived(std::int64_t pose_seq, std::int64_t utime) {
    received_.emplace(pose_seq, utime);
  }
  void Published(std::int64_t pose_seq, std::int64_t after_wrench_of) {
    if (after_wrench_of >= 0) next_pose_.emplace(after_wrench_of, pose_seq);
  }
  void Print() const {
    std::vector<double> to_wrench, to_pose, total;
    for (const auto& [seq, received] : received_) {
      const auto scanned = applied_.find(seq);
      const auto next = next_pose_.find(seq);
      if (scanned == applied_.end() || next == next_pose_.end()) continue;
      const auto applied = applied_.find(next->second);
      if (applied == applied_.end()) continue;
      to_wrench.push_back(1e-3 * double(received - scanned->second));
      to_pose.push_back(1e-3 * double(applied->second - received));
      total.push_back(1e-3 * double(applied->second - scanned->second));
    }
    std::printf(
        "rigid_body: latency over %zu loops (ms, median / p99): scan -> wrench received "
        "%.2f / %.2f; wrench -> next pose applied %.2f / %.2f; scan -> pose applied "
        "%.2f / %.2f\n",
        total.size(), Percentile(to_wrench, 0.5), Percentile(to_wrench, 0.99),
        Percentile(to_pose, 0.5), Percentile(to_pose, 0.99), Percentile(total, 0.5),
        Percentile(total, 0.99));
  }

 private:
  std::map<std::int64_t, std::int64_t> applied_, received_, next_pose_;
};

class Model {
 public:
  Model(const Options& options, lcm::LCM& lcm)
      : options_(options), lcm_(lcm), state_(options.start) {
    lcm.subscribe(options.robot + "/WRENCH", &Model::OnWrench, this);
    lcm.subscribe(options.robot + "/STATE", &Model::OnState, this);
    if (!options.log.empty()) {
      log_ = std::fopen(options.log.c_str(), "w");
      if (log_ == nullptr) throw std::runtime_error(options.log + ": cannot write the log");
      std::fprintf(log_, "step,t,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz,fx,fy,fz,tx,ty,tz\n");
    }
  }
  ~Model() {
    if (log_ != nullptr) std::fclose(log_);
  }

  int Run() {
    const long steps = std::lround(options_.duration_s / options_.dt);
    Publish(0);
    const auto period = std::chrono::duration<double>(1.0 / options_.rate_hz);
    auto next = std::chrono::steady_clock::now();
    for (long step = 1; step <= steps && !g_stop; ++step) {
      if (options_.lockstep) {
        if (!AwaitWrench()) return 1;
      } else {
        next += std::chrono::duration_cast<std::chrono::steady_clock::duration>(period);
        while (!g_stop && std::chrono::steady_clock::now() < next) {
          const auto left =
              std::chrono::duration<double, std::milli>(next - std::chrono::steady_clock::now());
          lcm_.handleTimeout(std::max(1, int(left.count())));
        }
      }
      Log(step - 1);
      for (int k = 0; k < options_.substeps; ++k) {
        Step(options_.body, options_.dt / options_.substeps, wrench_.force, wrench_.torque,
             &state_);
      }
      Publish(step);
    }
    // The last pose's scan and wrench, so the latency log holds every loop.
    if (options_.lockstep && !g_stop) AwaitWrench();
    Log(steps);
    std::printf(
        "rigid_body: %ld steps of %g s (%g s simulated), %ld poses published, %ld "
        "resent after %g s without their wrench; final position %.6f, %.6f, %.6f\n",
        steps, options_.dt, double(steps) * options_.dt, seq_, resent_, options_.wait_s,
        state_.p_W.x(), state_.p_W.y(), state_.p_W.z());
    if (options_.latency) latency_.Print();
    return 0;
  }

 private:
  void Publish(long step) {
    sandbox_msgs::robot_pose_t pose{};
    // Poses carry simulated time: what the sandbox and the contact module
    // compute from them (velocities by differences) depends on them alone.
    pose.utime = 1'000'000 + std::lround(1e6 * options_.dt * double(step));
    pose.seq = seq_++;
    for (int k = 0; k < 3; ++k) pose.position[k] = state_.p_W[k];
    pose.orientation[0] = state_.R_WB.w(), pose.orientation[1] = state_.R_WB.x();
    pose.orientation[2] = state_.R_WB.y(), pose.orientation[3] = state_.R_WB.z();
    lcm_.publish(options_.robot + "/POSE", &pose);
    latency_.Published(pose.seq, last_received_);
    published_at_ = std::chrono::steady_clock::now();
    last_pose_ = pose;
  }

  // Waits for the wrench of the last pose published; resends that pose (a
  // new seq, the same state) when it does not come.
  bool AwaitWrench() {
    int resends = 0;
    while (!g_stop && wrench_.input_seq != last_pose_.seq) {
      lcm_.handleTimeout(50);
      if (std::chrono::steady_clock::now() - published_at_ >
          std::chrono::duration<double>(options_.wait_s)) {
        if (++resends > 30) {
          std::fprintf(stderr,
                       "rigid_body: no wrench on %s/WRENCH for %g s: is the contact module "
                       "running, and the sandbox in --lockstep?\n",
                       options_.robot.c_str(), 30 * options_.wait_s);
          return false;
        }
        ++resent_;
        last_pose_.seq = seq_++;
        lcm_.publish(options_.robot + "/POSE", &last_pose_);
        published_at_ = std::chrono::steady_clock::now();
      }
    }
    return !g_stop;
  }

  void OnWrench(const lcm::ReceiveBuffer* buffer, const std::string& channel) {
    sandbox_msgs::wrench_t message;
    const std::int64_t now = NowUtime();
    if (message.decode(buffer->data, 0, int(buffer->data_size)) < 0 || message.frame != "world") {
      std::fprintf(stderr,
                   "rigid_body: rejected a message on %s (does not decode, or not in the "
                   "world frame)\n",
                   channel.c_str());
      return;
    }
    Wrench w;
    w.input_seq = message.input_seq;
    w.force = Eigen::Vector3d(message.force[0], message.force[1], message.force[2]);
    w.torque = Eigen::Vector3d(message.torque[0], message.torque[1], message.torque[2]);
    if (!w.force.allFinite() || !w.torque.allFinite()) {
      std::fprintf(stderr, "rigid_body: rejected a wrench on %s: not finite\n", channel.c_str());
      return;
    }
    if (w.input_seq < wrench_.input_seq || w.input_seq >= seq_) return;  // older, or not ours
    wrench_ = w;
    latency_.WrenchReceived(w.input_seq, now);
    last_received_ = w.input_seq;
  }

  void OnState(const lcm::ReceiveBuffer* buffer, const std::string&) {
    sandbox_msgs::robot_state_t state;
    if (state.decode(buffer->data, 0, int(buffer->data_size)) < 0) return;
    latency_.Applied(state.input_seq, state.utime);
  }

  void Log(long step) {
    if (log_ == nullptr) return;
    const RigidBodyState& s = state_;
    std::fprintf(log_, "%ld,%.17g", step, double(step) * options_.dt);
    const double values[] = {
        s.p_W.x(),          s.p_W.y(),          s.p_W.z(),         s.R_WB.w(),
        s.R_WB.x(),         s.R_WB.y(),         s.R_WB.z(),        s.v_W.x(),
        s.v_W.y(),          s.v_W.z(),          s.w_B.x(),         s.w_B.y(),
        s.w_B.z(),          wrench_.force.x(),  wrench_.force.y(), wrench_.force.z(),
        wrench_.torque.x(), wrench_.torque.y(), wrench_.torque.z()};
    for (const double v : values) std::fprintf(log_, ",%.17g", v);
    std::fprintf(log_, "\n");
  }

  const Options& options_;
  lcm::LCM& lcm_;
  RigidBodyState state_;
  Wrench wrench_;
  sandbox_msgs::robot_pose_t last_pose_{};
  std::chrono::steady_clock::time_point published_at_;
  std::int64_t seq_{0}, last_received_{-1};
  long resent_{0};
  LatencyLog latency_;
  std::FILE* log_{nullptr};
};

}  // namespace
}  // namespace sandbox::examples

int main(int argc, char** argv) {
  using namespace sandbox::examples;
  const auto options = ParseOptions(argc, argv);
  if (!options) {
    std::fputs(kUsage, stderr);
    return 2;
  }
  lcm::LCM lcm(options->url);
  if (!lcm.good()) {
    std::fprintf(stderr, "rigid_body: cannot open LCM URL '%s'\n", options->url.c_str());
    return 1;
  }
  signal(SIGINT, OnSignal);
  signal(SIGTERM, OnSignal);
  try {
    Model model(*options, lcm);
    return model.Run();
  } catch (const std::exception& error) {
    std::fprintf(stderr, "rigid_body: %s\n", error.what());
    return 1;
  }
}
