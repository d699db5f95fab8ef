#include "scene/triangle_bvh.h"

#include <algorithm>
#include <array>
#include <limits>

namespace sandbox::scene {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr int kBins = 16;
constexpr int kLeafSize = TriangleBvh::kWidth;

struct Box {
  Eigen::Vector3f lower{Eigen::Vector3f::Constant(kInf)}, upper{Eigen::Vector3f::Constant(-kInf)};
  void Extend(const Box& b) { lower = lower.cwiseMin(b.lower), upper = upper.cwiseMax(b.upper); }
  void Extend(const Eigen::Vector3f& p) { lower = lower.cwiseMin(p), upper = upper.cwiseMax(p); }
  float HalfArea() const {
    if (!(lower.array() <= upper.array()).all()) return 0.f;
    const Eigen::Vector3f e = upper - lower;
    return e.x() * e.y() + e.y() * e.z() + e.z() * e.x();
  }
};

struct Triangle {
  Box box;
  Eigen::Vector3f centroid;
  std::array<Eigen::Vector3f, 3> corner;
  std::int32_t part, index;
};

class Builder {
 public:
  explicit Builder(std::vector<Triangle> triangles) : triangles_(std::move(triangles)) {}

  TriangleBvh Build() {
    if (!triangles_.empty()) {
      Box all = BoundsOf(0, triangles_.size());
      bvh_.lower = all.lower, bvh_.upper = all.upper;
      bvh_.root = Subtree(0, triangles_.size(), &bvh_.depth);
    }
    return std::move(bvh_);
  }

 private:
  struct Range {
    std::size_t begin, end;
    std::size_t size() const { return end - begin; }
  };

  Box BoundsOf(std::size_t begin, std::size_t end) const {
    Box box;
    for (std::size_t i = begin; i < end; ++i) box.Extend(triangles_[i].box);
    return box;
  }

  // The subtree over triangles [begin, end): a leaf of up to four, or a node
  // over up to four groups, each made by splitting the largest group in two.
  std::int32_t Subtree(std::size_t begin, std::size_t end, int* depth) {
    if (end - begin <= std::size_t(kLeafSize)) {
      *depth = 1;
      return MakeLeaf(begin, end);
    }
    std::vector<Range> groups{{begin, end}};
    while (groups.size() < std::size_t(TriangleBvh::kWidth)) {
      auto largest =
          std::max_element(groups.begin(), groups.end(),
                           [](const Range& a, const Range& b) { return a.size() < b.size(); });
      if (largest->size() <= std::size_t(kLeafSize)) break;
      const Range whole = *largest;
      const std::size_t middle = Split(whole.begin, whole.end);
      *largest = {whole.begin, middle};
      groups.push_back({middle, whole.end});
    }
    const auto index = std::int32_t(bvh_.nodes.size());
    bvh_.nodes.emplace_back();
    int deepest = 0;
    for (int c = 0; c < TriangleBvh::kWidth; ++c) {
      std::int32_t child = TriangleBvh::kEmpty;
      Box box;
      if (c < int(groups.size())) {
        int child_depth = 0;
        child = Subtree(groups[std::size_t(c)].begin, groups[std::size_t(c)].end, &child_depth);
        deepest = std::max(deepest, child_depth);
        box = BoundsOf(groups[std::size_t(c)].begin, groups[std::size_t(c)].end);
      }
      TriangleBvh::Node& node = bvh_.nodes[std::size_t(index)];
      node.child[c] = child;
      for (int a = 0; a < 3; ++a) node.lower[a][c] = box.lower[a], node.upper[a][c] = box.upper[a];
    }
    *depth = deepest + 1;
    return index;
  }

  std::int32_t MakeLeaf(std::size_t begin, std::size_t end) {
    TriangleBvh::Leaves leaf{};
    leaf.count = std::int32_t(end - begin);
    for (int lane = 0; lane < TriangleBvh::kWidth; ++lane) {
      const Triangle& t = triangles_[std::min(begin + std::size_t(lane), end - 1)];
      for (int k = 0; k < 3; ++k) {
        for (int a = 0; a < 3; ++a) leaf.corner[3 * k + a][lane] = t.corner[std::size_t(k)][a];
      }
      leaf.part[lane] = t.part, leaf.triangle[lane] = t.index;
    }
    bvh_.leaves.push_back(leaf);
    return TriangleBvh::Leaf(std::int32_t(bvh_.leaves.size()) - 1);
  }

