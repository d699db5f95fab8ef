#include "bridge/face_points.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace sandbox::bridge {
namespace {

void Quaternion(const Eigen::Matrix3d& R, double wxyz[4]) {
  const Eigen::Quaterniond q(R);
  wxyz[0] = q.w(), wxyz[1] = q.x(), wxyz[2] = q.y(), wxyz[3] = q.z();
}

}  // namespace

void EncodeCompactFace(const sensors::FaceScan& scan, int f,
                       sandbox_msgs::scan_face_compact_t* message) {
  const sensors::ScanFace& face = scan.faces[std::size_t(f)];
  message->face = std::int8_t(f);
  message->n = scan.n;
  message->resolution_m = scan.resolution_m;
  message->half_extent_m = scan.half_extent_m;
  for (int k = 0; k < 3; ++k) message->sensor_position[k] = face.X_WS.translation()[k];
  Quaternion(face.X_WS.linear(), message->sensor_orientation);
  Quaternion(face.X_WB.linear(), message->box_orientation);
  const std::size_t cells = face.distance_m.size();
  message->num_runs = 0;
  message->run_surface.clear(), message->run_length.clear();
  if (scan.surface_ids) {
    for (std::size_t k = 0; k < cells;) {
      std::size_t end = k + 1;
      while (end < cells && face.surface[end] == face.surface[k]) ++end;
      message->run_surface.push_back(face.surface[k]);
      message->run_length.push_back(std::int32_t(end - k));
      k = end;
    }
    message->num_runs = std::int32_t(message->run_surface.size());
  }
  message->num_mm = 0, message->num_m = 0;
  message->distance_mm.clear(), message->distance_m.clear();
  if (scan.encoding == sensors::FaceEncoding::kFloat) {
    message->encoding = 2;
    message->num_m = int(cells);
    message->distance_m.resize(cells);
    for (std::size_t k = 0; k < cells; ++k) {
      const std::int8_t occupancy = face.occupancy[k];
      message->distance_m[k] = occupancy == sensors::kOccupied ? face.distance_m[k]
                               : occupancy == sensors::kFree
                                   ? std::numeric_limits<float>::infinity()
                                   : std::numeric_limits<float>::quiet_NaN();
    }
    return;
  }
  message->encoding = 1;
  message->num_mm = int(cells);
  message->distance_mm.resize(cells);
  for (std::size_t k = 0; k < cells; ++k) {
    std::uint16_t code = kUnvisitedMm;
    if (face.occupancy[k] == sensors::kFree) {
      code = kFreeMm;
    } else if (face.occupancy[k] == sensors::kOccupied) {
      const double mm = std::round(1e3 * double(face.distance_m[k]));
      code = mm < double(kBeyondMm) ? std::uint16_t(std::max(0.0, mm)) : kBeyondMm;
    }
    message->distance_mm[k] = std::int16_t(code);  // LCM has no unsigned types: the bits
  }
}

void CheckCompactFace(const sandbox_msgs::scan_face_compact_t& message) {
  const auto fail = [](const std::string& what) {
    throw std::invalid_argument("bridge::DecodeCompactFace(): " + what);
  };
  if (message.face < 0 || message.face > 5)
    fail("face " + std::to_string(message.face) + " is not 0..5");
  if (message.encoding != 1 && message.encoding != 2)
    fail("encoding " + std::to_string(message.encoding) + " is neither 1 (mm) nor 2 (m)");
  const double E = message.half_extent_m, res = message.resolution_m;
  if (!std::isfinite(E) || !std::isfinite(res) || E <= 0 || res <= 0)
    fail("half_extent_m " + std::to_string(E) + " and resolution_m " + std::to_string(res) +
         " must be finite and > 0");
  // The data's size bounds n before anything is allocated: n^2 cells, as sent.
  const std::int64_t sent = message.encoding == 1 ? message.num_mm : message.num_m;
  const std::size_t held =
      message.encoding == 1 ? message.distance_mm.size() : message.distance_m.size();
  if (message.n < 1 || std::int64_t(message.n) * message.n != sent || std::size_t(sent) != held)
    fail("n = " + std::to_string(message.n) + " needs n^2 distances, the message holds " +
         std::to_string(held));
  const double expected_n = 2.0 * E / res + 1.0;
  if (std::abs(expected_n - message.n) > 0.5)
    fail("n = " + std::to_string(message.n) +
         " does not match 2 half_extent_m / resolution_m + 1 = " + std::to_string(expected_n));
  if (message.num_runs < 0 || std::size_t(message.num_runs) != message.run_surface.size() ||
      std::size_t(message.num_runs) != message.run_length.size())
    fail("num_runs = " + std::to_string(message.num_runs) + " but the id plane holds " +
         std::to_string(message.run_surface.size()) + " ids and " +
         std::to_string(message.run_length.size()) + " lengths");
  std::int64_t covered = 0;
  for (const std::int32_t length : message.run_length) {
    if (length < 1) fail("run_length " + std::to_string(length) + " is not positive");
    covered += length;
  }
  if (message.num_runs > 0 && covered != sent)
    fail("the id plane's runs cover " + std::to_string(covered) +
         " samples, not n^2 = " + std::to_string(sent));
}

FacePoints DecodeCompactFace(const sandbox_msgs::scan_face_compact_t& message) {
  CheckCompactFace(message);
  const int n = message.n;
  const double E = message.half_extent_m, res = message.resolution_m;
  const Eigen::Vector3d p(message.sensor_position[0], message.sensor_position[1],
                          message.sensor_position[2]);
  const Eigen::Matrix3d R =
      Eigen::Quaterniond(message.box_orientation[0], message.box_orientation[1],
                         message.box_orientation[2], message.box_orientation[3])
          .normalized()
          .toRotationMatrix();
  Eigen::Vector3d u, v;
  sensors::FaceGridAxes(message.face, &u, &v);
  const Eigen::Vector3d axis_W = R * sensors::FaceAxis(message.face);
  const Eigen::Vector3d u_W = R * u, v_W = R * v;
  const bool millimetres = message.encoding == 1;
  const std::size_t cells = std::size_t(n) * std::size_t(n);
  FacePoints out;
  out.points_W.assign(cells, Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()));
  out.occupancy.assign(cells, sensors::kUnvisited);
  for (int j = 0; j < message.num_runs; ++j) {
    out.surface.insert(out.surface.end(), std::size_t(message.run_length[std::size_t(j)]),
                       message.run_surface[std::size_t(j)]);
  }
  for (int r = 0; r < n; ++r) {
    for (int c = 0; c < n; ++c) {
      const std::size_t k = std::size_t(r) * std::size_t(n) + std::size_t(c);
      double distance;
      std::int8_t occupancy = sensors::kOccupied;
      if (millimetres) {
        const auto code = std::uint16_t(message.distance_mm[k]);
        if (code == kUnvisitedMm) continue;
        if (code == kBeyondMm) {
          out.occupancy[k] = sensors::kOccupied;  // a hit, but where is not known
          continue;
        }
        occupancy = code == kFreeMm ? sensors::kFree : sensors::kOccupied;
        distance = code == kFreeMm ? E : 1e-3 * code;
      } else {
        const float d = message.distance_m[k];
        if (std::isnan(d)) continue;
        occupancy = std::isinf(d) ? sensors::kFree : sensors::kOccupied;
        distance = std::isinf(d) ? E : double(d);
      }
      out.occupancy[k] = occupancy;
      out.points_W[k] = p + u_W * (-E + c * res) + v_W * (-E + r * res) + axis_W * distance;
    }
  }
  return out;
}

}  // namespace sandbox::bridge
