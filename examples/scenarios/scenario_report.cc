// The closed-loop scenarios' settings and figures (docs/how-to/contact.md):
//
//   scenario_report SCENARIO --args model|contact    the rigid body's or contact module's options
//   scenario_report SCENARIO --poses CSV --contacts CSV [--plot PNG] [--check]
//
// The second form reads the rigid body's and the contact module's logs,
// prints the scenario's figures, plots height, orientation, force and torque
// against time, and with --check exits 1 unless each figure is within the
// bound the issue asks for. The expected values are derived here from the
// scenario's settings and geometry (the grid of scan points, the analytic
// terrain), not from the code under test.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "assets/generators/sample_terrain.h"

namespace {

constexpr double kG = 9.81, kRadToDeg = 180.0 / M_PI;

// One scenario's settings: the level (examples/scenarios/<level>.toml), the
// body, its start and the contact law, in the programs' own options.
struct Scenario {
  std::string level;
  std::string model;    // rigid_body options
  std::string contact;  // contact_module options (the mesh added by the script)
  double mass_kg, margin_m, stiffness, resolution_m, half_extent_m;
};

const std::map<std::string, Scenario>& Scenarios() {
  // The box: 100 kg, 1 m; k A = 1e5 N/m under its 1 m^2, so it rests 9.81 mm
  // into its 1 cm margin. Placed at rest: at that height, 0.5 + 0.01 - 0.00981.
  static const std::string box_law =
      "--resolution 0.05 --margin 0.01 --stiffness 1e5 --damping 5e3 --slip-damping 2e3";
  static const std::map<std::string, Scenario> scenarios = {
      {"flat_drop",
       {"flat_ground", "--mass 100 --box-size 1,1,1 --position 0,0,1.0 --dt 0.01 --duration 30",
        box_law, 100, 0.01, 1e5, 0.05, 1.025}},
      {"flat_rest",
       {"flat_ground", "--mass 100 --box-size 1,1,1 --position 0,0,0.50019 --dt 0.01 --duration 30",
        box_law, 100, 0.01, 1e5, 0.05, 1.025}},
      {"step_edge",
       {"step_edge", "--mass 100 --box-size 1,1,1 --position 0.1,0,1.1 --dt 0.01 --duration 6",
        box_law, 100, 0.01, 1e5, 0.05, 1.025}},
      // The wing: 200 kg, 25.2 m x 1 m x 0.12 m, 3 m short of (16, -96) on
      // heading 100 deg at 6 m/s, sinking at 0.5 m/s, its belly 0.29 m above the terrain.
      {"landing",
       {"landing",
        "--mass 200 --box-size 1,25.2,0.12 --position 16.52,-98.95,14.46 --rpy-deg 0,0,100 "
        "--velocity -1.042,5.909,-0.5 --dt 0.005 --duration 8",
        "--resolution 0.25 --voxel 0.02 --band 0.05 --margin 0.02 --stiffness 2e4 --damping 1e3 "
        "--slip-damping 500",
        200, 0.02, 2e4, 0.25, 13.0}},
  };
  return scenarios;
}

struct Series {
  std::vector<std::string> names;
  std::vector<std::vector<double>> rows;
  int Column(const std::string& name) const {
    const auto it = std::find(names.begin(), names.end(), name);
    if (it == names.end()) throw std::runtime_error("no column " + name);
    return int(it - names.begin());
  }
  double At(std::size_t row, const std::string& name) const {
    return rows[row][std::size_t(Column(name))];
  }
};

Series ReadCsv(const std::string& file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error(file + ": cannot read");
  Series series;
  std::string line, cell;
  std::getline(in, line);
  for (std::istringstream header(line); std::getline(header, cell, ',');)
    series.names.push_back(cell);
  while (std::getline(in, line)) {
    std::vector<double> row;
    for (std::istringstream cells(line); std::getline(cells, cell, ',');)
      row.push_back(std::stod(cell));
    if (row.size() != series.names.size()) throw std::runtime_error(file + ": a short row");
    series.rows.push_back(row);
  }
  if (series.rows.empty()) throw std::runtime_error(file + ": no rows");
  return series;
}

Eigen::Quaterniond Orientation(const Series& poses, std::size_t i) {
  return Eigen::Quaterniond(poses.At(i, "qw"), poses.At(i, "qx"), poses.At(i, "qy"),
                            poses.At(i, "qz"));
}

// Angle between the body's z axis and the world's, degrees.
double TiltDeg(const Eigen::Quaterniond& R_WB) {
  const Eigen::Vector3d z = R_WB * Eigen::Vector3d::UnitZ();
  return std::atan2(std::hypot(z.x(), z.y()), z.z()) * kRadToDeg;
}

// Scan points of a face strictly within |coordinate| < half along one axis
// (the face grid: -E + c res, c = 0 .. n-1).
int GridPointsWithin(double half, double resolution, double half_extent) {
  const int n = int(std::lround(2.0 * half_extent / resolution)) + 1;
  int count = 0;
  for (int c = 0; c < n; ++c) count += std::abs(-half_extent + c * resolution) < half;
  return count;
}

// Figures and their bounds; --check fails on any out of bounds.
struct Figures {
  bool ok = true;
  void Add(const std::string& name, double value, double low, double high, const char* unit) {
    const bool within = value >= low && value <= high;
    ok = ok && within;
    std::printf("  %-44s %12.6g %-4s [%g, %g] %s\n", name.c_str(), value, unit, low, high,
                within ? "ok" : "OUT OF BOUNDS");
  }
};

// --- The plot: four panels against time, drawn with OpenCV.
struct Line {
  std::string label;
  std::vector<double> values;
  cv::Scalar colour;
};

void DrawPanel(cv::Mat& image, cv::Rect area, const std::string& title,
               const std::vector<double>& t, const std::vector<Line>& lines) {
  double lo = INFINITY, hi = -INFINITY;
  for (const Line& line : lines) {
    for (const double v : line.values) lo = std::min(lo, v), hi = std::max(hi, v);
  }
  if (!(hi > lo)) lo -= 1.0, hi += 1.0;
  const double pad = 0.05 * (hi - lo);
  lo -= pad, hi += pad;
  const cv::Rect plot(area.x + 70, area.y + 25, area.width - 90, area.height - 50);
  cv::rectangle(image, plot, cv::Scalar(180, 180, 180));
  const double t0 = t.front(), t1 = std::max(t.back(), t0 + 1e-9);
  auto at = [&](double time, double v) {
    return cv::Point(plot.x + int((time - t0) / (t1 - t0) * plot.width),
                     plot.y + plot.height - int((v - lo) / (hi - lo) * plot.height));
  };
  if (lo < 0.0 && hi > 0.0) cv::line(image, at(t0, 0.0), at(t1, 0.0), cv::Scalar(220, 220, 220));
  for (const Line& line : lines) {
    std::vector<cv::Point> points;
    for (std::size_t i = 0; i < t.size(); ++i) points.push_back(at(t[i], line.values[i]));
    cv::polylines(image, points, false, line.colour, 1, cv::LINE_AA);
  }
  const auto font = cv::FONT_HERSHEY_SIMPLEX;
  cv::putText(image, title, {area.x + 70, area.y + 18}, font, 0.5, cv::Scalar(0, 0, 0), 1,
              cv::LINE_AA);
  char text[64];
  std::snprintf(text, sizeof(text), "%.4g", hi);
  cv::putText(image, text, {area.x + 2, plot.y + 10}, font, 0.4, cv::Scalar(0, 0, 0), 1,
              cv::LINE_AA);
  std::snprintf(text, sizeof(text), "%.4g", lo);
  cv::putText(image, text, {area.x + 2, plot.y + plot.height}, font, 0.4, cv::Scalar(0, 0, 0), 1,
              cv::LINE_AA);
  std::snprintf(text, sizeof(text), "%.3g s", t1);
  cv::putText(image, text, {plot.x + plot.width - 40, plot.y + plot.height + 15}, font, 0.4,
              cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  int x = area.x + area.width - 200;
  for (const Line& line : lines) {
    cv::putText(image, line.label, {x, area.y + 18}, font, 0.45, line.colour, 1, cv::LINE_AA);
    x += 60;
  }
}

// What touched when (the contact module's pairs log): per surface, the
// times (s, from the first wrench's input) of the poses it pushed on the
// robot, and the normal force then.
struct Touch {
  double t, normal_n;
  std::int64_t input_seq;
  Eigen::Vector3d force_n;
};
using Touches = std::map<std::string, std::vector<Touch>>;

Touches ReadPairs(const std::string& file, double first_utime) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error(file + ": cannot read");
  std::string line;
  std::getline(in, line);  // input_seq,input_utime,surface,name,points,max_depth_m,normal_n,...
  Touches touches;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::stringstream row(line);
    for (std::string cell; std::getline(row, cell, ',');) cells.push_back(cell);
    if (cells.size() < 10) throw std::runtime_error(file + ": a row of " + line);
    touches[cells[3]].push_back(
        {1e-6 * (std::stod(cells[1]) - first_utime), std::stod(cells[6]), std::stoll(cells[0]),
         Eigen::Vector3d(std::stod(cells[7]), std::stod(cells[8]), std::stod(cells[9]))});
  }
  return touches;
}