  // Splits [begin, end) in two where the surface area heuristic over binned
  // centroids is lowest (in the middle when the centroids coincide); returns
  // where the second part begins.
  std::size_t Split(std::size_t begin, std::size_t end) {
    Box centroids;
    for (std::size_t i = begin; i < end; ++i) centroids.Extend(triangles_[i].centroid);
    const Eigen::Vector3f extent = centroids.upper - centroids.lower;
    float best_cost = kInf;
    int best_axis = -1, best_bin = 0;
    for (int axis = 0; axis < 3; ++axis) {
      if (!(extent[axis] > 0.f)) continue;
      const float scale = float(kBins) / extent[axis];
      std::array<Box, kBins> boxes;
      std::array<std::size_t, kBins> counts{};
      for (std::size_t i = begin; i < end; ++i) {
        const int b = BinOf(triangles_[i].centroid[axis], centroids.lower[axis], scale);
        boxes[std::size_t(b)].Extend(triangles_[i].box);
        ++counts[std::size_t(b)];
      }
      // Costs of splitting after bin b: areas and counts from the left and the right.
      std::array<float, kBins> left_cost{};
      Box left;
      std::size_t left_count = 0;
      for (int b = 0; b < kBins - 1; ++b) {
        left.Extend(boxes[std::size_t(b)]);
        left_count += counts[std::size_t(b)];
        left_cost[std::size_t(b)] = left.HalfArea() * float(left_count);
      }
      Box right;
      std::size_t right_count = 0;
      for (int b = kBins - 1; b > 0; --b) {
        right.Extend(boxes[std::size_t(b)]);
        right_count += counts[std::size_t(b)];
        const float cost = left_cost[std::size_t(b - 1)] + right.HalfArea() * float(right_count);
        if (right_count < end - begin && cost < best_cost) {
          best_cost = cost, best_axis = axis, best_bin = b - 1;
        }
      }
    }
    if (best_axis >= 0) {
      const float scale = float(kBins) / extent[best_axis];
      const float low = centroids.lower[best_axis];
      const auto middle = std::partition(
          triangles_.begin() + std::ptrdiff_t(begin), triangles_.begin() + std::ptrdiff_t(end),
          [&](const Triangle& t) { return BinOf(t.centroid[best_axis], low, scale) <= best_bin; });
      const auto at = std::size_t(middle - triangles_.begin());
      if (at > begin && at < end) return at;
    }
    // No split by area: half the triangles each side along the longest extent.
    int axis = 0;
    for (int a = 1; a < 3; ++a) {
      if (extent[a] > extent[axis]) axis = a;
    }
    const std::size_t middle = begin + (end - begin) / 2;
    std::nth_element(
        triangles_.begin() + std::ptrdiff_t(begin), triangles_.begin() + std::ptrdiff_t(middle),
        triangles_.begin() + std::ptrdiff_t(end), [axis](const Triangle& a, const Triangle& b) {
          return a.centroid[axis] < b.centroid[axis];
        });
    return middle;
  }

  static int BinOf(float value, float low, float scale) {
    return std::clamp(int((value - low) * scale), 0, kBins - 1);
  }

  std::vector<Triangle> triangles_;
  TriangleBvh bvh_;
};

}  // namespace

TriangleBvh BuildTriangleBvh(const std::vector<TriangleSoup>& parts) {
  std::vector<Triangle> triangles;
  std::size_t total = 0;
  for (const TriangleSoup& part : parts) total += part.num_triangles;
  triangles.reserve(total);
  for (std::size_t p = 0; p < parts.size(); ++p) {
    const TriangleSoup& part = parts[p];
    for (std::size_t t = 0; t < part.num_triangles; ++t) {
      const std::uint32_t* index = part.indices + 3 * t;
      if (index[0] >= part.num_positions || index[1] >= part.num_positions ||
          index[2] >= part.num_positions) {
        continue;
      }
      Triangle triangle;
      triangle.part = std::int32_t(p), triangle.index = std::int32_t(t);
      for (int k = 0; k < 3; ++k) {
        triangle.corner[std::size_t(k)] = part.positions[index[k]];
        triangle.box.Extend(triangle.corner[std::size_t(k)]);
      }
      triangle.centroid = 0.5f * (triangle.box.lower + triangle.box.upper);
      triangles.push_back(triangle);
    }
  }
  return Builder(std::move(triangles)).Build();
}

}  // namespace sandbox::scene
