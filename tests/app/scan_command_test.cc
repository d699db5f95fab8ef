// `sandbox scan` as a user runs it: CSV and PLY contents against the
// analytic terrain, and clear errors.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "assets/generators/sample_terrain.h"
#include "tests/app/run_sandbox.h"
#include "tests/test_util.h"

namespace {

using sandbox::testing::RunSandbox;

std::vector<std::string> Lines(const std::string& file) {
  std::ifstream in(file);
  std::vector<std::string> lines;
  std::string line;
  while (std::getline(in, line)) lines.push_back(line);
  return lines;
}

std::vector<double> Cells(const std::string& line) {
  std::vector<double> cells;
  std::stringstream in(line);
  std::string cell;
  while (std::getline(in, cell, ',')) cells.push_back(std::stod(cell));
  return cells;
}

TEST(ScanCommandTest, FaceScanCsvMatchesTheTerrainBelow) {
  sandbox::testing::TempDir dir;
  const std::string csv = (dir.path() / "scan.csv").string();
  // World-aligned box 10 m above the ground at (-20, 150), 100 m from any rock or
  // building: the -Z face's rows and
  // columns are world y and x, 1 m apart.
  const double x = -20, y = 150, z = sandbox::assets::sample::TerrainHeight(-20, 150) + 10.0;
  std::ostringstream at;
  at << x << "," << y << "," << z;
  const auto run = RunSandbox("scan --at " + at.str() + " --aligned world --out " + csv);
  ASSERT_EQ(run.exit_code, 0) << run.out;
  const std::vector<std::string> lines = Lines(csv);
  ASSERT_EQ(lines.size(), 1u + 6u * 51u * 51u);
  EXPECT_EQ(lines[0], "face,row,col,occupancy,x,y,z,surface,nx,ny,nz");
  // The table beside it names the terrain's id.
  int terrain = -1;
  for (const std::string& row : Lines((dir.path() / "scan_surfaces.csv").string())) {
    if (row.find(",actor,terrain,") != std::string::npos) terrain = std::stoi(row);
  }
  ASSERT_GT(terrain, 0);
  int checked = 0;
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const std::vector<double> c = Cells(lines[i]);
    if (c[0] != 5 || c[3] != 1) continue;  // -Z face, occupied
    EXPECT_DOUBLE_EQ(c[4], x - 25 + c[2]);
    EXPECT_DOUBLE_EQ(c[5], y - 25 + c[1]);
    // The terrain is piecewise flat between 2 m grid points: within 5 cm of the function.
    EXPECT_NEAR(c[6], sandbox::assets::sample::TerrainHeight(c[4], c[5]), 0.05);
    EXPECT_EQ(c[7], terrain);
    // The normal faces the ray (up): its slope is the terrain's, to the 2 m grid's steps.
    const double dx = sandbox::assets::sample::TerrainHeight(c[4] + 0.5, c[5]) -
                      sandbox::assets::sample::TerrainHeight(c[4] - 0.5, c[5]);
    EXPECT_NEAR(std::hypot(c[8], c[9], c[10]), 1.0, 1e-5);
    EXPECT_GT(c[10], 0.0);
    EXPECT_NEAR(-c[8] / c[10], dx, 0.5);
    ++checked;
  }
  EXPECT_GT(checked, 2000);
}

TEST(ScanCommandTest, LidarCsvAndPlyColours) {
  sandbox::testing::TempDir dir;
  const std::string csv = (dir.path() / "lidar.csv").string();
  ASSERT_EQ(RunSandbox("scan --at 0,0,30 --sensor lidar --out " + csv).exit_code, 0);
  const std::vector<std::string> lines = Lines(csv);
  ASSERT_EQ(lines.size(), 1u + 16u * 1024u);
  EXPECT_EQ(lines[0], "channel,step,hit,x,y,z,range,intensity,surface,nx,ny,nz");
  for (std::size_t i = 1; i < lines.size(); ++i) {  // a hit has an id and a unit normal
    const std::vector<double> c = Cells(lines[i]);
    ASSERT_EQ(c.size(), 12u);
    EXPECT_EQ(c[2] != 0, c[8] != 0) << lines[i];
    if (c[2] != 0) {
      EXPECT_NEAR(std::hypot(c[9], c[10], c[11]), 1.0, 1e-5) << lines[i];
    }
  }
  const std::string ply = (dir.path() / "face.ply").string();
  ASSERT_EQ(RunSandbox("scan --at 0,0,30 --out " + ply).exit_code, 0);
  const std::vector<std::string> points = Lines(ply);
  ASSERT_GT(points.size(), 10u);
  EXPECT_EQ(points[0], "ply");
  int red = 0, green = 0;
  for (const std::string& line : points) {
    std::istringstream in(line);
    double x, y, z;
    int r, g, b, surface;
    if (!(in >> x >> y >> z >> r >> g >> b >> surface)) continue;  // the header
    red += r == 255 && g == 0 && b == 0 && surface > 0;
    green += r == 0 && g == 255 && b == 0 && surface == 0;
  }
  EXPECT_EQ(red + green, 6 * 51 * 51);
  EXPECT_GT(red, 51 * 51 - 100);  // nearly every down ray hits the valley
}

