#include "bridge/unknown_robots.h"

#include <stdexcept>

#include "bridge/lcm_link_impl.h"

namespace sandbox::bridge {
namespace {

void Deliver(const lcm::ReceiveBuffer*, const std::string& channel, UnknownRobots* watcher) {
  watcher->OnPose(channel);
}

}  // namespace

UnknownRobots::UnknownRobots(LcmLink& link, const std::vector<std::string>& prefixes,
                             RejectLog* log)
    : link_(link), log_(log) {
  std::string robots;
  for (const std::string& prefix : prefixes) {
    known_.insert(prefix + "/POSE");
    robots += (robots.empty() ? "" : ", ") + prefix;
  }
  reason_ = "a pose for a robot this level does not have; its robots are " + robots;
  // LCM matches the whole channel name against the expression.
  lcm::Subscription* subscription = link_.impl().lcm.subscribeFunction(".*/POSE", &Deliver, this);
  if (subscription == nullptr)
    throw std::runtime_error("UnknownRobots::UnknownRobots(): cannot subscribe");
  subscription->setQueueCapacity(LatestInput::kQueueCapacity);
  subscription_ = subscription;
}

UnknownRobots::~UnknownRobots() {
  link_.impl().lcm.unsubscribe(static_cast<lcm::Subscription*>(subscription_));
}

void UnknownRobots::OnPose(const std::string& channel) {
  if (known_.count(channel)) return;
  ++total_;
  const bool counted_apart = poses_.count(channel) || poses_.size() < kMaxChannels;
  const std::string key = counted_apart ? channel : "(other channels)";
  ++poses_[key];
  if (log_ != nullptr) {
    log_->Note(Printable(key, 64), reason_);
  }
}

}  // namespace sandbox::bridge
