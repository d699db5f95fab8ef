#include "sensors/render/hidden_faces.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <map>
#include <numeric>

#include "sensors/render/mesh_lods.h"

namespace sandbox::render {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

double Cross(const Vector2d& o, const Vector2d& a, const Vector2d& b) {
  return (a - o).x() * (b - o).y() - (a - o).y() * (b - o).x();
}

// The convex hull, counter-clockwise, without collinear points (Andrew's monotone chain).
std::vector<Vector2d> Hull(std::vector<Vector2d> points) {
  std::sort(points.begin(), points.end(), [](const Vector2d& a, const Vector2d& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  points.erase(std::unique(points.begin(), points.end()), points.end());
  if (points.size() < 3) return points;
  std::vector<Vector2d> hull(2 * points.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    while (k >= 2 && Cross(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  for (std::size_t i = points.size() - 1, lower = k + 1; i > 0; --i) {
    while (k >= lower && Cross(hull[k - 2], hull[k - 1], points[i - 1]) <= 0) --k;
    hull[k++] = points[i - 1];
  }
  hull.resize(k - 1);
  return hull;
}

double DistanceToBoundary(const std::vector<Vector2d>& hull, const Vector2d& p) {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < hull.size(); ++i) {
    const Vector2d& a = hull[i];
    const Vector2d& b = hull[(i + 1) % hull.size()];
    const Vector2d ab = b - a;
    const double s = std::clamp((p - a).dot(ab) / std::max(ab.squaredNorm(), 1e-300), 0.0, 1.0);
    best = std::min(best, (a + s * ab - p).norm());
  }
  return best;
}

}  // namespace

HiddenBackFaces HiddenBackFaces::Of(const std::vector<Eigen::Vector3f>& positions,
                                    const std::vector<std::uint32_t>& indices) {
  for (const std::uint32_t i : indices) {
    if (i >= positions.size()) return {};
  }
  const std::vector<std::uint32_t> welded =
      WeldIdentical(indices, positions.size(), {{positions.data(), sizeof(Eigen::Vector3f)}});
  std::vector<std::array<std::uint32_t, 3>> triangles;
  for (std::size_t t = 0; t + 2 < welded.size(); t += 3) {
    const std::uint32_t a = welded[t], b = welded[t + 1], c = welded[t + 2];
    if (a != b && b != c && c != a) triangles.push_back({a, b, c});
  }
  if (triangles.empty()) return {};
  // The edges (lower vertex first) run upwards and downwards, sorted.
  std::vector<std::uint64_t> up, down;
  up.reserve(3 * triangles.size()), down.reserve(3 * triangles.size());
  std::vector<std::uint32_t> piece(positions.size());
  std::iota(piece.begin(), piece.end(), 0u);
  auto find = [&](std::uint32_t v) {
    while (piece[v] != v) v = piece[v] = piece[piece[v]];
    return v;
  };
  HiddenBackFaces out;
  for (const auto& t : triangles) {
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = t[std::size_t(k)], b = t[std::size_t((k + 1) % 3)];
      (a < b ? up : down).push_back(std::uint64_t(std::min(a, b)) << 32 | std::max(a, b));
      piece[find(a)] = find(b);
      out.box_.extend(positions[a]);
    }
  }
  std::sort(up.begin(), up.end());
  std::sort(down.begin(), down.end());
  const bool balanced = up == down;
  const bool at_most_once = std::adjacent_find(up.begin(), up.end()) == up.end() &&
                            std::adjacent_find(down.begin(), down.end()) == down.end();
  auto p = [&](std::uint32_t v) { return Vector3d(positions[v].cast<double>()); };
  if (balanced) {
    // Each piece's volume, from a corner of its own (small sums, little cancellation).
    std::map<std::uint32_t, std::pair<Vector3d, double>> volumes;
    for (const auto& t : triangles) {
      auto [it, fresh] = volumes.try_emplace(find(t[0]), p(t[0]), 0.0);
      const Vector3d& o = it->second.first;
      it->second.second += (p(t[0]) - o).dot((p(t[1]) - o).cross(p(t[2]) - o)) / 6.0;
    }
    for (const auto& [root, volume] : volumes) {
      if (!(volume.second > 0.0)) return {};
    }
    out.shape_ = Shape::kSolid;
    return out;
  }
  if (!at_most_once) return {};
  // A height field: every triangle facing up, ...
  double area_seen = 0.0;
  for (const auto& t : triangles) {
    const Vector3d n = (p(t[1]) - p(t[0])).cross(p(t[2]) - p(t[0]));
    if (!(n.z() > 1e-7 * n.norm())) return {};
    area_seen += 0.5 * n.z();
  }
  // ... the open edges on the footprint's hull, ...
  std::vector<Vector2d> points;
  std::vector<bool> taken(positions.size(), false);
  for (const auto& t : triangles) {
    for (const std::uint32_t v : t) {
      if (!taken[v]) points.push_back(p(v).head<2>());
      taken[v] = true;
    }
  }
  const std::vector<Vector2d> hull = Hull(std::move(points));
  if (hull.size() < 3) return {};
  const Eigen::Vector3f extent = out.box_.sizes();
  const double tolerance = 1e-5 * double(std::max(extent.x(), extent.y()));
  // (Run once: in one list and not the other.)
  std::vector<std::uint64_t> open;
  std::set_symmetric_difference(up.begin(), up.end(), down.begin(), down.end(),
                                std::back_inserter(open));
  for (const std::uint64_t edge : open) {
    const Vector2d a = p(std::uint32_t(edge >> 32)).head<2>(),
                   b = p(std::uint32_t(edge & 0xffffffffu)).head<2>();
    for (const Vector2d& q : {a, b, Vector2d(0.5 * (a + b))}) {
      if (DistanceToBoundary(hull, q) > tolerance) return {};
    }
  }
  // ... and the footprint covered once.
  double hull_area = 0.0;
  for (std::size_t i = 1; i + 1 < hull.size(); ++i) {
    hull_area += 0.5 * Cross(hull[0], hull[i], hull[i + 1]);
  }
  if (!(std::abs(area_seen - hull_area) <= 1e-4 * hull_area)) return {};
  out.shape_ = Shape::kHeightField;
  for (const Vector2d& h : hull) out.hull_.push_back(h.cast<float>());
  // The highest surface over each cell (about 16 triangles a cell, 64 x 64 cells at most).
  const int side = std::clamp(int(std::sqrt(double(triangles.size()) / 16.0)), 1, 64);
  out.cells_x_ = out.cells_y_ = side;
  out.cell_size_ = extent.head<2>().cwiseMax(Eigen::Vector2f::Constant(1e-6f)) / float(side);
  out.top_.assign(std::size_t(side * side), -std::numeric_limits<float>::infinity());
  for (const auto& t : triangles) {
    Eigen::AlignedBox3f box;
    for (const std::uint32_t v : t) box.extend(positions[v]);
    int x0, x1, y0, y1;
    out.Cells(box.min().head<2>(), box.max().head<2>(), &x0, &x1, &y0, &y1);
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        float& top = out.top_[std::size_t(y * side + x)];
        top = std::max(top, box.max().z());
      }
    }
  }
  return out;
}

void HiddenBackFaces::Cells(const Eigen::Vector2f& low, const Eigen::Vector2f& high, int* x0,
                            int* x1, int* y0, int* y1) const {
  auto cell = [&](float v, float origin, float size, int count) {
    return std::clamp(int(std::floor((v - origin) / size)), 0, count - 1);
  };
  *x0 = cell(low.x(), box_.min().x(), cell_size_.x(), cells_x_);
  *x1 = cell(high.x(), box_.min().x(), cell_size_.x(), cells_x_);
  *y0 = cell(low.y(), box_.min().y(), cell_size_.y(), cells_y_);
  *y1 = cell(high.y(), box_.min().y(), cell_size_.y(), cells_y_);
}

HiddenBackFaces HiddenBackFaces::Union(const HiddenBackFaces& a, const HiddenBackFaces& b) {
  if (a.shape_ != Shape::kSolid || b.shape_ != Shape::kSolid) return {};
  HiddenBackFaces out = a;
  out.box_.extend(b.box_);
  return out;
}

bool HiddenBackFaces::HiddenFrom(const Eigen::Vector3f& eye, float near_reach) const {
  switch (shape_) {
    case Shape::kNone:
      return false;
    case Shape::kSolid:
      return box_.exteriorDistance(eye) > near_reach;
    case Shape::kHeightField: {
      const Eigen::Vector2f e = eye.head<2>();
      for (std::size_t i = 0; i < hull_.size(); ++i) {
        const Eigen::Vector2f& a = hull_[i];
        const Eigen::Vector2f& b = hull_[(i + 1) % hull_.size()];
        if ((b - a).x() * (e - a).y() - (b - a).y() * (e - a).x() <= 0.f) return false;
      }
      // Higher than the surface anywhere within the near plane's reach.
      int x0, x1, y0, y1;
      Cells(e - Eigen::Vector2f::Constant(near_reach), e + Eigen::Vector2f::Constant(near_reach),
            &x0, &x1, &y0, &y1);
      for (int y = y0; y <= y1; ++y) {
        for (int x = x0; x <= x1; ++x) {
          if (!(eye.z() - near_reach > top_[std::size_t(y * cells_x_ + x)])) return false;
        }
      }
      return true;
    }
  }
  return false;
}

}  // namespace sandbox::render
