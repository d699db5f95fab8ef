// Listens to <ROBOT>/SCAN_FACE from a running sandbox and checks every face
// against a one-shot scan of the same level at the same sensor pose: the same
// occupancy and the same points (to float rounding of the message's offsets).
// Exit 0 when at least --faces faces arrived and all matched.
//
//   face_check LEVEL [--robot NAME] [--faces N] [--seconds S] [--lcm-url URL]

#include <chrono>
#include <cstdio>
#include <cstring>
#include <lcm/lcm-cpp.hpp>
#include <string>

#include "sandbox_msgs/scan_face_t.hpp"
#include "scene/collision_world.h"
#include "scene/level.h"
#include "sensors/sensor.h"

namespace {

using namespace sandbox;

struct Checker {
  const scene::Level* level;
  const scene::CollisionWorld* world;
  const sensors::FaceScanner* scanner;
  sensors::RayCaster* caster;
  int robot;
  int faces{0}, mismatched_points{0}, inputs_seen{0};
  double worst_m{0.0};

  void OnFace(const lcm::ReceiveBuffer* buffer, const std::string&,
              const sandbox_msgs::scan_face_t* message) {
    (void)buffer;
    Eigen::Isometry3d X_WS = Eigen::Isometry3d::Identity();
    X_WS.translation() = Eigen::Vector3d(message->sensor_position[0], message->sensor_position[1],
                                         message->sensor_position[2]);
    X_WS.linear() =
        Eigen::Quaterniond(message->sensor_orientation[0], message->sensor_orientation[1],
                           message->sensor_orientation[2], message->sensor_orientation[3])
            .toRotationMatrix();
    sensors::RayFilter filter;
    filter.ignore_robot = robot;
    sensors::FaceScan scan = scanner->EmptyScan();
    // The same face as the message: scan the tick that refreshes it.
    scanner->Scan(*world, *caster, filter, X_WS, message->tick, &scan);
    const sensors::ScanFace& face = scan.faces[std::size_t(message->face)];
    const Eigen::Vector3d origin(message->origin[0], message->origin[1], message->origin[2]);
    for (int k = 0; k < message->num_points; ++k) {
      const Eigen::Vector3d p = origin + Eigen::Vector3d(message->xyz[std::size_t(3 * k)],
                                                         message->xyz[std::size_t(3 * k + 1)],
                                                         message->xyz[std::size_t(3 * k + 2)]);
      const double diff = (p - scan.PointW(message->face, std::size_t(k))).norm();
      worst_m = std::max(worst_m, diff);
      if (message->occupancy[std::size_t(k)] != face.occupancy[std::size_t(k)] || diff > 1e-4) {
        ++mismatched_points;
      }
    }
    inputs_seen += message->input_seq >= 0 ? 1 : 0;
    ++faces;
  }
};

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(
        stderr,
        "usage: face_check LEVEL [--robot NAME] [--faces N] [--seconds S] [--lcm-url URL]\n");
    return 2;
  }
  std::string robot_name = "ELAHA", url;
  int want = 12;
  double seconds = 5.0;
  for (int i = 2; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--robot"))
      robot_name = argv[i + 1];
    else if (!std::strcmp(argv[i], "--faces"))
      want = std::atoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--seconds"))
      seconds = std::atof(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--lcm-url"))
      url = argv[i + 1];
  }
  const scene::Level level = scene::LoadLevel(argv[1]);
  const scene::CollisionWorld world(level);
  const int robot = level.FindRobot(robot_name);
  const std::vector<sensors::MountedSensor> mounted = sensors::MakeRobotSensors(level);
  const sensors::FaceScannerConfig* config = nullptr;
  for (const auto& m : mounted) {
    if (m.robot == robot) config = std::get_if<sensors::FaceScannerConfig>(&m.config);
    if (config != nullptr) break;
  }
  if (robot < 0 || config == nullptr) {
    std::fprintf(stderr, "face_check: no face scanner on robot '%s'\n", robot_name.c_str());
    return 2;
  }
  const sensors::FaceScanner scanner(*config);
  sensors::RayCaster caster(1);
  Checker checker{&level, &world, &scanner, &caster, robot};
  lcm::LCM lcm(url.empty() ? "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304" : url);
  lcm.subscribe(robot_name + "/SCAN_FACE", &Checker::OnFace, &checker);
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (checker.faces < want && std::chrono::steady_clock::now() < end) lcm.handleTimeout(100);
  std::printf(
      "face_check: %d faces (%d from an external pose), %d mismatched points, worst %.2e m\n",
      checker.faces, checker.inputs_seen, checker.mismatched_points, checker.worst_m);
  return checker.faces >= want && checker.mismatched_points == 0 && checker.inputs_seen > 0 ? 0 : 1;
}
