// `sandbox info` as a user runs it: exit codes, output, and one clear message
// (never a crash) for bad input.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

#include "tests/app/run_sandbox.h"
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

TEST(InfoCommandTest, BadUsageExitsTwo) {
  EXPECT_EQ(Sandbox("info --up sideways").exit_code, 2);
  EXPECT_EQ(Sandbox("info --frobnicate").exit_code, 2);
  EXPECT_EQ(Sandbox("nonsense").exit_code, 2);
  const CommandRun help = Sandbox("info --help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.out.find("usage: sandbox info"), std::string::npos);
}

}  // namespace
