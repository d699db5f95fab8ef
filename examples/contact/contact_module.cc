// An external contact module: the robot-world interaction computed outside
// the sandbox from what its face scanner saw. It reads the robot's mesh once
// into a signed distance field, then for every pose the sandbox applied
// (<ROBOT>/STATE) it takes that pose's scan faces (<ROBOT>/SCAN_FACE), finds
// the scan points inside the robot's shape, and publishes the penalty
// contact's force and torque about the centre of mass (<ROBOT>/WRENCH). Each
// scan point says what it hit (its surface id, named on <ROBOT>/WORLD): the
// pairs log has the wrench per body pair (the robot on each surface).
// docs/how-to/contact.md explains the chain and the law.
//
//   contact_module --mesh FILE --resolution M [options]   (--help lists them)

#include <signal.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "examples/contact/penalty_contact.h"
#include "examples/contact/robot_shape.h"
#include "examples/rigid_body/rigid_body.h"
#include "sandbox_msgs/robot_state_t.hpp"
#include "sandbox_msgs/scan_face_t.hpp"
#include "sandbox_msgs/surface_table_t.hpp"
#include "sandbox_msgs/wrench_t.hpp"

namespace sandbox::examples {
namespace {

const char* kUsage =
    "usage: contact_module --mesh FILE --resolution M [options]\n"
    "  Subscribes to <ROBOT>/SCAN_FACE and <ROBOT>/STATE, publishes <ROBOT>/WRENCH.\n"
    "  --robot NAME        channel prefix (default BOX)\n"
    "  --mesh FILE         the robot's mesh (glTF is Y-up, other formats Z-up), robot frame\n"
    "  --com X,Y,Z         centre of mass in the robot frame (default 0,0,0)\n"
    "  --resolution M      the face scanner's resolution_m: each point stands for M^2\n"
    "  --voxel M           distance field spacing (default 0.02)\n"
    "  --band M            distance field exact within M of the surface (default 0.1)\n"
    "  --margin M          safety margin: points this close outside touch (default 0.01)\n"
    "  --stiffness K       Pa per metre of depth (default 1e5)\n"
    "  --damping C         Pa per m/s of approach (default 5e3)\n"
    "  --friction MU       Coulomb coefficient (default 0.6)\n"
    "  --slip-damping C    Pa per m/s of slip below the Coulomb cap (default 2e3)\n"
    "  --max-face-age N    use faces up to N poses older than the pose (default 0; staged\n"
    "                      refresh needs 5 or 11)\n"
    "  --faces CHANNEL     face channel after <ROBOT>/ (default SCAN_FACE)\n"
    "  --lcm-url URL       (default LCM's, with a 4 MB receive buffer)\n"
    "  --log FILE          one CSV row per wrench\n"
    "  --pairs-log FILE    one CSV row per wrench and surface touched: the robot on that\n"
    "                      surface alone (names from <ROBOT>/WORLD)\n";

volatile sig_atomic_t g_stop = 0;
void OnSignal(int) { g_stop = 1; }

std::int64_t NowUtime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

struct Options {
  std::string robot = "BOX", mesh, faces = "SCAN_FACE", log, pairs_log;
  std::string url = "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304";
  Eigen::Vector3d com = Eigen::Vector3d::Zero();
  SignedDistanceField::Options field;
  ContactLaw law;
  double resolution_m = 0.0;
  int max_face_age = 0;
};

bool ParseVector(const std::string& text, Eigen::Vector3d* v) {
  return std::sscanf(text.c_str(), "%lf,%lf,%lf", &v->x(), &v->y(), &v->z()) == 3 && v->allFinite();
}

std::optional<Options> ParseOptions(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string key = argv[i];
    if (key == "--help") return std::nullopt;
    if (i + 1 >= argc) {
      std::fprintf(stderr, "contact_module: %s needs a value\n", key.c_str());
      return std::nullopt;
    }
    const std::string value = argv[++i];
    char* end = nullptr;
    const double number = std::strtod(value.c_str(), &end);
    const bool numeric = end != value.c_str() && *end == '\0' && std::isfinite(number);
    auto positive = [&](double* field) {
      if (!numeric || !(number > 0.0)) return false;
      *field = number;
      return true;
    };
    auto non_negative = [&](double* field) {
      if (!numeric || number < 0.0) return false;
      *field = number;
      return true;
    };
    bool ok = true;
    if (key == "--robot")
      o.robot = value;
    else if (key == "--mesh")
      o.mesh = value;
    else if (key == "--faces")
      o.faces = value;
    else if (key == "--lcm-url")
      o.url = value;
    else if (key == "--log")
      o.log = value;
    else if (key == "--pairs-log")
      o.pairs_log = value;
    else if (key == "--com")
      ok = ParseVector(value, &o.com);
    else if (key == "--resolution")
      ok = positive(&o.resolution_m);
    else if (key == "--voxel")
      ok = positive(&o.field.voxel_m);
    else if (key == "--band")
      ok = positive(&o.field.band_m);
    else if (key == "--margin")
      ok = non_negative(&o.law.margin_m);
    else if (key == "--stiffness")
      ok = positive(&o.law.stiffness_pa_per_m);
    else if (key == "--damping")
      ok = non_negative(&o.law.damping_pa_s_per_m);
    else if (key == "--friction")
      ok = non_negative(&o.law.friction);
    else if (key == "--slip-damping")
      ok = non_negative(&o.law.slip_damping_pa_s_per_m);
    else if (key == "--max-face-age") {
      ok = numeric && number >= 0 && number == std::floor(number) && number < 1000;
      o.max_face_age = int(number);
    } else {
      std::fprintf(stderr, "contact_module: unknown option %s\n", key.c_str());
      return std::nullopt;
    }
    if (!ok) {
      std::fprintf(stderr, "contact_module: bad value for %s: '%s'\n", key.c_str(), value.c_str());
      return std::nullopt;
    }
  }
  if (o.mesh.empty() || o.resolution_m <= 0.0) {
    std::fprintf(stderr, "contact_module: --mesh and --resolution are required\n");
    return std::nullopt;
  }
  o.law.point_area_m2 = o.resolution_m * o.resolution_m;
  return o;
}

// What the module has heard and done, for its reports.
struct Counters {
  long wrenches = 0;
  long skipped_poses = 0;  // a newer pose came before this one was computed
  long stale_faces = 0;    // older than the pose in use (beyond --max-face-age)
  long missing_faces = 0;  // face slots without a usable face at compute time
  long rejected = 0;       // messages that failed to decode or made no sense
  std::vector<double> compute_ms;
};

class ContactModule {
 public:
  ContactModule(const Options& options, const SignedDistanceField& shape, lcm::LCM& lcm)
      : options_(options), shape_(shape), lcm_(lcm) {
    if (!options.log.empty()) {
      log_.open(options.log);
      if (!log_) throw std::runtime_error(options.log + ": cannot write the log");
      log_ << "input_seq,input_utime,points,faces,max_depth_m,normal_n,fx,fy,fz,tx,ty,tz,"
              "cop_x,cop_y,cop_z\n";
      log_ << std::setprecision(10);
    }
    if (!options.pairs_log.empty()) {
      pairs_log_.open(options.pairs_log);
      if (!pairs_log_) throw std::runtime_error(options.pairs_log + ": cannot write the log");
      pairs_log_ << "input_seq,input_utime,surface,name,points,max_depth_m,normal_n,fx,fy,fz,"
                    "tx,ty,tz\n";
      pairs_log_ << std::setprecision(10);
    }
    lcm.subscribe(options.robot + "/" + options.faces, &ContactModule::OnFace, this);
    lcm.subscribe(options.robot + "/WORLD", &ContactModule::OnWorld, this);
    lcm.subscribe(options.robot + "/STATE", &ContactModule::OnState, this);
  }