// One lane per surface: a mark at each pose it touched the robot.
void DrawTouches(cv::Mat& image, cv::Rect area, const Touches& touches, double t0, double t1) {
  const auto font = cv::FONT_HERSHEY_SIMPLEX;
  cv::putText(image, "what touched the robot, when (contact module's pairs log)",
              {area.x + 70, area.y + 18}, font, 0.5, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  const cv::Rect plot(area.x + 70, area.y + 25, area.width - 90, area.height - 35);
  cv::rectangle(image, plot, cv::Scalar(180, 180, 180));
  const int lane = touches.empty() ? plot.height : plot.height / int(touches.size());
  int k = 0;
  for (const auto& [name, list] : touches) {
    const int y = plot.y + k * lane + lane / 2;
    cv::putText(image, name, {area.x + 2, y + 4}, font, 0.4, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
    for (const Touch& touch : list) {
      const int x = plot.x + int((touch.t - t0) / std::max(t1 - t0, 1e-9) * plot.width);
      cv::line(image, {x, y - lane / 3}, {x, y + lane / 3}, cv::Scalar(200, 80, 30));
    }
    ++k;
  }
}

void Plot(const std::string& file, const std::string& scenario, const Series& poses,
          const Touches* touches) {
  std::vector<double> t, z, turn[3], f[3], tau[3];
  const Eigen::Quaterniond R0 = Orientation(poses, 0);
  for (std::size_t i = 0; i < poses.rows.size(); ++i) {
    t.push_back(poses.At(i, "t"));
    z.push_back(poses.At(i, "z"));
    const Eigen::AngleAxisd since_start(Orientation(poses, i) * R0.conjugate());
    for (int k = 0; k < 3; ++k) {
      turn[k].push_back(since_start.axis()[k] * since_start.angle() * kRadToDeg);
      f[k].push_back(poses.At(i, std::string("f") + "xyz"[k]));
      tau[k].push_back(poses.At(i, std::string("t") + "xyz"[k]));
    }
  }
  const cv::Scalar red(40, 40, 220), green(40, 160, 40), blue(200, 80, 30);
  const int touch_rows = touches != nullptr ? 60 + 25 * int(touches->size()) : 0;
  cv::Mat image(1000 + touch_rows, 900, CV_8UC3, cv::Scalar(255, 255, 255));
  DrawPanel(image, {0, 0, 900, 250}, scenario + ": height of the centre of mass (m)", t,
            {{"z", z, blue}});
  DrawPanel(image, {0, 250, 900, 250}, "orientation: turn since the start, world axes (deg)", t,
            {{"x", turn[0], red}, {"y", turn[1], green}, {"z", turn[2], blue}});
  DrawPanel(image, {0, 500, 900, 250}, "contact force, world (N)", t,
            {{"fx", f[0], red}, {"fy", f[1], green}, {"fz", f[2], blue}});
  DrawPanel(image, {0, 750, 900, 250}, "contact torque about the centre of mass, world (N m)", t,
            {{"tx", tau[0], red}, {"ty", tau[1], green}, {"tz", tau[2], blue}});
  if (touches != nullptr)
    DrawTouches(image, {0, 1000, 900, touch_rows}, *touches, t.front(), t.back());
  if (!cv::imwrite(file, image)) throw std::runtime_error(file + ": cannot write the plot");
}

// --- The figures of each scenario.
void FlatGround(const std::string& name, const Scenario& s, const Series& poses, Figures* figures) {
  const std::size_t last = poses.rows.size() - 1;
  const double t_end = poses.At(last, "t");
  // Rest height: weight on the points under the 1 m footprint, each res^2.
  const int per_side = GridPointsWithin(0.5, s.resolution_m, s.half_extent_m);
  const double area = per_side * per_side * s.resolution_m * s.resolution_m;
  const double expected_z = 0.5 + s.margin_m - s.mass_kg * kG / (s.stiffness * area);
  double z_lo = INFINITY, z_hi = -INFINITY, tilt_max = 0.0;
  for (std::size_t i = 0; i <= last; ++i) {
    tilt_max = std::max(tilt_max, TiltDeg(Orientation(poses, i)));
    if (poses.At(i, "t") >= t_end - 5.0) {
      z_lo = std::min(z_lo, poses.At(i, "z")), z_hi = std::max(z_hi, poses.At(i, "z"));
    }
  }
  std::printf("  (%d x %d points under the box, %.4g m^2: rest height %.6f m)\n", per_side,
              per_side, area, expected_z);
  figures->Add("rest height error (m)", poses.At(last, "z") - expected_z, -2e-4, 2e-4, "m");
  figures->Add("vertical oscillation, last 5 s, peak to peak", z_hi - z_lo, 0.0, 1e-3, "m");
  figures->Add("tilt at the end", TiltDeg(Orientation(poses, last)), 0.0, 0.1, "deg");
  if (name == "flat_rest") figures->Add("largest tilt of the run", tilt_max, 0.0, 0.01, "deg");
  figures->Add("horizontal drift", std::hypot(poses.At(last, "x"), poses.At(last, "y")), 0.0, 1e-3,
               "m");
}

void StepEdge(const Series& poses, Figures* figures) {
  const Eigen::Quaterniond R0 = Orientation(poses, 0);
  // The turn from the start once it has tipped 20 degrees: its axis against
  // the edge's direction (+y; a positive turn about +y lowers the +x side,
  // the gap's).
  std::size_t i = 0;
  while (i + 1 < poses.rows.size() && TiltDeg(Orientation(poses, i)) < 20.0) ++i;
  const Eigen::AngleAxisd turn(Orientation(poses, i) * R0.conjugate());
  const Eigen::Vector3d axis = turn.axis() * (turn.angle() >= 0 ? 1.0 : -1.0);
  std::printf("  (tipped 20 degrees at t = %.3f s; turn %.2f deg about (%.5f, %.5f, %.5f))\n",
              poses.At(i, "t"), turn.angle() * kRadToDeg, axis.x(), axis.y(), axis.z());
  figures->Add("tilt reached", TiltDeg(Orientation(poses, i)), 20.0, 180.0, "deg");
  figures->Add("axis error against the edge (+y, towards the gap)",
               std::acos(std::clamp(axis.dot(Eigen::Vector3d::UnitY()), -1.0, 1.0)) * kRadToDeg,
               0.0, 2.0, "deg");
  // The end: the box's lowest corner on the lower ground (z = 0), past the edge.
  const std::size_t last = poses.rows.size() - 1;
  const Eigen::Quaterniond R = Orientation(poses, last);
  const Eigen::Vector3d p(poses.At(last, "x"), poses.At(last, "y"), poses.At(last, "z"));
  double lowest = INFINITY;
  for (int c = 0; c < 8; ++c) {
    const Eigen::Vector3d corner(c & 1 ? 0.5 : -0.5, c & 2 ? 0.5 : -0.5, c & 4 ? 0.5 : -0.5);
    lowest = std::min(lowest, (p + R * corner).z());
  }
  figures->Add("lowest corner at the end (lower ground z = 0)", lowest, -0.03, 0.03, "m");
  figures->Add("centre of mass at the end, x (past the edge x = 0)", p.x(), 0.0, 10.0, "m");
}

void Landing(const Scenario& s, const Series& poses, const Series& contacts, Figures* figures) {
  using sandbox::assets::sample::TerrainHeight;
  // Touchdown: the first wrenches with contact; their centre of pressure
  // against the analytic terrain under it.
  double worst = 0.0;
  int rows = 0;
  double touchdown_t = NAN;
  for (std::size_t i = 0; i < contacts.rows.size(); ++i) {
    if (contacts.At(i, "points") <= 0) continue;
    if (rows == 0) touchdown_t = 1e-6 * (contacts.At(i, "input_utime") - 1e6);
    const double x = contacts.At(i, "cop_x"), y = contacts.At(i, "cop_y"),
                 z = contacts.At(i, "cop_z");
    worst = std::max(worst, std::abs(z - TerrainHeight(x, y)));
    if (++rows == 20) break;
  }
  std::printf("  (touchdown at t = %.3f s)\n", touchdown_t);
  figures->Add("wrenches with contact in the first 20", rows, 20, 20, "");
  figures->Add("touchdown: centre of pressure off the terrain", worst, 0.0, 0.05, "m");
  // At the end: at rest on the terrain, its weight carried by the contact.
  const std::size_t last = poses.rows.size() - 1;
  const double x = poses.At(last, "x"), y = poses.At(last, "y"), z = poses.At(last, "z");
  double lowest_clearance = INFINITY;
  for (std::size_t i = 0; i < poses.rows.size(); ++i) {
    lowest_clearance = std::min(
        lowest_clearance, poses.At(i, "z") - TerrainHeight(poses.At(i, "x"), poses.At(i, "y")));
  }
  const Eigen::Vector3d v(poses.At(last, "vx"), poses.At(last, "vy"), poses.At(last, "vz"));
  figures->Add("wing centre above the terrain at the end", z - TerrainHeight(x, y), 0.0,
               0.06 + s.margin_m, "m");
  figures->Add("lowest clearance of the wing centre in the run", lowest_clearance, 0.0, 10.0, "m");
  figures->Add("speed at the end", v.norm(), 0.0, 0.05, "m/s");
  figures->Add("vertical force / weight at the end", poses.At(last, "fz") / (s.mass_kg * kG), 0.98,
               1.02, "");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fputs(
        "usage: scenario_report SCENARIO --args model|contact|level\n"
        "       scenario_report SCENARIO --poses CSV --contacts CSV [--pairs CSV] [--plot PNG]\n"
        "                       [--check]\n",
        stderr);
    return 2;
  }
  const std::string name = argv[1];
  const auto found = Scenarios().find(name);
  if (found == Scenarios().end()) {
    std::fprintf(
        stderr,
        "scenario_report: unknown scenario '%s' (flat_drop, flat_rest, step_edge, landing)\n",
        name.c_str());
    return 2;
  }
  const Scenario& scenario = found->second;
  std::map<std::string, std::string> options;
  bool check = false;
  for (int i = 2; i < argc; ++i) {
    const std::string key = argv[i];
    if (key == "--check") {
      check = true;
    } else if (i + 1 < argc && (key == "--args" || key == "--poses" || key == "--contacts" ||
                                key == "--plot" || key == "--pairs")) {
      options[key] = argv[++i];
    } else {
      std::fprintf(stderr, "scenario_report: unknown option %s\n", key.c_str());
      return 2;
    }
  }
  if (options.count("--args")) {
    const std::string& what = options["--args"];
    std::printf("%s\n", (what == "model"     ? scenario.model
                         : what == "contact" ? scenario.contact
                                             : scenario.level)
                            .c_str());
    return 0;
  }
  try {
    const Series poses = ReadCsv(options.at("--poses"));
    const Series contacts = ReadCsv(options.at("--contacts"));
    std::printf("scenario %s: %zu poses, %zu wrenches\n", name.c_str(), poses.rows.size(),
                contacts.rows.size());
    Figures figures;
    if (name == "flat_drop" || name == "flat_rest") FlatGround(name, scenario, poses, &figures);
    if (name == "step_edge") StepEdge(poses, &figures);
    if (name == "landing") Landing(scenario, poses, contacts, &figures);
    std::optional<Touches> touches;
    if (options.count("--pairs") && !contacts.rows.empty()) {
      touches = ReadPairs(options["--pairs"], contacts.At(0, "input_utime"));
      for (const auto& [surface, list] : *touches) {
        double peak = 0.0;
        for (const Touch& touch : list) peak = std::max(peak, touch.normal_n);
        std::printf("  touched %-28s %6zu poses, %.3f to %.3f s, peak normal force %.6g N\n",
                    surface.c_str(), list.size(), list.front().t, list.back().t, peak);
      }
      // The pairs' forces add up to each wrench's total.
      std::map<std::int64_t, Eigen::Vector3d> sums;
      for (const auto& [surface, list] : *touches) {
        for (const Touch& touch : list) {
          sums.try_emplace(touch.input_seq, Eigen::Vector3d::Zero()).first->second += touch.force_n;
        }
      }
      double worst = 0.0, largest = 1e-300;
      for (std::size_t i = 0; i < contacts.rows.size(); ++i) {
        const Eigen::Vector3d total(contacts.At(i, "fx"), contacts.At(i, "fy"),
                                    contacts.At(i, "fz"));
        const auto sum = sums.find(std::int64_t(contacts.At(i, "input_seq")));
        const Eigen::Vector3d pairs = sum != sums.end() ? sum->second : Eigen::Vector3d::Zero();
        worst = std::max(worst, (pairs - total).norm());
        largest = std::max(largest, total.norm());
      }
      figures.Add("body pairs' forces against the total", worst / largest, 0.0, 1e-9, "");
    }
    if (options.count("--plot")) {
      Plot(options["--plot"], name, poses, touches ? &*touches : nullptr);
      std::printf("  plot: %s\n", options["--plot"].c_str());
    }
    if (check && !figures.ok) {
      std::printf("scenario %s: FAILED\n", name.c_str());
      return 1;
    }
    return 0;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "scenario_report: %s\n", error.what());
    return 1;
  }
}
