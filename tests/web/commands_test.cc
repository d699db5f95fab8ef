#include "web/commands.h"
#include "web/player.h"

#include <gtest/gtest.h>

#include <string>

namespace sandbox::web {
namespace {

TEST(PlayerCommandTest, ReadsEachFieldAndRefusesTheRestNamingIt) {
  PlayerCommand c = ParsePlayerCommand(R"({"type":"player","play":true,"speed":2.5,"seek":42})");
  EXPECT_EQ(c.play, true);
  EXPECT_EQ(c.speed, 2.5);
  EXPECT_EQ(c.seek, 42);
  c = ParsePlayerCommand(R"({"type":"player"})");
  EXPECT_FALSE(c.play || c.speed || c.seek);
  const std::pair<const char*, const char*> bad[] = {
      {"not json", "JSON object"},
      {"[1, 2]", "JSON object"},
      {R"({"play":true})", "'type'"},
      {R"({"type":"state"})", "'type'"},
      {R"({"type":"player","play":1})", "'play'"},
      {R"({"type":"player","speed":0})", "'speed'"},
      {R"({"type":"player","speed":1000})", "'speed'"},
      {R"({"type":"player","speed":"fast"})", "'speed'"},
      {R"({"type":"player","seek":-1})", "'seek'"},
      {R"({"type":"player","seek":1.5})", "'seek'"},
      {R"({"type":"player","jump":3})", "unknown field 'jump'"},
  };
  for (const auto& [text, named] : bad) {
    try {
      ParsePlayerCommand(text);
      ADD_FAILURE() << text << " was taken";
    } catch (const std::invalid_argument& error) {
      EXPECT_NE(std::string(error.what()).find(named), std::string::npos)
          << text << ": " << error.what();
    }
  }
}

TEST(CameraCommandTest, TakesTheKeysTheLiveViewSteersCamerasWithAndNoOthers) {
  for (const char* key : kCameraKeys)
    EXPECT_EQ(ParseCameraCommand(std::string(R"({"type":"camera","key":")") + key + "\"}"), key);
  const std::pair<const char*, const char*> bad[] = {
      {"{", "JSON object"},
      {R"({"type":"player","key":"zoom_in"})", "'type'"},
      {R"({"type":"camera"})", "'key'"},
      {R"({"type":"camera","key":"quit"})", "got 'quit'"},
      {R"({"type":"camera","key":"pause"})", "got 'pause'"},
      {R"({"type":"camera","key":7})", "'key'"},
      {R"({"type":"camera","key":"zoom_in","times":3})", "unknown field 'times'"},
  };
  for (const auto& [text, named] : bad) {
    try {
      ParseCameraCommand(text);
      ADD_FAILURE() << text << " was taken";
    } catch (const std::invalid_argument& error) {
      EXPECT_NE(std::string(error.what()).find(named), std::string::npos)
          << text << ": " << error.what();
    }
  }
}

// Ticks 10 ms apart (a 100 Hz log of 101 ticks: 0 to 1 s).
std::vector<double> Ticks() {
  std::vector<double> t;
  for (int i = 0; i <= 100; ++i) t.push_back(0.01 * i);
  return t;
}

TEST(PlayheadTest, PlaysAtItsSpeedPausesSeeksAndStopsAtTheEnd) {
  Playhead head(Ticks());
  EXPECT_EQ(head.At(5.0), 0u);  // paused at the start
  PlayerCommand play;
  play.play = true;
  head.Apply(play, 10.0);
  EXPECT_TRUE(head.playing());
  EXPECT_EQ(head.At(10.0), 0u);
  EXPECT_EQ(head.At(10.2501), 25u);  // 1x: 25 ticks in 0.25 s
  PlayerCommand faster;
  faster.speed = 4.0;
  head.Apply(faster, 10.2501);  // from tick 25 on, 4x
  EXPECT_EQ(head.At(10.3504), 65u);
  PlayerCommand pause;
  pause.play = false;
  head.Apply(pause, 10.3504);
  EXPECT_FALSE(head.playing());
  EXPECT_EQ(head.At(99.0), 65u);  // held
  PlayerCommand seek;
  seek.seek = 90;
  head.Apply(seek, 99.0);
  EXPECT_EQ(head.At(100.0), 90u);
  head.Apply(play, 100.0);  // 4x: the end (tick 100) in 0.025 s, paused there
  EXPECT_EQ(head.At(100.0201), 98u);
  EXPECT_EQ(head.At(101.0), 100u);
  EXPECT_FALSE(head.playing());
  head.Apply(play, 102.0);  // play at the end: from the start
  EXPECT_TRUE(head.playing());
  EXPECT_EQ(head.At(102.0), 0u);
  seek.seek = 5000;  // past the end: the end
  head.Apply(seek, 103.0);
  EXPECT_EQ(head.At(103.0), 100u);
  EXPECT_THROW(Playhead({}), std::invalid_argument);
}

}  // namespace
}  // namespace sandbox::web
