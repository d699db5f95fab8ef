// `sandbox info` as a user runs it: exit codes, output, and one clear message
// (never a crash) for bad input.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <regex>
#include <string>
#include <vector>

#include "tests/app/run_sandbox.h"
#include "tests/test_rasters.h"
#include "tests/test_util.h"

namespace {

using sandbox::testing::CommandRun;

CommandRun Sandbox(const std::string& args) { return sandbox::testing::RunSandbox(args); }

std::size_t Count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(InfoCommandTest, DefaultIsTheSampleLevel) {
  const CommandRun run = Sandbox("info");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  for (const char* actor : {"terrain", "water", "rocks", "wall", "tower", "boulder", "gate"}) {
    EXPECT_NE(run.out.find(actor), std::string::npos) << actor;
  }
  EXPECT_NE(run.out.find("peak memory"), std::string::npos);
}

TEST(InfoCommandTest, JsonListsActorsTotalsAndLoadFigures) {
  const CommandRun run = Sandbox("info " + sandbox::testing::SampleLevel().string() + " --json");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  EXPECT_EQ(run.out.front(), '{');
  EXPECT_EQ(Count(run.out, "\"triangles\": "), 7u + 1u + 1u);  // 7 actors, 1 robot, the totals
  // The flying wing: 24 bones in its bone map, 21 of them with two angles, 3 with one.
  EXPECT_NE(run.out.find("{\"name\": \"ELAHA\", "), std::string::npos);
  EXPECT_NE(run.out.find("\"bones\": 24, \"bone_values\": 45"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("{\"name\": \"gate\", "), std::string::npos);
  EXPECT_NE(run.out.find("\"movable\": true"), std::string::npos);
  EXPECT_NE(run.out.find("\"actors\": 7, \"collision_actors\": 6, \"movable_actors\": 1"),
            std::string::npos)
      << run.out;
  EXPECT_NE(run.out.find("\"peak_memory_mib\": "), std::string::npos);
  EXPECT_EQ(Count(run.out, "{"), Count(run.out, "}"));
  EXPECT_EQ(Count(run.out, "["), Count(run.out, "]"));
}

// Whether the rays walk the static actors in one hierarchy: the count is the
// static collision actors' triangles as the actor list gives them.
TEST(InfoCommandTest, SaysWhetherTheStaticActorsShareOneHierarchy) {
  const CommandRun json = Sandbox("info " + sandbox::testing::SampleLevel().string() + " --json");
  ASSERT_EQ(json.exit_code, 0) << json.out;
  const std::regex actor(
      "\"triangles\": ([0-9]+), \"vertices\": [0-9]+, \"collision\": (true|false), "
      "\"movable\": (true|false)");
  std::size_t static_triangles = 0;
  for (std::sregex_iterator it(json.out.begin(), json.out.end(), actor), end; it != end; ++it) {
    if ((*it)[2] == "true" && (*it)[3] == "false") static_triangles += std::stoul((*it)[1]);
  }
  EXPECT_GT(static_triangles, 0u);
  EXPECT_NE(json.out.find("\"merged_static_triangles\": " + std::to_string(static_triangles)),
            std::string::npos)
      << json.out;
  const CommandRun text = Sandbox("info");
  EXPECT_NE(text.out.find("rays  the static actors' " + std::to_string(static_triangles) +
                          " triangles in one hierarchy"),
            std::string::npos)
      << text.out;
  // One static actor: nothing to merge.
  sandbox::testing::TempDir dir;
  dir.Write("one.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const auto one = dir.Write("one.toml", "[[actor]]\nname = \"a\"\nfile = \"one.obj\"\n");
  const CommandRun single = Sandbox("info " + one.string());
  ASSERT_EQ(single.exit_code, 0) << single.out;
  EXPECT_NE(single.out.find("rays  a hierarchy per object"), std::string::npos) << single.out;
}

// The three numbers after `key` in `text` ("key": [x, y, z]).
std::array<double, 3> Triple(const std::string& text, const std::string& key) {
  std::smatch m;
  const std::regex pattern("\"" + key + "\": \\[([-0-9.e+]+), ([-0-9.e+]+), ([-0-9.e+]+)\\]");
  if (!std::regex_search(text, m, pattern)) return {0, 0, 0};
  return {std::stod(m[1]), std::stod(m[2]), std::stod(m[3])};
}

// A terrain's extent comes from its rasters: a flat raster of 129 x 129
// samples 0.0003 deg apart at 46 deg north spans 0.0387 deg each way, about
// 4,301 m north-south (111.14 km a degree of latitude there) and 2,993 m
// east-west (cos 46 deg of 111.32 km), and a metre of height at most (the
// curvature within 3 km of the anchor).
TEST(InfoCommandTest, ATerrainsExtentComesFromItsRasters) {
  sandbox::testing::TempDir dir;
  sandbox::testing::WriteRaster(dir.path() / "flat.tif", 129, 129, 8.0, 46.02, 0.0003, 1,
                                GDT_Float32, [](int, int, int) { return 500.0; });
  const std::string level = dir.Write("level.toml",
                                      "[[terrain]]\nname = \"ground\"\nanchor = [46.0, 8.02, 500]\n"
                                      "elevation = [\"flat.tif\"]\n")
                                .string();
  const CommandRun json = Sandbox("info " + level + " --json");
  ASSERT_EQ(json.exit_code, 0) << json.out;
  const std::size_t terrain = json.out.find("\"terrain\": {\"name\": \"ground\"");
  ASSERT_NE(terrain, std::string::npos) << json.out;
  EXPECT_NE(json.out.find("\"usable_rasters\": 1", terrain), std::string::npos) << json.out;
  const std::string block = json.out.substr(terrain);
  const auto lo = Triple(block, "bounds_min"), hi = Triple(block, "bounds_max");
  EXPECT_NEAR(hi[0] - lo[0], 2993.0, 15.0) << json.out;
  EXPECT_NEAR(hi[1] - lo[1], 4301.0, 15.0) << json.out;
  EXPECT_GE(hi[2] - lo[2], 0.0);
  EXPECT_LE(hi[2] - lo[2], 1.0) << json.out;
  // The totals and the text's size line include it.
  const auto total_lo = Triple(json.out.substr(json.out.find("\"totals\"")), "bounds_min");
  EXPECT_DOUBLE_EQ(total_lo[0], lo[0]);
  const CommandRun text = Sandbox("info " + level);
  ASSERT_EQ(text.exit_code, 0) << text.out;
  std::smatch size;
  ASSERT_TRUE(std::regex_search(text.out, size, std::regex("size  ([0-9.]+) x ([0-9.]+) x")))
      << text.out;
  EXPECT_NEAR(std::stod(size[1]), 2993.0, 15.0) << text.out;
  EXPECT_NEAR(std::stod(size[2]), 4301.0, 15.0) << text.out;
}

TEST(InfoCommandTest, BadLevelsExitOneWithOneMessage) {
  sandbox::testing::TempDir dir;
  const auto bad = dir.Write("bad.toml", "[[actor]]\nname = \"a\"\nfile = \"x.obj\"\nscale = -2\n");
  CommandRun run = Sandbox("info " + bad.string());
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_EQ(run.out,
            "sandbox info: " + bad.string() + ":4: actor 'a': 'scale' must be positive, got -2\n");

  run = Sandbox("info " + (dir.path() / "none.glb").string());
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_EQ(Count(run.out, "\n"), 1u) << run.out;
  EXPECT_NE(run.out.find("none.glb: no such file"), std::string::npos);

  const auto garbage = dir.Write("garbage.glb", "this is not a glb file at all");
  run = Sandbox("info " + garbage.string());
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_EQ(run.out.find("terminate"), std::string::npos) << run.out;
  EXPECT_EQ(run.out.rfind("sandbox info: " + garbage.string() + ": ", 0), 0u) << run.out;
}

// `info` makes the checks `run` makes: what one refuses the other refuses
// with the same message.
TEST(InfoCommandTest, WhatRunRefusesInfoRefusesWithTheSameMessage) {
  sandbox::testing::TempDir dir;
  const std::string robots =
      (std::filesystem::path(SANDBOX_SOURCE_DIR) / "assets/robots/generated/flying_wing.gltf")
          .string();
  auto level = [&](const std::string& name, const std::string& robot_tables) {
    return dir.Write(name, robot_tables).string();
  };
  auto robot = [&](const std::string& name, const std::string& extra) {
    return "[[robot]]\nname = \"" + name + "\"\nfile = \"" + robots + "\"\n" + extra;
  };
  const std::vector<std::pair<std::string, std::string>> cases = {
      // Two robots of one name.
      {level("names.toml", robot("A", "") + robot("A", "")),
       ":4: duplicate robot name 'A': the [[robot]] on line 1 has it too"},
      // Two robots on one channel prefix.
      {level("prefix.toml",
             robot("A", "") + robot("B", "[robot.bridge]\nchannel_prefix = \"A\"\n")),
       ":8: robot 'B' bridge: robot 'B' would use the channel prefix 'A' of robot 'A'; give one "
       "of them its own 'channel_prefix'"},
      // Channels longer than LCM carries (63 bytes): the robot's, a sensor's.
      {level("long_prefix.toml",
             robot("A", "[robot.bridge]\nchannel_prefix = \"" + std::string(59, 'P') + "\"\n")),
       ":5: robot 'A' bridge: robot 'A' would use the channel '" + std::string(59, 'P') +
           "/POSE' (64 bytes); LCM carries names of at most 63 bytes, without NUL: give it a "
           "shorter 'channel_prefix'"},
      {level("long_sensor.toml",
             robot("A", "[[robot.sensor]]\nname = \"s\"\ntype = \"ray\"\nchannel = \"" +
                            std::string(62, 'S') + "\"\n")),
       ":4: sensor 's': robot 'A' would use the channel 'A/" + std::string(62, 'S') +
           "' (64 bytes); LCM carries names of at most 63 bytes, without NUL: give the sensor a "
           "shorter 'channel'"},
      // A port taken by another robot, and a bind address that is none.
      {level("ports.toml", robot("A", "[robot.bridge]\nnet_fdm_port = 5600\n") +
                               robot("B", "[robot.bridge]\nudp_doubles_port = 5600\n")),
       ":10: robot 'B' bridge: port 5600 is taken by robot 'A'"},
      {level("address.toml", robot("A", "[robot.bridge]\nbind_address = \"localhost\"\n")),
       ":5: robot 'A' bridge: 'bind_address' must be an IPv4 address like 127.0.0.1, got "
       "'localhost'"},
      // A layout that names an item twice.
      {level("layout.toml",
             robot("A", "[robot.bridge]\nudp_doubles_layout = [\"position\", \"position\"]\n")),
       ":5: robot 'A' bridge: 'udp_doubles_layout' names 'position' twice"},
      // A camera of 100000 pixels a side.
      {level("camera.toml", robot("A",
                                  "[[robot.camera]]\nname = \"c\"\ntype = \"chase\"\n"
                                  "width = 100000\n")),
       ":4: camera 'c': resolution must be 1 to 8192 pixels a side, got 100000 x 480"}};
  for (const auto& [file, message] : cases) {
    const CommandRun info = Sandbox("info " + file);
    const CommandRun run = Sandbox("run " + file + " --duration 0.1 --lcm-url memq://");
    EXPECT_EQ(info.exit_code, 1) << info.out;
    EXPECT_EQ(run.exit_code, 1) << run.out;
    EXPECT_EQ(info.out, "sandbox info: " + file + message + "\n");
    EXPECT_EQ(run.out, "sandbox run: " + file + message + "\n");
  }
}

TEST(InfoCommandTest, BadUsageExitsTwo) {
  EXPECT_EQ(Sandbox("info --up sideways").exit_code, 2);
  EXPECT_EQ(Sandbox("info --frobnicate").exit_code, 2);
  EXPECT_EQ(Sandbox("nonsense").exit_code, 2);
  const CommandRun help = Sandbox("info --help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.out.find("usage: sandbox info"), std::string::npos);
}

}  // namespace