// The lidar's manifest keys on the command line: its size, its noise against
// the exact sweep from the same pose, its intensity and its last returns.
TEST(ScanCommandTest, LidarSettingsFromTheCommandLine) {
  sandbox::testing::TempDir dir;
  const std::string exact = (dir.path() / "exact.csv").string();
  const std::string noisy = (dir.path() / "noisy.csv").string();
  const std::string shape =
      "channels = 4, min_elevation_deg = -60, max_elevation_deg = -30, azimuth_steps = 512";
  ASSERT_EQ(RunSandbox("scan --at 0,0,30 --sensor lidar --lidar '" + shape + "' --out " + exact)
                .exit_code,
            0);
  ASSERT_EQ(RunSandbox("scan --at 0,0,30 --sensor lidar --lidar '" + shape +
                       ", range_noise_sigma_m = 0.5, seed = 3' --out " + noisy)
                .exit_code,
            0);
  const std::vector<std::string> a = Lines(exact), b = Lines(noisy);
  ASSERT_EQ(a.size(), 1u + 4u * 512u);
  ASSERT_EQ(b.size(), a.size());
  EXPECT_EQ(a[0], "channel,step,hit,x,y,z,range,intensity,surface,nx,ny,nz");
  double sum = 0.0, sum2 = 0.0;
  int hits = 0;
  for (std::size_t i = 1; i < a.size(); ++i) {
    const std::vector<double> p = Cells(a[i]), q = Cells(b[i]);
    ASSERT_EQ(p.size(), 12u);
    ASSERT_EQ(q.size(), 12u);
    if (p[2] == 0) {
      EXPECT_EQ(p[7], 0.0) << a[i];  // no return, no intensity
      continue;
    }
    EXPECT_GT(p[7], 0.0) << a[i];  // the valley, lit at some incidence
    EXPECT_LE(p[7], 1.0) << a[i];
    const double d = q[6] - p[6];
    sum += d, sum2 += d * d, ++hits;
  }
  ASSERT_GT(hits, 1500);  // the beams point 30-60 degrees down onto the valley
  const double mean = sum / hits, sigma = std::sqrt(sum2 / hits - mean * mean);
  EXPECT_NEAR(sigma, 0.5, 0.05);
  EXPECT_NEAR(mean, 0.0, 0.05);

  const std::string cone = (dir.path() / "cone.csv").string();
  ASSERT_EQ(RunSandbox("scan --at 0,0,30 --sensor lidar --lidar '" + shape +
                       ", divergence_deg = 0.5' --out " + cone)
                .exit_code,
            0);
  const std::vector<std::string> c = Lines(cone);
  ASSERT_EQ(c.size(), a.size());
  EXPECT_EQ(c[0],
            "channel,step,hit,x,y,z,range,intensity,last_range,last_surface,last_intensity,"
            "surface,nx,ny,nz");
  EXPECT_EQ(Cells(c[1]).size(), 15u);
}

TEST(ScanCommandTest, BadLidarSettingsNameTheKey) {
  sandbox::testing::TempDir dir;
  const std::string out = " --out " + (dir.path() / "x.csv").string();
  auto run = RunSandbox("scan --at 0,0,30 --sensor lidar --lidar 'seed = -1'" + out);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_EQ(run.out, "sandbox scan: --lidar:1: lidar: 'seed' must be 0 or more\n");
  run = RunSandbox("scan --at 0,0,30 --sensor lidar --lidar 'dropout_probability = 1.5'" + out);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.out.find("dropout_probability"), std::string::npos) << run.out;
  run = RunSandbox("scan --at 0,0,30 --sensor lidar --lidar 'chanels = 4'" + out);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.out.find("chanels"), std::string::npos) << run.out;
  run = RunSandbox("scan --at 0,0,30 --sensor lidar --lidar 'channels ='" + out);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.out.find("--lidar: TOML syntax error"), std::string::npos) << run.out;
  run = RunSandbox("scan --at 0,0,30 --lidar 'channels = 4'" + out);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_EQ(run.out, "sandbox scan: --lidar sets the lidar: give --sensor lidar\n");
}

TEST(ScanCommandTest, BadArgumentsAreOneClearMessage) {
  sandbox::testing::TempDir dir;
  const std::string out = " --out " + (dir.path() / "x.csv").string();
  auto run = RunSandbox("scan --at 0,0,nan" + out);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_EQ(run.out, "sandbox scan: --at: 'nan' is not a finite number\n");
  run = RunSandbox("scan --at 0,0,30 --resolution 0.01 --half-extent 100" + out);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_EQ(run.out,
            "sandbox scan: half_extent_m 100 at resolution_m 0.01 makes 6 x 20001 x 20001 = "
            "2400240006 samples a scan, over sample_budget 10000000\n");
  EXPECT_EQ(RunSandbox("scan --at 0,0,30 --sensor sonar" + out).exit_code, 2);
  EXPECT_EQ(RunSandbox("scan --out x.csv").exit_code, 2);
}

}  // namespace
