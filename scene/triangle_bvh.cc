#include "scene/triangle_bvh.h"

#include <algorithm>
#include <array>
#include <limits>

namespace sandbox::scene {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr int kBins = 16;
constexpr int kLeafSize = TriangleBvh::kWidth;

// Plain floats rather than Eigen's expressions: building is most of loading
// a level, and sanitizer builds (which inline little) build every test's world.
using Vec3 = std::array<float, 3>;

struct Box {
  Vec3 lower{kInf, kInf, kInf}, upper{-kInf, -kInf, -kInf};
  void Extend(const Box& b) {
    for (int a = 0; a < 3; ++a) {
      lower[a] = std::min(lower[a], b.lower[a]), upper[a] = std::max(upper[a], b.upper[a]);
    }
  }
  void Extend(const Vec3& p) {
    for (int a = 0; a < 3; ++a) {
      lower[a] = std::min(lower[a], p[a]), upper[a] = std::max(upper[a], p[a]);
    }
  }
  float HalfArea() const {
    if (!(lower[0] <= upper[0] && lower[1] <= upper[1] && lower[2] <= upper[2])) return 0.f;
    const float x = upper[0] - lower[0], y = upper[1] - lower[1], z = upper[2] - lower[2];
    return x * y + y * z + z * x;
  }
};

// A triangle as the builder sorts it: its box and centre; which triangle of
// which part it is.
struct Item {
  Box box;
  Vec3 centre;
  std::int32_t part, index;
};

class Builder {
 public:
  Builder(const std::vector<TriangleSoup>& parts, std::vector<Item> items)
      : parts_(parts), items_(std::move(items)) {}

  TriangleBvh Build() {
    if (!items_.empty()) {
      Box all;
      for (const Item& item : items_) all.Extend(item.box);
      bvh_.lower = Eigen::Vector3f(all.lower.data());
      bvh_.upper = Eigen::Vector3f(all.upper.data());
      bvh_.root = Subtree({0, items_.size(), all}, &bvh_.depth);
      bvh_.nodes.shrink_to_fit();
      bvh_.leaves.shrink_to_fit();
    }
    return std::move(bvh_);
  }

 private:
  struct Range {
    std::size_t begin, end;
    Box box;  // of its triangles
    std::size_t size() const { return end - begin; }
  };

