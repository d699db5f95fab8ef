// sandbox view's command line: what it refuses before it serves anything
// (the player itself is tests/web/recorded_view.py, in a browser).
#include <gtest/gtest.h>

#include "tests/app/run_sandbox.h"
#include "tests/test_util.h"

namespace {

using sandbox::testing::RunSandbox;

TEST(ViewCommandTest, ALogIsNeededReadableAndTheAddressChecked) {
  auto run = RunSandbox("view");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.out.find("sandbox view: which log?"), std::string::npos) << run.out;
  run = RunSandbox("view /nonexistent/flight.lcmlog");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.out.find("/nonexistent/flight.lcmlog"), std::string::npos) << run.out;
  sandbox::testing::TempDir dir;
  const std::string empty = dir.Write("empty.lcmlog", "").string();
  run = RunSandbox("view " + empty + " --web 70000");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.out.find("--web"), std::string::npos) << run.out;
  run = RunSandbox("view " + empty + " --web 0");
  EXPECT_EQ(run.exit_code, 1) << run.out;  // nothing to replay
  EXPECT_NE(run.out.find(empty), std::string::npos) << run.out;
}

}  // namespace
