#pragma once
// Inputs for senders without LCM (Simulink's UDP Send block, its FlightGear
// blocks): a UDP socket bound to bind_address:port that keeps only the newest
// datagram, decoded and applied to a robot like the LCM inputs, with the same
// counting of superseded and rejected packets. Threads: the loop thread.

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "bridge/lcm_link.h"
#include "bridge/net_fdm.h"
#include "bridge/reject_log.h"
#include "bridge/robot_bridge_config.h"
#include "scene/robot_state.h"

namespace sandbox::bridge {

// A non-blocking UDP socket that keeps the newest good datagram: each one is
// checked as it is read (`check`, as for LCM inputs), and a bad one is
// rejected without displacing the good one before it.
class UdpLatest {
 public:
  // Throws std::runtime_error naming the address and port when it cannot bind.
  UdpLatest(const std::string& address, int port, MessageCheck check = {});
  ~UdpLatest();
  UdpLatest(const UdpLatest&) = delete;
  UdpLatest& operator=(const UdpLatest&) = delete;

  // Reads every waiting datagram; returns the newest good one or nullptr.
  const std::vector<std::uint8_t>* TakeNewest();
  void Reject(const std::string& reason);
  // Where rejections are also logged, once per cause per second (nullptr: nowhere).
  void set_log(RejectLog* log) { log_ = log; }

  const std::string& name() const { return name_; }  // "udp:127.0.0.1:5505"
  std::int64_t received() const { return received_; }
  std::int64_t superseded() const { return superseded_; }
  std::int64_t rejected() const { return rejected_; }
  const std::string& last_reject_reason() const { return last_reason_; }
  const std::map<std::string, std::int64_t>& rejected_by_reason() const { return reasons_; }

 private:
  int socket_{-1};
  std::string name_;
  MessageCheck check_;
  std::vector<std::uint8_t> buffer_, newest_;
  std::int64_t received_{0}, superseded_{0}, rejected_{0};
  std::map<std::string, std::int64_t> reasons_;
  RejectLog* log_{nullptr};
  std::string last_reason_;
};

// The sequence number and time a packet carries (-1 where its format has none).
struct PacketTag {
  std::int64_t seq{-1};
  std::int64_t utime{-1};
};

// FlightGear net_fdm: geodetic position and NED attitude drive the robot
// pose; control-surface fields drive the bones the config names.
class NetFdmInput {
 public:
  NetFdmInput(const RobotBridgeConfig& config);
  // Applies the newest good packet; true when the pose changed.
  bool Apply(scene::RobotState* state);
  // The applied packet's time: its cur_time (whole seconds since 1970) in
  // microseconds, -1 when it is 0. The format has no counter (seq -1).
  PacketTag last_tag() const {
    return {-1, last_.cur_time > 0 ? 1'000'000LL * last_.cur_time : -1};
  }
  const UdpLatest& socket() const { return socket_; }
  void set_log(RejectLog* log) { socket_.set_log(log); }
  const NetFdm& last_good() const { return last_; }

 private:
  RobotBridgeConfig config_;
  UdpLatest socket_;
  NetFdm last_;
  std::vector<double> values_;  // bone values kept between packets
};

// A packet of doubles in `config`'s layout and byte order, decoded: the pose
// (items the layout lacks keep X_WB_before's), the bone values (empty when
// the layout has none) and the packet's own `time` (seconds) and `seq` when
// the layout has them (`tag`, may be null). Returns "" or why the packet is
// rejected (size, non-finite value, non-unit quaternion, a pose that is no
// pose, a seq or time that is negative or not whole).
std::string DecodeDoubles(const RobotBridgeConfig& config, int num_bone_values,
                          const std::uint8_t* data, std::size_t size,
                          const Eigen::Isometry3d& X_WB_before, Eigen::Isometry3d* X_WB,
                          std::vector<double>* bones, PacketTag* tag = nullptr);

// A plain vector of doubles in the configured layout and byte order.
class DoublesInput {
 public:
  DoublesInput(const RobotBridgeConfig& config, const scene::RobotModel& model);
  bool Apply(scene::RobotState* state);
  const UdpLatest& socket() const { return socket_; }
  void set_log(RejectLog* log) { socket_.set_log(log); }
  std::size_t expected_doubles() const { return expected_; }
  // The applied packet's `seq` and `time` (microseconds), -1 for what the layout lacks.
  PacketTag last_tag() const { return last_tag_; }

 private:
  RobotBridgeConfig config_;
  UdpLatest socket_;
  PacketTag last_tag_;
  std::size_t expected_{0};
  int num_values_{0};
};

}  // namespace sandbox::bridge