  // The subtree over a range: a leaf of up to four triangles, or a node over
  // up to four groups, each made by splitting in two the group of more than
  // four triangles whose box has the largest area (as Embree's builders do:
  // the group rays meet most often).
  std::int32_t Subtree(const Range& range, int* depth) {
    if (range.size() <= std::size_t(kLeafSize)) {
      *depth = 1;
      return MakeLeaf(range.begin, range.end);
    }
    std::array<Range, TriangleBvh::kWidth> groups;
    int count = 1;
    groups[0] = range;
    while (count < TriangleBvh::kWidth) {
      int largest = -1;
      for (int g = 0; g < count; ++g) {
        if (groups[std::size_t(g)].size() <= std::size_t(kLeafSize)) continue;
        if (largest < 0 ||
            groups[std::size_t(g)].box.HalfArea() > groups[std::size_t(largest)].box.HalfArea()) {
          largest = g;
        }
      }
      if (largest < 0) break;
      Range second;
      Split(&groups[std::size_t(largest)], &second);
      groups[std::size_t(count++)] = second;
    }
    const auto index = std::int32_t(bvh_.nodes.size());
    bvh_.nodes.emplace_back();
    int deepest = 0;
    for (int c = 0; c < TriangleBvh::kWidth; ++c) {
      std::int32_t child = TriangleBvh::kEmpty;
      Box box;
      if (c < count) {
        int child_depth = 0;
        child = Subtree(groups[std::size_t(c)], &child_depth);
        deepest = std::max(deepest, child_depth);
        box = groups[std::size_t(c)].box;
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
      const Item& item = items_[std::min(begin + std::size_t(lane), end - 1)];
      const TriangleSoup& part = parts_[std::size_t(item.part)];
      const std::uint32_t* index = part.indices + 3 * std::size_t(item.index);
      for (int k = 0; k < 3; ++k) {
        for (int a = 0; a < 3; ++a) leaf.corner[3 * k + a][lane] = part.positions[index[k]][a];
      }
      leaf.part[lane] = item.part, leaf.triangle[lane] = item.index;
    }
    bvh_.leaves.push_back(leaf);
    return TriangleBvh::Leaf(std::int32_t(bvh_.leaves.size()) - 1);
  }

  // Splits *first in two where the surface area heuristic over binned
  // centres is lowest (in the middle of the longest extent when no split by
  // area parts them): *first keeps the first part, *second takes the rest.
  void Split(Range* first, Range* second) {
    const std::size_t begin = first->begin, end = first->end;
    Box centres;
    for (std::size_t i = begin; i < end; ++i) centres.Extend(items_[i].centre);
    Vec3 extent, scale;
    for (int a = 0; a < 3; ++a) extent[a] = centres.upper[a] - centres.lower[a];
    // (A denormal extent gives an infinite scale: BinOf copes.)
    for (int a = 0; a < 3; ++a) scale[a] = extent[a] > 0.f ? float(kBins) / extent[a] : 0.f;
    // The axes tried: all three for small ranges, the longest extent's for
    // large ones (where the others rarely win and binning costs most).
    int longest = 0;
    for (int a = 1; a < 3; ++a) {
      if (extent[a] > extent[longest]) longest = a;
    }
    const bool all_axes = end - begin <= 4096;
    // The axes' bins in one pass.
    std::array<std::array<Box, kBins>, 3> boxes;
    std::array<std::array<std::size_t, kBins>, 3> counts{};
    for (std::size_t i = begin; i < end; ++i) {
      const Item& item = items_[i];
      for (int a = all_axes ? 0 : longest; a < (all_axes ? 3 : longest + 1); ++a) {
        const int b = BinOf(item.centre[a], centres.lower[a], scale[a]);
        boxes[std::size_t(a)][std::size_t(b)].Extend(item.box);
        ++counts[std::size_t(a)][std::size_t(b)];
      }
    }
    float best_cost = kInf;
    int best_axis = -1, best_bin = 0;
    Box best_left, best_right;
    for (int a = 0; a < 3; ++a) {
      if (!(extent[a] > 0.f) || (!all_axes && a != longest)) continue;
      const auto& box = boxes[std::size_t(a)];
      const auto& n = counts[std::size_t(a)];
      // The left parts' boxes and costs, then the right parts' from the other end.
      std::array<Box, kBins> left_box;
      std::array<float, kBins> left_cost{};
      Box left;
      std::size_t left_count = 0;
      for (int b = 0; b < kBins - 1; ++b) {
        left.Extend(box[std::size_t(b)]);
        left_count += n[std::size_t(b)];
        left_box[std::size_t(b)] = left;
        left_cost[std::size_t(b)] = left.HalfArea() * float(left_count);
      }
      Box right;
      std::size_t right_count = 0;
      for (int b = kBins - 1; b > 0; --b) {
        right.Extend(box[std::size_t(b)]);
        right_count += n[std::size_t(b)];
        const float cost = left_cost[std::size_t(b - 1)] + right.HalfArea() * float(right_count);
        if (right_count < end - begin && right_count > 0 && cost < best_cost) {
          best_cost = cost, best_axis = a, best_bin = b - 1;
          best_left = left_box[std::size_t(b - 1)], best_right = right;
        }
      }
    }
    std::size_t middle = begin;
    if (best_axis >= 0) {
      const float low = centres.lower[best_axis], s = scale[best_axis];
      middle = std::size_t(
          std::partition(
              items_.begin() + std::ptrdiff_t(begin), items_.begin() + std::ptrdiff_t(end),
              [&](const Item& item) { return BinOf(item.centre[best_axis], low, s) <= best_bin; }) -
          items_.begin());
    }
    if (middle > begin && middle < end) {
      *first = {begin, middle, best_left};
      *second = {middle, end, best_right};
      return;
    }
    // No split by area: half the triangles each side along the longest extent.
    int axis = 0;
    for (int a = 1; a < 3; ++a) {
      if (extent[a] > extent[axis]) axis = a;
    }
    middle = begin + (end - begin) / 2;
    std::nth_element(
        items_.begin() + std::ptrdiff_t(begin), items_.begin() + std::ptrdiff_t(middle),
        items_.begin() + std::ptrdiff_t(end),
        [axis](const Item& a, const Item& b) { return a.centre[axis] < b.centre[axis]; });
    *first = {begin, middle, BoundsOf(begin, middle)};
    *second = {middle, end, BoundsOf(middle, end)};
  }

  Box BoundsOf(std::size_t begin, std::size_t end) const {
    Box box;
    for (std::size_t i = begin; i < end; ++i) box.Extend(items_[i].box);
    return box;
  }

  // Clamped as a float (one beyond int's range, e.g. infinite, has no int),
  // NaN (0 times an infinite scale) to bin 0.
  static int BinOf(float value, float low, float scale) {
    const float bin = (value - low) * scale;
    return bin > 0.f ? int(std::min(bin, float(kBins - 1))) : 0;
  }

  const std::vector<TriangleSoup>& parts_;
  std::vector<Item> items_;
  TriangleBvh bvh_;
};

}  // namespace

TriangleBvh BuildTriangleBvh(const std::vector<TriangleSoup>& parts) {
  std::vector<Item> items;
  std::size_t total = 0;
  for (const TriangleSoup& part : parts) total += part.num_triangles;
  items.reserve(total);
  for (std::size_t p = 0; p < parts.size(); ++p) {
    const TriangleSoup& part = parts[p];
    for (std::size_t t = 0; t < part.num_triangles; ++t) {
      const std::uint32_t* index = part.indices + 3 * t;
      if (index[0] >= part.num_positions || index[1] >= part.num_positions ||
          index[2] >= part.num_positions) {
        continue;
      }
      Item item;
      item.part = std::int32_t(p), item.index = std::int32_t(t);
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3f& corner = part.positions[index[k]];
        item.box.Extend(Vec3{corner.x(), corner.y(), corner.z()});
      }
      for (int a = 0; a < 3; ++a) item.centre[a] = 0.5f * (item.box.lower[a] + item.box.upper[a]);
      items.push_back(item);
    }
  }
  return Builder(parts, std::move(items)).Build();
}

}  // namespace sandbox::scene
