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

UdpLatest::UdpLatest(const std::string& address, int port)
    : name_("udp:" + address + ":" + std::to_string(port)), buffer_(65536) {
  socket_ = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in where{};
  where.sin_family = AF_INET;
  where.sin_port = htons(static_cast<std::uint16_t>(port));
  if (socket_ < 0 || inet_pton(AF_INET, address.c_str(), &where.sin_addr) != 1 ||
      ::bind(socket_, reinterpret_cast<sockaddr*>(&where), sizeof(where)) != 0 ||
      ::fcntl(socket_, F_SETFL, O_NONBLOCK) != 0) {
    const std::string reason = std::strerror(errno);
    if (socket_ >= 0) ::close(socket_);
    throw std::runtime_error("UdpLatest: cannot bind " + address + ":" + std::to_string(port) +
                             ": " + reason);
  }
}

UdpLatest::~UdpLatest() { ::close(socket_); }

const std::vector<std::uint8_t>* UdpLatest::TakeNewest() {
  bool any = false;
  for (;;) {
    const ssize_t size = ::recv(socket_, buffer_.data(), buffer_.size(), 0);
    if (size < 0) break;  // EAGAIN: nothing more waiting
    ++received_;
    if (any) ++superseded_;
    newest_.assign(buffer_.begin(), buffer_.begin() + size);
    any = true;
  }
  return any ? &newest_ : nullptr;
}

void UdpLatest::Reject(const std::string& reason) {
  ++rejected_;
  ++reasons_[reason];
  last_reason_ = reason;
  if (log_ != nullptr) log_->Note(name_, reason);
}

NetFdmInput::NetFdmInput(const RobotBridgeConfig& config)
    : config_(config), socket_(config.bind_address, config.net_fdm_port) {}

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

DoublesInput::DoublesInput(const RobotBridgeConfig& config, const scene::RobotModel& model)
    : config_(config),
      socket_(config.bind_address, config.udp_doubles_port),
      num_values_(model.num_values) {
  for (const std::string& item : config_.udp_doubles_layout) {
    expected_ += item == "position"     ? 3
                 : item == "quaternion" ? 4
                 : item == "rpy"        ? 3
                                        : std::size_t(num_values_);
  }
}

bool DoublesInput::Apply(scene::RobotState* state) {
  const std::vector<std::uint8_t>* packet = socket_.TakeNewest();
  if (packet == nullptr) return false;
  if (packet->size() != 8 * expected_) {
    socket_.Reject("expected " + std::to_string(expected_) + " doubles (" +
                   std::to_string(8 * expected_) + " bytes), got " +
                   std::to_string(packet->size()) + " bytes");
    return false;
  }
  std::vector<double> v(expected_);
  for (std::size_t i = 0; i < expected_; ++i) {
    std::uint8_t b[8];
    std::memcpy(b, packet->data() + 8 * i, 8);
    if (config_.udp_doubles_big_endian) std::reverse(b, b + 8);
    std::memcpy(&v[i], b, 8);
    if (!std::isfinite(v[i])) {
      socket_.Reject("non-finite value");
      return false;
    }
  }
  Eigen::Vector3d position = state->pose().translation();
  Eigen::Quaterniond q(state->pose().linear());
  std::vector<double> bones;
  std::size_t at = 0;
  for (const std::string& item : config_.udp_doubles_layout) {
    if (item == "position") {
      position = Eigen::Vector3d(v[at], v[at + 1], v[at + 2]), at += 3;
    } else if (item == "quaternion") {
      q = Eigen::Quaterniond(v[at], v[at + 1], v[at + 2], v[at + 3]), at += 4;
      if (std::abs(q.norm() - 1.0) > 1e-3) {
        socket_.Reject("non-unit quaternion");
        return false;
      }
    } else if (item == "rpy") {
      // In the convention's own frame: aerospace attitude for ned and geodetic.
      q = config_.pose.convention == Convention::kNed ||
                  config_.pose.convention == Convention::kGeodetic
              ? NedAttitude(v[at], v[at + 1], v[at + 2])
              : Eigen::Quaterniond(Eigen::AngleAxisd(v[at + 2], Eigen::Vector3d::UnitZ()) *
                                   Eigen::AngleAxisd(v[at + 1], Eigen::Vector3d::UnitY()) *
                                   Eigen::AngleAxisd(v[at], Eigen::Vector3d::UnitX()));
      at += 3;
    } else {
      bones.assign(v.begin() + std::ptrdiff_t(at), v.begin() + std::ptrdiff_t(at) + num_values_);
      at += std::size_t(num_values_);
    }
  }
  if (!state->SetPose(config_.pose.ToWorld(position, q))) {
    socket_.Reject(state->last_rejection());
    return false;
  }
  if (!bones.empty() && !state->SetBones(bones)) {
    socket_.Reject(state->last_rejection());
    return false;
  }
  return true;
}

}  // namespace sandbox::bridge