  // Handles what has arrived (waiting up to timeout_ms for the first
  // message), then computes the newest pose's wrench if it is new.
  void Poll(int timeout_ms) {
    if (lcm_.handleTimeout(timeout_ms) <= 0) return;
    while (lcm_.handleTimeout(0) > 0) {
    }
    if (pending_) Compute();
  }

  const Counters& counters() const { return counters_; }

 private:
  void Reject(const std::string& channel, const std::string& why) {
    if (counters_.rejected++ < 10) {
      std::fprintf(stderr, "contact_module: rejected a message on %s: %s\n", channel.c_str(),
                   why.c_str());
    }
  }

  void OnFace(const lcm::ReceiveBuffer* buffer, const std::string& channel) {
    sandbox_msgs::scan_face_t face;
    if (face.decode(buffer->data, 0, int(buffer->data_size)) < 0)
      return Reject(channel, "does not decode");
    if (face.face < 0 || face.face > 5 || face.n <= 0 ||
        std::int64_t(face.num_points) != std::int64_t(face.n) * face.n ||
        face.num_xyz != 3 * face.num_points ||
        (face.num_surface != 0 && face.num_surface != face.num_points) ||
        !(std::isfinite(face.origin[0]) && std::isfinite(face.origin[1]) &&
          std::isfinite(face.origin[2]))) {
      return Reject(channel, "face index, size or origin out of range");
    }
    if (face.input_seq <= computed_seq_ - options_.max_face_age) {
      ++counters_.stale_faces;  // older than the pose in use: ignored
      return;
    }
    faces_[std::size_t(face.face)] = std::move(face);
  }

