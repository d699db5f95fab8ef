// Latest-value inputs over real UDP multicast, in one process inside a
// private network namespace (ctest runs this binary through scripts/netns-run;
// it refuses to run outside one). memq:// hands each message over when it is
// handled, so LCM's per-subscription queue only shows here.

#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <string>
#include <thread>

#include "bridge/robot_inputs.h"
#include "sandbox_msgs/robot_pose_t.hpp"
#include "tests/test_util.h"

namespace sandbox::bridge {
namespace {

const char* kUrl = "udpm://239.255.76.67:7667?ttl=0";

template <typename Message>
void Publish(LcmLink& link, const std::string& channel, const Message& message) {
  std::vector<std::uint8_t> bytes(std::size_t(message.getEncodedSize()));
  message.encode(bytes.data(), 0, int(bytes.size()));
  ASSERT_TRUE(link.Publish(channel, bytes.data(), unsigned(bytes.size())));
}

sandbox_msgs::robot_pose_t Pose(std::int64_t seq) {
  sandbox_msgs::robot_pose_t pose{};
  pose.seq = seq;
  pose.position[0] = double(seq), pose.position[2] = 50.0;
  pose.orientation[0] = 1.0;
  return pose;
}

// Drains until `input` has received `count` messages (or 30 s pass).
void DrainUntil(LcmLink& link, const LatestInput& input, std::int64_t count) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (input.received() < count && std::chrono::steady_clock::now() < end) {
    link.Drain();
    link.Wait(10);
  }
}

// The sample level's robot with its inputs on UDP multicast (made in a test
// body, after SetUp has checked for the namespace).
struct Robot {
  scene::Level level = scene::LoadLevel(testing::SampleLevel());
  scene::CollisionWorld world{level};
  scene::RobotState state{level.robots.at(0)};
  LcmLink link{kUrl};
  RobotInputs inputs{link, level, 0};
};

class UdpmTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const char* in_netns = std::getenv("SANDBOX_IN_NETNS");
    if (in_netns == nullptr || std::string(in_netns) != "1") {
      GTEST_SKIP() << "UDP multicast only inside a private network namespace (scripts/netns-run)";
    }
  }
};

TEST_F(UdpmTest, TheNewestOfAThousandPosesBetweenTwoTicksWins) {
  Robot robot;
  auto& [level, world, state, link, inputs] = robot;
  // A thousand poses while the loop sleeps between two ticks (100 kHz at 100
  // ticks a second); LCM's default queue of 30 kept the oldest 30.
  for (int seq = 1; seq <= 1000; ++seq) Publish(link, "ELAHA/POSE", Pose(seq));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  DrainUntil(link, inputs.pose(), 1000);
  EXPECT_EQ(inputs.pose().received(), 1000);
  const RobotInputs::Applied applied = inputs.Apply(&state, &world);
  EXPECT_EQ(applied.pose_seq, 1000);
  EXPECT_EQ(inputs.pose().superseded(), 999);
}

TEST_F(UdpmTest, LockstepKeepsEveryPoseThatArrivedWhileTheLoopWasHeldUp) {
  Robot robot;
  auto& [level, world, state, link, inputs] = robot;
  inputs.set_lockstep(true);
  // Three times the free-running queue arrives while the loop is held up (a
  // busy machine): a lock-step run applies every one, in order.
  const int count = 3 * LatestInput::kQueueCapacity;
  for (int seq = 1; seq <= count; ++seq) Publish(link, "ELAHA/POSE", Pose(seq));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  DrainUntil(link, inputs.pose(), count);
  EXPECT_EQ(inputs.pose().received(), count);
  for (int seq = 1; seq <= count; ++seq) {
    const RobotInputs::Applied applied = inputs.ApplyNext(&state, &world);
    ASSERT_TRUE(applied.pose) << "pose " << seq;
    ASSERT_EQ(applied.pose_seq, seq);
  }
  EXPECT_FALSE(inputs.ApplyNext(&state, &world).pose);
}

TEST_F(UdpmTest, AFragmentedOversizedMessageIsRejectedAndTheGoodPoseStays) {
  Robot robot;
  auto& [level, world, state, link, inputs] = robot;
  Publish(link, "ELAHA/POSE", Pose(5));
  // 2 MB in LCM fragments, then 2 MB on the bones channel.
  const std::vector<std::uint8_t> big(2u << 20, 0x5a);
  ASSERT_TRUE(link.Publish("ELAHA/POSE", big.data(), unsigned(big.size())));
  ASSERT_TRUE(link.Publish("ELAHA/BONES", big.data(), unsigned(big.size())));
  DrainUntil(link, inputs.pose(), 2);
  DrainUntil(link, inputs.bones(), 1);
  ASSERT_EQ(inputs.pose().received(), 2);
  EXPECT_EQ(inputs.pose().last_reject_reason(), "over the channel's budget of 80 bytes");
  EXPECT_EQ(inputs.bones().rejected(), 1);
  EXPECT_EQ(inputs.Apply(&state, &world).pose_seq, 5);
}

}  // namespace
}  // namespace sandbox::bridge
