#include "bridge/udp_inputs.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <stdexcept>

namespace sandbox::bridge {

UdpLatest::UdpLatest(const std::string& address, int port, MessageCheck check)
    : name_("udp:" + address + ":" + std::to_string(port)),
      check_(std::move(check)),
      buffer_(65536) {
  socket_ = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in where{};
  where.sin_family = AF_INET;
  where.sin_port = htons(static_cast<std::uint16_t>(port));
  if (socket_ < 0 || inet_pton(AF_INET, address.c_str(), &where.sin_addr) != 1 ||
      ::bind(socket_, reinterpret_cast<sockaddr*>(&where), sizeof(where)) != 0 ||
      ::fcntl(socket_, F_SETFL, O_NONBLOCK) != 0) {
    const std::string reason = std::strerror(errno);
    if (socket_ >= 0) ::close(socket_);
    throw std::runtime_error("UdpLatest::UdpLatest(): cannot bind " + address + ":" +
                             std::to_string(port) + ": " + reason);
  }
}

UdpLatest::~UdpLatest() { ::close(socket_); }

const std::vector<std::uint8_t>* UdpLatest::TakeNewest() {
  bool any = false;
  // At most this many a call: a flood cannot hold the loop (the rest waits).
  for (int read = 0; read < 4096; ++read) {
    const ssize_t size = ::recv(socket_, buffer_.data(), buffer_.size(), 0);
    if (size < 0) break;  // EAGAIN: nothing more waiting
    ++received_;
    if (check_) {
      if (std::string problem = check_(buffer_.data(), std::size_t(size)); !problem.empty()) {
        Reject(problem);
        continue;
      }
    }
    if (any) ++superseded_;
    newest_.assign(buffer_.begin(), buffer_.begin() + size);
    any = true;
  }
  return any ? &newest_ : nullptr;
}

void UdpLatest::Reject(const std::string& reason) {
  ++rejected_;
  last_reason_ = Printable(reason);
  if (reasons_.size() < LatestInput::kMaxReasons || reasons_.count(last_reason_) > 0) {
    ++reasons_[last_reason_];
  } else {
    ++reasons_["other"];
  }
  if (log_ != nullptr) log_->Note(name_, last_reason_);
}

NetFdmInput::NetFdmInput(const RobotBridgeConfig& config)
    : config_(config),
      socket_(config.bind_address, config.net_fdm_port,
              [](const std::uint8_t* data, std::size_t size) {
                NetFdm fdm;
                return DecodeNetFdm(data, size, &fdm);
              }) {}

bool NetFdmInput::Apply(scene::RobotState* state) {
  const std::vector<std::uint8_t>* packet = socket_.TakeNewest();
  if (packet == nullptr) return false;
  NetFdm fdm;
  const std::string reason = DecodeNetFdm(packet->data(), packet->size(), &fdm);
  if (!reason.empty()) {
    socket_.Reject(reason);
    return false;
  }
  // Geodetic position, NED attitude, relative to the configured origin.
  Translation geodetic = config_.pose;
  geodetic.convention = Convention::kGeodetic;
  const Eigen::Isometry3d X_WB =
      geodetic.ToWorld(Eigen::Vector3d(fdm.latitude_rad * 180.0 / M_PI,
                                       fdm.longitude_rad * 180.0 / M_PI, fdm.altitude_m),
                       NedAttitude(fdm.phi_rad, fdm.theta_rad, fdm.psi_rad));
  if (!state->SetPose(X_WB)) {
    socket_.Reject(state->last_rejection());
    return false;
  }
  // Control surfaces: each named bone's first angle.
  const std::map<std::string, float> surfaces = {{"elevator", fdm.elevator},
                                                 {"elevator_trim_tab", fdm.elevator_trim_tab},
                                                 {"left_flap", fdm.left_flap},
                                                 {"right_flap", fdm.right_flap},
                                                 {"left_aileron", fdm.left_aileron},
                                                 {"right_aileron", fdm.right_aileron},
                                                 {"rudder", fdm.rudder},
                                                 {"nose_wheel", fdm.nose_wheel},
                                                 {"speedbrake", fdm.speedbrake},
                                                 {"spoilers", fdm.spoilers}};
  for (const auto& [surface, bones] : config_.net_fdm_surfaces) {
    for (const int bone : bones) {
      const scene::Bone& b = state->model().bones[std::size_t(bone)];
      std::vector<double> values(std::size_t(b.num_values), 0.0);
      values[0] = double(surfaces.at(surface)) * config_.net_fdm_max_deflection_rad;
      if (!state->SetBone(bone, values.data(), b.num_values))
        socket_.Reject(state->last_rejection());
    }
  }
  last_ = fdm;
  return true;
}

namespace {

std::size_t ExpectedDoubles(const RobotBridgeConfig& config, int num_bone_values) {
  std::size_t expected = 0;
  for (const std::string& item : config.udp_doubles_layout) {
    expected += item == "position"                ? 3
                : item == "quaternion"            ? 4
                : item == "rpy"                   ? 3
                : item == "time" || item == "seq" ? 1
                                                  : std::size_t(num_bone_values);
  }
  return expected;
}

}  // namespace

std::string DecodeDoubles(const RobotBridgeConfig& config, int num_bone_values,
                          const std::uint8_t* data, std::size_t size,
                          const Eigen::Isometry3d& X_WB_before, Eigen::Isometry3d* X_WB,
                          std::vector<double>* bones, PacketTag* tag) {
  const std::size_t expected = ExpectedDoubles(config, num_bone_values);
  if (size != 8 * expected) {
    return "expected " + std::to_string(expected) + " doubles (" + std::to_string(8 * expected) +
           " bytes), got " + std::to_string(size) + " bytes";
  }
  std::vector<double> v(expected);
  for (std::size_t i = 0; i < expected; ++i) {
    std::uint8_t b[8];
    std::memcpy(b, data + 8 * i, 8);
    if (config.udp_doubles_big_endian) std::reverse(b, b + 8);
    std::memcpy(&v[i], b, 8);
    if (!std::isfinite(v[i])) return "non-finite value";
  }
  Eigen::Vector3d position = X_WB_before.translation();
  Eigen::Quaterniond q(X_WB_before.linear());
  bones->clear();
  PacketTag own;
  std::size_t at = 0;
  for (const std::string& item : config.udp_doubles_layout) {
    if (item == "time") {
      if (v[at] < 0.0 || v[at] > 9.2e12) return "time must be 0 to 9.2e12 s";
      own.utime = std::llround(v[at++] * 1e6);
    } else if (item == "seq") {
      if (v[at] < 0.0 || v[at] > 9e15 || v[at] != std::floor(v[at])) {
        return "seq must be a whole number from 0";
      }
      own.seq = std::int64_t(v[at++]);
    } else if (item == "position") {
      position = Eigen::Vector3d(v[at], v[at + 1], v[at + 2]), at += 3;
    } else if (item == "quaternion") {
      q = Eigen::Quaterniond(v[at], v[at + 1], v[at + 2], v[at + 3]), at += 4;
      if (std::abs(q.norm() - 1.0) > 1e-3) return "non-unit quaternion";
    } else if (item == "rpy") {
      // In the convention's own frame: aerospace attitude for ned and geodetic.
      q = config.pose.convention == Convention::kNed ||
                  config.pose.convention == Convention::kGeodetic
              ? NedAttitude(v[at], v[at + 1], v[at + 2])
              : Eigen::Quaterniond(Eigen::AngleAxisd(v[at + 2], Eigen::Vector3d::UnitZ()) *
                                   Eigen::AngleAxisd(v[at + 1], Eigen::Vector3d::UnitY()) *
                                   Eigen::AngleAxisd(v[at], Eigen::Vector3d::UnitX()));
      at += 3;
    } else {
      bones->assign(v.begin() + std::ptrdiff_t(at),
                    v.begin() + std::ptrdiff_t(at) + num_bone_values);
      at += std::size_t(num_bone_values);
    }
  }
  if (std::string problem = PositionProblem(config.pose, position); !problem.empty())
    return problem;
  *X_WB = config.pose.ToWorld(position, q);
  if (tag != nullptr) *tag = own;
  return scene::PoseProblem(*X_WB);
}

DoublesInput::DoublesInput(const RobotBridgeConfig& config, const scene::RobotModel& model)
    : config_(config),
      socket_(config.bind_address, config.udp_doubles_port,
              [this](const std::uint8_t* data, std::size_t size) {
                Eigen::Isometry3d X_WB;
                std::vector<double> bones;
                return DecodeDoubles(config_, num_values_, data, size,
                                     Eigen::Isometry3d::Identity(), &X_WB, &bones);
              }),
      num_values_(model.num_values) {
  expected_ = ExpectedDoubles(config_, num_values_);
}

bool DoublesInput::Apply(scene::RobotState* state) {
  const std::vector<std::uint8_t>* packet = socket_.TakeNewest();
  if (packet == nullptr) return false;
  Eigen::Isometry3d X_WB;
  std::vector<double> bones;
  PacketTag tag;
  const std::string problem = DecodeDoubles(config_, num_values_, packet->data(), packet->size(),
                                            state->pose(), &X_WB, &bones, &tag);
  if (!problem.empty()) {
    socket_.Reject(problem);
    return false;
  }
  if (!state->SetPose(X_WB)) {
    socket_.Reject(state->last_rejection());
    return false;
  }
  if (!bones.empty() && !state->SetBones(bones)) {
    socket_.Reject(state->last_rejection());
    return false;
  }
  last_tag_ = tag;
  return true;
}

}  // namespace sandbox::bridge
