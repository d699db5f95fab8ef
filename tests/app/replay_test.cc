// `sandbox run --replay` on log files written here with LCM's own LogFile:
// one tick per pose, the same frame indexes and scans from two replays, a
// truncated log replayed up to where it breaks (and said so), and a file that
// is not an LCM log refused.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "sandbox_msgs/bone_values_t.hpp"
#include "sandbox_msgs/robot_pose_t.hpp"
#include "sandbox_msgs/robot_state_t.hpp"
#include "tests/app/flight_log.h"
#include "tests/app/run_sandbox.h"
#include "tests/encoded.h"
#include "tests/test_util.h"

namespace {

using sandbox::testing::Encoded;
using sandbox::testing::RunSandbox;
using sandbox::testing::WriteFlightLog;
namespace fs = std::filesystem;

std::string Read(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(ReplayTest, TwoReplaysGiveOneTickPerPoseAndIdenticalFrameIndexesAndScans) {
  sandbox::testing::TempDir dir;
  const std::string log = (dir.path() / "flight.lcmlog").string();
  WriteFlightLog(log, 120);  // 2.4 s of flight
  std::string first_out;
  for (const char* name : {"a", "b"}) {
    const auto run = RunSandbox("run --replay " + log + " --out " + (dir.path() / name).string() +
                                " --scans-every 0.5");
    ASSERT_EQ(run.exit_code, 0) << run.out;
    EXPECT_NE(run.out.find("sandbox run: 120 ticks"), std::string::npos) << run.out;
    // A replay runs flat out: it never asks for real-time priority (it would
    // starve the machine); only paced runs do, and say so on their first line.
    EXPECT_EQ(run.out.substr(0, run.out.find('\n')).find("priority"), std::string::npos) << run.out;
    EXPECT_NE(run.out.find("0 dropped, 0 failed"), std::string::npos) << run.out;  // lossless
  }
  // Cameras due by input time: chase 30 fps over 2.38 s of input is 72 frames.
  for (const char* file : {"chase.csv", "belly.csv", "trailing.csv"}) {
    const std::string a = Read(dir.path() / "a" / file);
    EXPECT_FALSE(a.empty()) << file;
    EXPECT_EQ(a, Read(dir.path() / "b" / file)) << file;
  }
  int lines = 0;
  for (const char c : Read(dir.path() / "a" / "chase.csv")) lines += c == '\n';
  EXPECT_EQ(lines - 1, 72);
  int scans = 0, sheets = 0;
  for (const auto& entry : fs::directory_iterator(dir.path() / "a" / "scans")) {
    scans += entry.path().extension() == ".ply";
    sheets += entry.path().extension() == ".png";
    EXPECT_EQ(Read(entry.path()), Read(dir.path() / "b" / "scans" / entry.path().filename()))
        << entry.path().filename();
  }
  EXPECT_EQ(scans, 5);   // at 0, 0.5, 1.0, 1.5 and 2.0 s of input time
  EXPECT_EQ(sheets, 5);  // each with its sheet
}

TEST(ReplayTest, PosesForRobotsTheLevelDoesNotHaveAreCountedAndReportedNotApplied) {
  sandbox::testing::TempDir dir;
  const std::string log = (dir.path() / "flight.lcmlog").string();
  WriteFlightLog(log, 50);
  WriteFlightLog(log, 30, 20'000, 10.0, "a", "GHOST/POSE");  // a robot the sample level lacks
  const auto run = RunSandbox("run --replay " + log);
  ASSERT_EQ(run.exit_code, 0) << run.out;
  EXPECT_NE(run.out.find("sandbox run: 50 ticks"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("    ELAHA/POSE: 50 received, 0 superseded, 0 rejected"),
            std::string::npos)
      << run.out;
  EXPECT_NE(run.out.find("poses for robots this level does not have, not applied: 30\n"
                         "    GHOST/POSE: 30\n"),
            std::string::npos)
      << run.out;
  // Logged as it happens, naming the channel and the robots there are.
  EXPECT_NE(run.out.find("GHOST/POSE: rejected (a pose for a robot this level does not have; "
                         "its robots are ELAHA)"),
            std::string::npos)
      << run.out;
}

// How many messages a recorded log holds on `channel`, from `sandbox topics --log`.
int MessagesOn(const std::string& log, const std::string& channel) {
  const auto json = RunSandbox("topics --log " + log + " --json");
  EXPECT_EQ(json.exit_code, 0) << json.out;
  const std::string key = "{\"channel\":\"" + channel + "\",";
  const auto at = json.out.find(key);
  if (at == std::string::npos) return 0;
  const auto count = json.out.find("\"messages\":", at);
  return std::stoi(json.out.substr(count + 11));
}

// A model that restarts its clock, and one whose clock starts below zero:
// the altimeter (50 Hz) and the face scanner (every tick) keep the tick
// schedule, one output per pose, and the jump is said once, naming the channel.
TEST(ReplayTest, InputTimeThatJumpsBackOrIsNegativeKeepsTheSensorsOnTheTickSchedule) {
  sandbox::testing::TempDir dir;
  const std::string log = (dir.path() / "restart.lcmlog").string();
  WriteFlightLog(log, 60);                      // 1.00 .. 2.18 s
  WriteFlightLog(log, 60, 20'000, 100.0, "a");  // 1.00 .. 2.18 s again: back by 1.18 s
  const std::string out = (dir.path() / "out.lcmlog").string();
  auto run = RunSandbox("run --replay " + log + " --record " + out);
  ASSERT_EQ(run.exit_code, 0) << run.out;
  EXPECT_NE(run.out.find("sandbox run: 120 ticks"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("ELAHA/POSE: input time jumped back by 1.180000 s (from 2.180000 s to "
                         "1.000000 s); the sensors keep the loop's schedule"),
            std::string::npos)
      << run.out;
  EXPECT_EQ(MessagesOn(out, "ELAHA/RANGE"), 120);
  EXPECT_EQ(MessagesOn(out, "ELAHA/SCAN_FACE"), 120);

  const std::string negative = (dir.path() / "negative.lcmlog").string();
  WriteFlightLog(negative, 50, 20'000, 100.0, "w", "ELAHA/POSE", -2'000'000);
  run = RunSandbox("run --replay " + negative + " --record " + out);
  ASSERT_EQ(run.exit_code, 0) << run.out;
  EXPECT_EQ(run.out.find("jumped back"), std::string::npos) << run.out;
  EXPECT_EQ(MessagesOn(out, "ELAHA/RANGE"), 50);
  EXPECT_EQ(MessagesOn(out, "ELAHA/SCAN_FACE"), 50);
}

// Every message on `channel` of an LCM log, decoded.
template <typename Message>
std::vector<Message> Decoded(const std::string& path, const std::string& channel) {
  std::vector<Message> messages;
  lcm::LogFile log(path, "r");
  EXPECT_TRUE(log.good()) << path;
  while (const lcm::LogEvent* event = log.readNextEvent()) {
    if (event->channel != channel) continue;
    messages.emplace_back();
    EXPECT_EQ(messages.back().decode(event->data, 0, event->datalen), event->datalen);
  }
  return messages;
}

// A --record log holds what the run applied (STATE), not its inputs: its
// replay takes each STATE as the robot's BONES and POSE, so the replayed run
// applies the first run's inputs again (checked against the poses and bone
// values this test wrote) and its sensors scan exactly as the first run's did.
TEST(ReplayTest, ARecordedRunIsReplayedFromItsStates) {
  sandbox::testing::TempDir dir;
  const std::string inputs = (dir.path() / "inputs.lcmlog").string();
  WriteFlightLog(inputs, 60);
  // The wing's 45 bone values, bending a little more each pose.
  const auto poses = Decoded<sandbox_msgs::robot_pose_t>(inputs, "ELAHA/POSE");
  ASSERT_EQ(poses.size(), 60u);
  auto bend = [](std::size_t i, int k) { return 0.002 * double(i) * std::sin(1.0 + k); };
  {
    lcm::LogFile log(inputs, "w");
    for (std::size_t i = 0; i < poses.size(); ++i) {
      sandbox_msgs::bone_values_t bones{};
      bones.utime = poses[i].utime;
      bones.seq = std::int64_t(i);
      bones.num_values = 45;
      for (int k = 0; k < 45; ++k) bones.values.push_back(bend(i, k));
      sandbox_msgs::robot_pose_t pose = poses[i];
      for (const auto& [channel, bytes] : {std::pair{std::string("ELAHA/BONES"), Encoded(bones)},
                                           std::pair{std::string("ELAHA/POSE"), Encoded(pose)}}) {
        lcm::LogEvent event{};
        event.timestamp = pose.utime;
        event.channel = channel;
        event.datalen = std::int32_t(bytes.size());
        event.data = const_cast<std::uint8_t*>(bytes.data());
        ASSERT_EQ(log.writeEvent(&event), 0);
      }
    }
  }
  const std::string first = (dir.path() / "first.lcmlog").string(),
                    second = (dir.path() / "second.lcmlog").string();
  auto run = RunSandbox("run --replay " + inputs + " --record " + first + " --out " +
                        (dir.path() / "a").string() + " --scans-every 0.2 --frames none");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  EXPECT_EQ(run.out.find("holds what a run applied"), std::string::npos) << run.out;
  run = RunSandbox("run --replay " + first + " --record " + second + " --out " +
                   (dir.path() / "b").string() + " --scans-every 0.2 --frames none");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  EXPECT_NE(run.out.find("holds what a run applied (ELAHA/STATE before any ELAHA/POSE): its "
                         "states are replayed as ELAHA's POSE and BONES"),
            std::string::npos)
      << run.out;
  EXPECT_NE(run.out.find("sandbox run: 60 ticks"), std::string::npos) << run.out;

  const auto states = Decoded<sandbox_msgs::robot_state_t>(second, "ELAHA/STATE");
  ASSERT_EQ(states.size(), poses.size());
  for (std::size_t i = 0; i < states.size(); ++i) {
    EXPECT_EQ(states[i].utime, poses[i].utime) << i;
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(states[i].position[k], poses[i].position[k], 1e-9);
    for (int k = 0; k < 4; ++k) {
      EXPECT_NEAR(states[i].orientation[k], poses[i].orientation[k], 1e-12) << i;
    }
    ASSERT_EQ(states[i].num_values, 45) << i;
    for (int k = 0; k < 45; ++k)
      EXPECT_NEAR(states[i].bone_values[std::size_t(k)], bend(i, k), 1e-12);
  }
  EXPECT_EQ(MessagesOn(second, "ELAHA/SCAN_FACE"), 60);
  int scans = 0;
  for (const auto& entry : fs::directory_iterator(dir.path() / "a" / "scans")) {
    ++scans;
    EXPECT_EQ(Read(entry.path()), Read(dir.path() / "b" / "scans" / entry.path().filename()))
        << entry.path().filename();
  }
  EXPECT_GE(scans, 5);
}

TEST(ReplayTest, TopicsOfALogGiveTypeRateSizeAndBandwidthAsTableOrJson) {
  sandbox::testing::TempDir dir;
  const std::string log = (dir.path() / "flight.lcmlog").string();
  WriteFlightLog(log, 120);  // every 20 ms: 50 Hz, 119 intervals over 2.38 s
  // robot_pose_t on the wire: fingerprint, utime, seq (8 bytes each), 7 doubles.
  const int bytes = 8 + 8 + 8 + 7 * 8;
  const auto table = RunSandbox("topics --log " + log);
  ASSERT_EQ(table.exit_code, 0) << table.out;
  std::istringstream rows(table.out);
  std::string header, channel, type, total;
  double messages = 0, rate = 0, mean = 0, kBps = 0;
  std::getline(rows, header);
  rows >> channel >> type >> messages >> rate >> mean >> kBps >> total;
  EXPECT_EQ(channel, "ELAHA/POSE");
  EXPECT_EQ(type, "robot_pose_t");
  EXPECT_EQ(messages, 120);
  EXPECT_DOUBLE_EQ(rate, 50.0);
  EXPECT_DOUBLE_EQ(mean, bytes);
  EXPECT_DOUBLE_EQ(kBps, 4.0);  // 119 messages' bytes over 2.38 s
  EXPECT_EQ(total, "total");
  const auto json = RunSandbox("topics --log " + log + " --json");
  ASSERT_EQ(json.exit_code, 0) << json.out;
  EXPECT_NE(
      json.out.find("{\"channel\":\"ELAHA/POSE\",\"type\":\"robot_pose_t\",\"messages\":120,"
                    "\"bytes\":9600,\"rate_hz\":50,\"mean_bytes\":80,\"bandwidth_Bps\":4000}"),
      std::string::npos)
      << json.out;
}

// Names with control characters, bytes that are not UTF-8, and LCM's
// longest (63): each listed once, escaped, the columns wide enough for all.
TEST(ReplayTest, TopicsOfALogShowEveryChannelNameEscapedInColumnsThatFit) {
  sandbox::testing::TempDir dir;
  const std::string log = (dir.path() / "names.lcmlog").string();
  const std::string longest(63, 'L');
  WriteFlightLog(log, 3);
  for (const std::string& name :
       {std::string("bad\xff\xfe"), std::string("new\nline"), std::string("bell\x07"), longest}) {
    WriteFlightLog(log, 3, 20'000, 100.0, "a", name);
  }
  const auto table = RunSandbox("topics --log " + log);
  ASSERT_EQ(table.exit_code, 0) << table.out;
  std::istringstream rows(table.out);
  std::string line;
  std::getline(rows, line);  // the header
  std::set<std::string> listed;
  std::set<std::size_t> type_columns;
  while (std::getline(rows, line) && line.rfind("total", 0) != 0) {
    listed.insert(line.substr(0, line.find(' ')));
    type_columns.insert(line.find("robot_pose_t"));
    for (const char c : line) EXPECT_TRUE(c >= 0x20 && c < 0x7f) << line;  // printable only
  }
  EXPECT_EQ(listed, (std::set<std::string>{"ELAHA/POSE", "bad\\xff\\xfe", "new\\x0aline",
                                           "bell\\x07", longest}));
  ASSERT_EQ(type_columns.size(), 1u) << table.out;  // one type column for every row
  EXPECT_GT(*type_columns.begin(), longest.size()) << table.out;
}

TEST(ReplayTest, TruncatedLogIsReplayedUpToTheBreakAndNotALogIsRefused) {
  sandbox::testing::TempDir dir;
  const std::string log = (dir.path() / "flight.lcmlog").string();
  WriteFlightLog(log, 50);
  const auto size = fs::file_size(log);
  const std::string cut = (dir.path() / "cut.lcmlog").string();
  fs::copy_file(log, cut);
  fs::resize_file(cut, size - 20);  // the last event loses its end
  const auto run = RunSandbox("run --replay " + cut + " --lcm-url memq://");
  EXPECT_EQ(run.exit_code, 0) << run.out;
  EXPECT_NE(run.out.find("sandbox run: 49 ticks"), std::string::npos) << run.out;
  const std::size_t event_size = size / 50;
  EXPECT_NE(run.out.find("is truncated (the event needs " + std::to_string(event_size) +
                         " bytes): event 50 at byte " + std::to_string(49 * event_size) + " of " +
                         std::to_string(size - 20) + "; the 49 events before it were replayed"),
            std::string::npos)
      << run.out;

  const std::string text = dir.Write("notes.lcmlog", "these are not LCM events\n");
  const auto bad = RunSandbox("run --replay " + text);
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.out.find("'" + text + "' is not an LCM log"), std::string::npos) << bad.out;
  const auto missing = RunSandbox("run --replay " + (dir.path() / "nothing.lcmlog").string());
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.out.find("cannot read the LCM log"), std::string::npos) << missing.out;
}

}  // namespace
