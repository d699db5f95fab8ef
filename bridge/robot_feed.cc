#include "bridge/robot_feed.h"

#include <cstdio>

namespace sandbox::bridge {
namespace {

// Notes `utime` on `channel`; a time before the newest seen is a jump back.
void WatchTime(const std::string& channel, std::int64_t utime, int* jumps_said, bool* seen,
               std::int64_t* newest, std::vector<std::string>* out) {
  constexpr int kSaid = 3;
  if (*seen && utime < *newest && ++*jumps_said <= kSaid) {
    char text[256];
    std::snprintf(text, sizeof(text),
                  "%s: input time jumped back by %.6f s (from %.6f s to %.6f s); the sensors keep "
                  "the loop's schedule%s",
                  channel.c_str(), double(*newest - utime) * 1e-6, double(*newest) * 1e-6,
                  double(utime) * 1e-6,
                  *jumps_said == kSaid ? " (further jumps on this channel are not said)" : "");
    out->push_back(text);
  }
  *seen = true;
  *newest = utime;
}

}  // namespace

RobotFeed::RobotFeed(LcmLink& link, const scene::Level& level, int robot,
                     const RobotBridgeConfig& config, bool lockstep, RejectLog* log)
    : config_(config), robot_(robot), lockstep_(lockstep), inputs_(link, level, robot, config) {
  inputs_.set_log(log);
  inputs_.set_lockstep(lockstep);
  if (config.net_fdm_port > 0) {
    net_fdm_ = std::make_unique<NetFdmInput>(config);
    net_fdm_->set_log(log);
  }
  if (config.udp_doubles_port > 0) {
    doubles_ = std::make_unique<DoublesInput>(config, level.robots[std::size_t(robot)]);
    doubles_->set_log(log);
  }
}

RobotFeed::Changes RobotFeed::Apply(std::int64_t now_utime, scene::RobotState* state,
                                    scene::CollisionWorld* world) {
  const RobotInputs::Applied applied =
      lockstep_ ? inputs_.ApplyNext(state, world) : inputs_.Apply(state, world);
  Changes changes;
  changes.messages =
      int(applied.pose) + int(applied.bones) + int(applied.actors) + int(applied.camera);
  changes.pose = applied.pose;
  changes.pose_utime = applied.pose_utime;
  changes.moved = applied.pose || applied.bones;
  if (applied.pose) {
    input_ = {applied.pose_seq, applied.pose_utime};
    WatchTime(inputs_.pose().channel(), applied.pose_utime, &pose_time_.jumps, &pose_time_.seen,
              &pose_time_.utime, &changes.time_jumps);
  }
  // UDP inputs: the packet's own counter and time where its format has
  // them, else the receive counter and the arrival time.
  auto tag = [now_utime](const PacketTag& own, std::int64_t received) {
    return InputTag{own.seq >= 0 ? own.seq : received, own.utime >= 0 ? own.utime : now_utime};
  };
  if (net_fdm_ && net_fdm_->Apply(state)) {
    changes.moved = true;
    ++changes.messages;
    input_ = tag(net_fdm_->last_tag(), net_fdm_->socket().received());
    if (net_fdm_->last_tag().utime >= 0) {
      WatchTime(net_fdm_->socket().name(), net_fdm_->last_tag().utime, &net_fdm_time_.jumps,
                &net_fdm_time_.seen, &net_fdm_time_.utime, &changes.time_jumps);
    }
  }
  if (doubles_ && doubles_->Apply(state)) {
    changes.moved = true;
    ++changes.messages;
    input_ = tag(doubles_->last_tag(), doubles_->socket().received());
    if (doubles_->last_tag().utime >= 0) {
      WatchTime(doubles_->socket().name(), doubles_->last_tag().utime, &doubles_time_.jumps,
                &doubles_time_.seen, &doubles_time_.utime, &changes.time_jumps);
    }
  }
  if (changes.moved) {
    state->UpdateKinematics();  // skinned when a camera draws it (RobotState::Skin)
    world->UpdateRobot(robot_, *state);
  }
  return changes;
}

std::vector<ChannelStatus> RobotFeed::Channels(std::int64_t now_utime) const {
  std::vector<ChannelStatus> channels;
  for (const LatestInput* in : {&inputs_.pose(), &inputs_.bones(), &inputs_.joints(),
                                &inputs_.actors(), &inputs_.camera()}) {
    // Camera commands come when someone steers: never stale. Joint values
    // come on BONES or JOINTS: stale when neither has brought any lately.
    const bool joint_values = in == &inputs_.bones() || in == &inputs_.joints();
    const bool stale = joint_values
                           ? JointValuesStale(now_utime)
                           : in != &inputs_.camera() && in->Stale(now_utime, config_.stale_after_s);
    channels.push_back({in->channel(), in->received(), in->superseded(), in->rejected(), stale,
                        in->last_reject_reason()});
  }
  for (const UdpLatest* socket :
       {net_fdm_ ? &net_fdm_->socket() : nullptr, doubles_ ? &doubles_->socket() : nullptr}) {
    if (socket == nullptr) continue;
    channels.push_back({socket->name(), socket->received(), socket->superseded(),
                        socket->rejected(), false, socket->last_reject_reason()});
  }
  return channels;
}

void RobotFeed::AppendStale(std::int64_t now_utime, std::vector<bool>* stale) const {
  stale->push_back(inputs_.pose().Stale(now_utime, config_.stale_after_s));
  stale->push_back(JointValuesStale(now_utime));
  stale->push_back(inputs_.actors().Stale(now_utime, config_.stale_after_s));
}

bool RobotFeed::JointValuesStale(std::int64_t now_utime) const {
  return inputs_.bones().Stale(now_utime, config_.stale_after_s) &&
         inputs_.joints().Stale(now_utime, config_.stale_after_s);
}

}  // namespace sandbox::bridge
