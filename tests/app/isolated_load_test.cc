// Loading a level apart (--isolate, and any scene file given as the level):
// a file that crashes assimp is an error naming it, not the end of the
// program; what loads there loads here.

#include <gtest/gtest.h>

#include <string>

#include "tests/app/run_sandbox.h"
#include "tests/test_util.h"

namespace {

using sandbox::testing::RunSandbox;

// An OFF file found by tests/fuzz/fuzz_level_file that makes assimp 5.2.5's
// OFF importer read out of bounds (a segmentation fault).
const std::string kCrashingOff = std::string(
    "OFF\n2 2 0\n0 0 0\n1 0 0\n"
    "\xff\xff\xff\xff"
    "10 0\n"
    "\xff\xff\xff\xff"
    "1 1 0\n0 1 0\n3 1 0\n0 1 0\n3 0 0 2\n3 0 2-3\n");

#if defined(__SANITIZE_ADDRESS__)
#define SANDBOX_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SANDBOX_ASAN 1
#endif
#endif

// Under AddressSanitizer the child reports the fault and aborts; its report
// comes first on stderr, so the error is looked for as a line of its own.
#ifdef SANDBOX_ASAN
const char kCrashSignal[] = "(Aborted, signal 6)";
#else
const char kCrashSignal[] = "(Segmentation fault, signal 11)";
#endif

bool HasLine(const std::string& out, const std::string& start) {
  return out.rfind(start, 0) == 0 || out.find("\n" + start) != std::string::npos;
}

TEST(IsolatedLoadTest, AFileThatCrashesTheImporterIsAnErrorNamingIt) {
  sandbox::testing::TempDir dir;
  const std::string off = dir.Write("crash.off", kCrashingOff).string();
  const std::string crashed = off + ": assimp crashed reading it " + kCrashSignal;
  // A scene file given as the level is always read apart first.
  const auto info = RunSandbox("info " + off);
  EXPECT_EQ(info.exit_code, 1) << info.out;
  EXPECT_TRUE(HasLine(info.out, "sandbox info: " + crashed)) << info.out;
  const auto render = RunSandbox("render " + off + " --camera fixed --at 0,0,5 --out " +
                                 (dir.path() / "frame.png").string());
  EXPECT_EQ(render.exit_code, 1) << render.out;
  EXPECT_TRUE(HasLine(render.out, "sandbox render: " + crashed)) << render.out;
  // In a manifest: named as the file the child was reading.
  const std::string level =
      dir.Write("level.toml", "[[actor]]\nname = \"a\"\nfile = \"crash.off\"\n").string();
  const auto run = RunSandbox("run " + level + " --isolate --duration 0.1 --lcm-url memq://");
  EXPECT_EQ(run.exit_code, 1) << run.out;
  EXPECT_TRUE(HasLine(run.out, "sandbox run: " + crashed)) << run.out;
  const auto scan = RunSandbox("scan " + level + " --isolate --at 0,0,5 --out " +
                               (dir.path() / "scan.csv").string());
  EXPECT_EQ(scan.exit_code, 1) << scan.out;
  EXPECT_TRUE(HasLine(scan.out, "sandbox scan: " + crashed)) << scan.out;
}

TEST(IsolatedLoadTest, ErrorsAndGoodLevelsAreTheSameApart) {
  sandbox::testing::TempDir dir;
  // An error found apart is the error found here.
  const std::string bad =
      dir.Write("bad.toml", "[[actor]]\nname = \"a\"\nfile = \"none.obj\"\n").string();
  const auto here = RunSandbox("info " + bad);
  const auto apart = RunSandbox("info " + bad + " --isolate");
  EXPECT_EQ(here.exit_code, 1);
  EXPECT_EQ(apart.exit_code, 1);
  EXPECT_EQ(apart.out, here.out);
  EXPECT_NE(here.out.find("none.obj: no such file"), std::string::npos) << here.out;
  // The sample level loads apart and then here.
  const auto sample = RunSandbox("run --isolate --duration 0.2 --lcm-url memq://");
  EXPECT_EQ(sample.exit_code, 0) << sample.out;
}

TEST(IsolatedLoadTest, AnImportOverItsMemoryLimitIsAnErrorNamingTheLimit) {
#ifdef SANDBOX_ASAN
  GTEST_SKIP() << "AddressSanitizer needs terabytes of address space: no limit is set under it";
#endif
  sandbox::testing::TempDir dir;
  // A 2048 x 2048 heightmap takes about 300 MB as a mesh; the program itself
  // about 600 MB of address space. 700 MB is too little for both.
  dir.Write("land.pgm", "P5\n2048 2048\n255\n" + std::string(2048 * 2048, '\x40'));
  const std::string tight = dir.Write("tight.toml",
                                      "[level]\nmax_import_mb = 700\n[[actor]]\nname = \"land\"\n"
                                      "heightmap = \"land.pgm\"\nsize = [100, 100, 10]\n")
                                .string();
  const auto limited = RunSandbox("info " + tight + " --isolate");
  EXPECT_EQ(limited.exit_code, 1) << limited.out;
  EXPECT_NE(limited.out.find("land.pgm: importing it needed more than 700 MB ([level] "
                             "max_import_mb in a level manifest)"),
            std::string::npos)
      << limited.out;
  // Too little to start at all: said so.
  const std::string none = dir.Write("none.toml",
                                     "[level]\nmax_import_mb = 1\n[[actor]]\nname = \"land\"\n"
                                     "heightmap = \"land.pgm\"\nsize = [100, 100, 10]\n")
                               .string();
  const auto unstarted = RunSandbox("info " + none + " --isolate");
  EXPECT_EQ(unstarted.exit_code, 1) << unstarted.out;
  EXPECT_NE(unstarted.out.find("could not start"), std::string::npos) << unstarted.out;
}

}  // namespace