  // The names of the surface ids (what the pairs log calls them).
  void OnWorld(const lcm::ReceiveBuffer* buffer, const std::string& channel) {
    sandbox_msgs::surface_table_t table;
    if (table.decode(buffer->data, 0, int(buffer->data_size)) < 0 || table.num_surfaces < 0 ||
        table.id.size() != std::size_t(table.num_surfaces)) {
      return Reject(channel, "does not decode");
    }
    for (int k = 0; k < table.num_surfaces; ++k) names_[table.id[k]] = table.name[k];
  }

  void OnState(const lcm::ReceiveBuffer* buffer, const std::string& channel) {
    sandbox_msgs::robot_state_t state;
    if (state.decode(buffer->data, 0, int(buffer->data_size)) < 0)
      return Reject(channel, "does not decode");
    const Eigen::Vector3d p(state.position[0], state.position[1], state.position[2]);
    const Eigen::Quaterniond q(state.orientation[0], state.orientation[1], state.orientation[2],
                               state.orientation[3]);
    if (!p.allFinite() || !q.coeffs().allFinite() || std::abs(q.norm() - 1.0) > 1e-6) {
      return Reject(channel, "pose not finite or not a unit quaternion");
    }
    if (state.input_seq <= computed_seq_) return;  // a pose already done (or older)
    if (pending_ && pending_->input_seq < state.input_seq) {
      ++counters_.skipped_poses;  // fell behind: the newer pose wins
    }
    pending_ = std::move(state);
  }

  void Compute() {
    const auto start = std::chrono::steady_clock::now();
    const sandbox_msgs::robot_state_t& state = *pending_;
    const Eigen::Quaterniond R_WB(state.orientation[0], state.orientation[1], state.orientation[2],
                                  state.orientation[3]);
    const Eigen::Vector3d origin_W(state.position[0], state.position[1], state.position[2]);
    BodyMotion body;
    body.R_WB = R_WB.normalized();
    body.com_W = origin_W + body.R_WB * options_.com;
    // Velocities from the previous pose (exact for a semi-implicit integrator).
    if (previous_ && state.input_utime > previous_->utime) {
      VelocitiesFromPoses(previous_->com, previous_->R, body.com_W, body.R_WB,
                          1e-6 * double(state.input_utime - previous_->utime), &velocity_,
                          &angular_velocity_);
    }
    body.v_W = velocity_;
    body.w_W = angular_velocity_;
    ContactAccumulator contact(shape_, options_.law, body);
    std::map<std::int32_t, ContactAccumulator> by_surface;  // 0: the face had no ids
    int faces_used = 0;
    for (const std::optional<sandbox_msgs::scan_face_t>& face : faces_) {
      if (!face || face->input_seq > state.input_seq ||
          face->input_seq < state.input_seq - options_.max_face_age) {
        ++counters_.missing_faces;
        continue;
      }
      ++faces_used;
      const Eigen::Vector3d origin(face->origin[0], face->origin[1], face->origin[2]);
      for (int k = 0; k < face->num_points; ++k) {
        if (face->occupancy[std::size_t(k)] != 1) continue;
        const float* xyz = &face->xyz[3 * std::size_t(k)];
        contact.AddPoint(origin, Eigen::Vector3f(xyz[0], xyz[1], xyz[2]));
        if (!pairs_log_) continue;
        const std::int32_t surface = face->num_surface > 0 ? face->surface[std::size_t(k)] : 0;
        by_surface.try_emplace(surface, shape_, options_.law, body)
            .first->second.AddPoint(origin, Eigen::Vector3f(xyz[0], xyz[1], xyz[2]));
      }
    }
    const ContactWrench wrench = contact.Result();
    sandbox_msgs::wrench_t message{};
    message.utime = NowUtime();
    message.seq = next_seq_++;
    message.input_seq = state.input_seq;
    message.frame = "world";
    for (int k = 0; k < 3; ++k) {
      message.point[k] = body.com_W[k];
      message.force[k] = wrench.force_W[k];
      message.torque[k] = wrench.torque_W[k];
    }
    lcm_.publish(options_.robot + "/WRENCH", &message);
    if (log_) {
      log_ << state.input_seq << "," << state.input_utime << "," << wrench.points << ","
           << faces_used << "," << wrench.max_depth_m << "," << wrench.normal_force_n;
      for (const Eigen::Vector3d* v :
           {&wrench.force_W, &wrench.torque_W, &wrench.centre_of_pressure_W}) {
        for (int k = 0; k < 3; ++k) log_ << "," << (*v)[k];
      }
      log_ << "\n";
    }
    for (const auto& [surface, accumulator] : by_surface) {
      const ContactWrench pair = accumulator.Result();
      if (pair.points == 0) continue;  // seen, not touched
      const auto name = names_.find(surface);
      pairs_log_ << state.input_seq << "," << state.input_utime << "," << surface << ","
                 << (name != names_.end() ? name->second : std::string("?")) << "," << pair.points
                 << "," << pair.max_depth_m << "," << pair.normal_force_n;
      for (const Eigen::Vector3d* v : {&pair.force_W, &pair.torque_W}) {
        for (int k = 0; k < 3; ++k) pairs_log_ << "," << (*v)[k];
      }
      pairs_log_ << "\n";
    }
    previous_ = Previous{body.com_W, body.R_WB, state.input_utime};
    computed_seq_ = state.input_seq;
    pending_.reset();
    ++counters_.wrenches;
    counters_.compute_ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count());
  }

  struct Previous {
    Eigen::Vector3d com;
    Eigen::Quaterniond R;
    std::int64_t utime;
  };

  const Options& options_;
  const SignedDistanceField& shape_;
  lcm::LCM& lcm_;
  std::ofstream log_, pairs_log_;
  std::map<std::int32_t, std::string> names_;  // surface ids' names (<ROBOT>/WORLD)
  std::array<std::optional<sandbox_msgs::scan_face_t>, 6> faces_;
  std::optional<sandbox_msgs::robot_state_t> pending_;
  std::optional<Previous> previous_;
  Eigen::Vector3d velocity_{Eigen::Vector3d::Zero()}, angular_velocity_{Eigen::Vector3d::Zero()};
  std::int64_t computed_seq_{-1}, next_seq_{0};
  Counters counters_;
};

double Percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  const std::size_t k = std::min(values.size() - 1, std::size_t(q * double(values.size())));
  std::nth_element(values.begin(), values.begin() + long(k), values.end());
  return values[k];
}

int Run(const Options& options) {
  const auto start = std::chrono::steady_clock::now();
  const std::vector<Triangle> mesh = ReadRobotMesh(options.mesh);
  const SignedDistanceField shape(mesh, options.field);
  const Eigen::Vector3d size = shape.box_max() - shape.box_min();
  std::printf(
      "contact_module: %s: %zu triangles, %.3g x %.3g x %.3g m, distance field of %ld nodes "
      "in %.2f s\n",
      options.mesh.c_str(), mesh.size(), size.x(), size.y(), size.z(), shape.nodes(),
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  lcm::LCM lcm(options.url);
  if (!lcm.good()) {
    std::fprintf(stderr, "contact_module: cannot open LCM URL '%s'\n", options.url.c_str());
    return 1;
  }
  ContactModule module(options, shape, lcm);
  std::printf("contact_module: listening on %s/%s and %s/STATE\n", options.robot.c_str(),
              options.faces.c_str(), options.robot.c_str());
  std::fflush(stdout);
  signal(SIGINT, OnSignal);
  signal(SIGTERM, OnSignal);
  auto next_report = std::chrono::steady_clock::now() + std::chrono::seconds(1);
  long skipped_reported = 0;
  while (!g_stop) {
    module.Poll(100);
    if (std::chrono::steady_clock::now() >= next_report) {
      next_report += std::chrono::seconds(1);
      const long skipped = module.counters().skipped_poses - skipped_reported;
      if (skipped > 0) {
        std::fprintf(stderr,
                     "contact_module: falling behind: %ld poses skipped in the last second\n",
                     skipped);
        skipped_reported = module.counters().skipped_poses;
      }
    }
  }
  const Counters& c = module.counters();
  std::printf(
      "contact_module: %ld wrenches; %ld poses skipped (fell behind), %ld stale faces "
      "ignored, %ld face slots missing, %ld messages rejected; compute median %.3f ms, "
      "p99 %.3f ms\n",
      c.wrenches, c.skipped_poses, c.stale_faces, c.missing_faces, c.rejected,
      Percentile(c.compute_ms, 0.5), Percentile(c.compute_ms, 0.99));
  return 0;
}

}  // namespace
}  // namespace sandbox::examples

int main(int argc, char** argv) {
  const auto options = sandbox::examples::ParseOptions(argc, argv);
  if (!options) {
    std::fputs(sandbox::examples::kUsage, stderr);
    return 2;
  }
  try {
    return sandbox::examples::Run(*options);
  } catch (const std::exception& error) {
    std::fprintf(stderr, "contact_module: %s\n", error.what());
    return 1;
  }
}
