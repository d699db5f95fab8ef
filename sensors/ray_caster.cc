// Over 600 lines: the caster and its structured grid kernel (bands, their area,
// the triangles queued), which share its targets and worker pool.
#include "sensors/ray_caster.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <stdexcept>
#include <string>

#include "scene/collision_world_internal.h"
#include "sensors/lanes4.h"
#include "sensors/ray_kernels.h"
#include "sensors/walk_stack.h"

namespace sandbox::sensors {
namespace {

constexpr int kRaysPerChunk = 256;

// The widest kernel the CPU runs, or the one SANDBOX_RAY_KERNEL names (tests
// run each; the results are the same). A name the CPU cannot run, or no
// kernel's, is said on stderr and the widest taken.
const RayKernel& ChosenKernel() {
  static const RayKernel chosen = [] {
    const bool fma = __builtin_cpu_supports("fma");
    const bool avx2 = fma && __builtin_cpu_supports("avx2");
    const bool avx512 =
        avx2 && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq");
    const struct {
      const RayKernel& kernel;
      bool runs;
    } kernels[] = {{avx512::kKernel, avx512},
                   {avx2::kKernel, avx2},
                   {fma::kKernel, fma},
                   {sse2::kKernel, true}};
    const char* asked = std::getenv("SANDBOX_RAY_KERNEL");
    if (asked != nullptr && *asked != '\0') {
      bool known = false;
      for (const auto& k : kernels) {
        if (std::string(asked) != k.kernel.name) continue;
        if (k.runs) return k.kernel;
        known = true;
        std::cerr << "RayCaster::kernel(): SANDBOX_RAY_KERNEL=" << asked
                  << ": this CPU cannot run that kernel; using the widest it can\n";
      }
      if (!known) {
        std::cerr << "RayCaster::kernel(): SANDBOX_RAY_KERNEL=" << asked
                  << " is no kernel (avx512, avx2, fma, sse2); using the widest this CPU runs\n";
      }
    }
    for (const auto& k : kernels) {
      if (k.runs) return k.kernel;
    }
    return kernels[3].kernel;
  }();
  return chosen;
}

// Sizes `hits` for n rays (normals only when asked for: else they stay as
// they were, so that casts with and without them on one RayHits do not clear
// and refill megabytes in turn).
void SizeHits(std::size_t n, RayHits* hits) {
  hits->distance_m.resize(n);
  if (hits->with_normals) hits->normal_W.resize(n);
  if (hits->with_reflectivity) hits->reflectivity.resize(n);
  hits->surface.resize(n);
}

// Whether a filter lets rays see an object.
struct Visible {
  const RayFilter& filter;
  int num_actors;
  bool operator()(const Target& t) const {
    return (t.group & filter.group_mask) != 0 &&
           !(filter.ignore_actor >= 0 && t.body == filter.ignore_actor) &&
           !(filter.ignore_robot >= 0 && t.body == num_actors + filter.ignore_robot);
  }
};

// The objects of `seen` whose boxes meet the box around rays [first, end),
// into `near` (a run of one body's objects stays a run).
void TargetsNear(const RayBatch& rays, const Eigen::Vector3f& origin_B, std::size_t first,
                 std::size_t end, const std::vector<const Target*>& seen,
                 std::vector<const Target*>* near) {
  Eigen::Vector3f chunk_min = Eigen::Vector3f::Constant(std::numeric_limits<float>::max());
  Eigen::Vector3f chunk_max = -chunk_min;
  for (std::size_t r = first; r < end; ++r) {
    const Eigen::Vector3f a = origin_B + rays.start[r];
    const Eigen::Vector3f b = a + rays.length_m[r] * rays.direction[r];
    chunk_min = chunk_min.cwiseMin(a.cwiseMin(b));
    chunk_max = chunk_max.cwiseMax(a.cwiseMax(b));
  }
  near->clear();
  for (const Target* target : seen) {
    if ((target->aabb_min.array() > chunk_max.array()).any() ||
        (target->aabb_max.array() < chunk_min.array()).any()) {
      continue;
    }
    near->push_back(target);
  }
}

// The span [from, to] of columns that the triangle with corners at columns
// u[k], rows v[k] covers within `margin` rows of row y: the extent of its
// intersection with the strip [y - margin, y + margin]. False when it misses it.
inline bool RowSpan(const float u[3], const float v[3], float y, float margin, float* from,
                    float* to) {
  const float low = y - margin, high = y + margin;
  float lo = kHuge, hi = -kHuge;
  for (int i = 0; i < 3; ++i) {
    if (v[i] >= low && v[i] <= high) lo = std::min(lo, u[i]), hi = std::max(hi, u[i]);
    const int j = i == 2 ? 0 : i + 1;
    if (v[i] == v[j]) continue;
    for (const float line : {low, high}) {
      if ((line - v[i]) * (line - v[j]) > 0.0f) continue;  // the edge does not cross it
      const float t = std::clamp((line - v[i]) / (v[j] - v[i]), 0.0f, 1.0f);
      const float x = u[i] + t * (u[j] - u[i]);
      lo = std::min(lo, x), hi = std::max(hi, x);
    }
  }
  *from = lo, *to = hi;
  return lo <= hi;
}

// The least whole number >= x and >= 0 (at most `cap`), and the greatest
// <= x and <= top (-1 below 0): float to int without libm.
inline int CeilNotBelowZero(float x, int cap) {
  if (!(x > 0.0f)) return 0;
  if (x >= float(cap)) return cap;
  const int whole = int(x);
  return whole + (float(whole) < x ? 1 : 0);
}
inline int FloorNotAbove(float x, int top) {
  if (!(x >= 0.0f)) return -1;
  return x >= float(top) ? top : int(x);
}

// A band's grid coordinates of Bullet-frame points, in float: columns, rows
// and depth along the rays of p - corner; margins in metres and in cells.
struct BandFrame {
  BandFrame(const Eigen::Vector3d& corner_B, const Eigen::Vector3d& to_column,
            const Eigen::Vector3d& to_row, const Eigen::Vector3d& direction, double margin_m,
            double columns_m, double rows_m)
      : margin(float(margin_m)), margin_columns(float(columns_m)), margin_rows(float(rows_m)) {
    const Eigen::Vector3d* axes[3] = {&to_column, &to_row, &direction};
    for (int k = 0; k < 3; ++k) {
      corner[k] = _mm_set1_ps(float(corner_B[k]));
      for (int w = 0; w < 3; ++w) axis[w][k] = _mm_set1_ps(float((*axes[w])[k]));
    }
  }
  // Coordinate w (0 column, 1 row, 2 depth) of the points x, y, z (relative to corner).
  __m128 Along(int w, __m128 x, __m128 y, __m128 z) const {
    return Add(Add(Mul(x, axis[w][0]), Mul(y, axis[w][1])), Mul(z, axis[w][2]));
  }
  __m128 corner[3];
  __m128 axis[3][3];
  float margin, margin_columns, margin_rows;
};

// Up to four linear coordinates of points (a band's columns, rows and depths)
// as seen from one object's own hierarchy: over a node box [lo, hi] (the
// object's frame), coordinate w spans w0 + sum_k (p_k * a_k) over its corners;
// `margin` widens that, and it must meet [0, limit] (in a whole number, in
// `integral` lanes).
struct GridCull {
  __m128 positive[3], negative[3];  // per axis k: the weights a_k, split by sign
  __m128 w0, margin, limit, integral;

  // From per-coordinate lanes (coordinates a lane; integral: the first two).
  static GridCull Of(const float positive[3][4], const float negative[3][4], const float w0[4],
                     const float margin[4], const float limit[4], bool integral_first_two) {
    GridCull cull;
    for (int k = 0; k < 3; ++k) {
      cull.positive[k] = _mm_loadu_ps(positive[k]);
      cull.negative[k] = _mm_loadu_ps(negative[k]);
    }
    cull.w0 = _mm_loadu_ps(w0);
    cull.margin = _mm_loadu_ps(margin);
    cull.limit = _mm_loadu_ps(limit);
    cull.integral =
        _mm_castsi128_ps(integral_first_two ? _mm_setr_epi32(-1, -1, 0, 0) : _mm_setzero_si128());
    return cull;
  }
};

// An object's placement X_BL in the Bullet frame, in double.
void ObjectFrame(const Target& target, Eigen::Matrix3d* R_BL, Eigen::Vector3d* p_BL) {
  const btTransform& X_BL = target.X_BL;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) (*R_BL)(r, c) = double(X_BL.getBasis()[r][c]);
  }
  *p_BL = Eigen::Vector3d(X_BL.getOrigin().x(), X_BL.getOrigin().y(), X_BL.getOrigin().z());
}

// The cull for coordinates w = (X_BL p - origin) . axes[w] (p in the
// object's frame) that must lie in [0, limit[w]] to within margin[w]; lanes
// beyond `count` always pass. w is linear in p, and the slack covers the
// boxes' growth for the change of frame and the rounding of the sums.
GridCull CullForWide(const Target& target, const Eigen::Vector3d& origin,
                     const Eigen::Vector3d* const axes[], int count, const double limit[],
                     const double margin[], bool integral_first_two) {
  Eigen::Matrix3d R_BL;
  Eigen::Vector3d p_BL;
  ObjectFrame(target, &R_BL, &p_BL);
  const double extent =
      std::max(target.bvh->lower.cwiseAbs().maxCoeff(), target.bvh->upper.cwiseAbs().maxCoeff());
  alignas(16) float positive[3][4] = {}, negative[3][4] = {}, w0[4] = {}, slack[4] = {};
  alignas(16) float top[4] = {};
  for (int w = 0; w < count; ++w) {
    const Eigen::Vector3d a = R_BL.transpose() * *axes[w];
    w0[w] = float((p_BL - origin).dot(*axes[w]));
    top[w] = float(limit[w]);
    const double weight = a.cwiseAbs().sum();
    for (int k = 0; k < 3; ++k) {
      positive[k][w] = float(std::max(a[k], 0.0));
      negative[k][w] = float(std::min(a[k], 0.0));
    }
    const double reach = std::abs(w0[w]) + weight * extent;
    slack[w] = float(margin[w] + weight * target.box_margin + 1e-6 * reach);
  }
  return GridCull::Of(positive, negative, w0, slack, top, integral_first_two);
}

// Whether child c of one of the object's own nodes reaches a grid point in
// columns and rows and the rays' span in depth.
inline bool ChildMeetsGrid(const scene::TriangleBvh::Node& node, int c, const GridCull& cull) {
  __m128 from = cull.w0, to = cull.w0;
  for (int k = 0; k < 3; ++k) {
    const __m128 lower = _mm_set1_ps(node.lower[k][c]), upper = _mm_set1_ps(node.upper[k][c]);
    from = Add(from, Add(Mul(lower, cull.positive[k]), Mul(upper, cull.negative[k])));
    to = Add(to, Add(Mul(upper, cull.positive[k]), Mul(lower, cull.negative[k])));
  }
  const __m128 low = _mm_max_ps(Sub(from, cull.margin), _mm_setzero_ps());
  const __m128 high = _mm_min_ps(Add(to, cull.margin), cull.limit);
  const __m128 whole = _mm_cvtepi32_ps(_mm_cvttps_epi32(high));
  return _mm_movemask_ps(_mm_cmpge_ps(Select(cull.integral, whole, high), low)) == 0xF;
}

// Calls visit(corners, surface) (the Bullet frame, as Corners() places them) for
// each triangle of `target` in a leaf of its own hierarchy whose box meets the grid.
template <typename Visit>
void ForEachTriangleOverGridWide(const Target& target, const GridCull& cull, Visit&& visit) {
  const scene::TriangleBvh& bvh = *target.bvh;
  if (bvh.root == scene::TriangleBvh::kEmpty) return;
  WalkStack<std::int32_t, kStackInPlace> stack;
  stack.Push(bvh.root);
  while (!stack.empty()) {
    const std::int32_t ref = stack.Pop();
    if (ref < 0) {
      const scene::TriangleBvh::Leaves& leaf = bvh.leaves[std::size_t(-1 - ref)];
      for (int i = 0; i < leaf.count; ++i) {
        Eigen::Vector3f corners[3];
        LeafCorners(target, leaf, i, corners);
        visit(corners, target.SurfaceOf(leaf.part[i]));
      }
      continue;
    }
    const scene::TriangleBvh::Node& node = bvh.nodes[std::size_t(ref)];
    for (int c = scene::TriangleBvh::kWidth - 1; c >= 0; --c) {
      if (node.child[c] != scene::TriangleBvh::kEmpty && ChildMeetsGrid(node, c, cull)) {
        stack.Push(node.child[c]);
      }
    }
  }
}

// One band of rows of one grid block: CastGrids()'s unit of work.
struct BandJob {
  const RayGrid* grid;
  int block, row_begin, row_end;
  double cost;
};

// A band's place in the Bullet frame, in the grid's coordinates (BandFrame),
// with the box around its rays and the bounds a triangle's cells must meet.
struct BandArea {
  int rows, cols;
  BandFrame frame;
  Eigen::Vector3d corner, to_column, to_row, direction;
  double margin, margin_columns, margin_rows;
  Eigen::Vector3f box_min, box_max;
  // Per lane (column, row, depth): the margins, and the bounds of the cells'
  // columns and rows and of the rays' depths (the fourth lane: none).
  __m128 lane_margins, cap, top;
};

// The band's area. The margin covers the float rounding of the rays' origins
// and of the triangle test's tolerance.
BandArea AreaOf(const BandJob& band, const Eigen::Vector3d& world_origin) {
  const RayGrid& grid = *band.grid;
  const int rows = band.row_end - band.row_begin, cols = grid.cols;
  const float length = grid.length_m;
  // A point's column is (p - corner) . to_column, its row (p - corner) .
  // to_row, its depth along the rays (p - corner) . direction.
  const Eigen::Vector3d corner = grid.corner_W - world_origin + band.row_begin * grid.step_v_W;
  const double step_u = grid.step_u_W.norm(), step_v = grid.step_v_W.norm();
  const Eigen::Vector3d to_column = grid.step_u_W / (step_u * step_u);
  const Eigen::Vector3d to_row = grid.step_v_W / (step_v * step_v);
  const Eigen::Vector3d direction = grid.direction.cast<double>();
  const double margin =
      1e-5 * (corner.norm() + cols * step_u + rows * step_v + double(length)) + 1e-5;
  const double margin_columns = margin / step_u, margin_rows = margin / step_v;
  Eigen::AlignedBox3d box;
  for (const double u : {-margin_columns, cols - 1 + margin_columns}) {
    for (const double v : {-margin_rows, rows - 1 + margin_rows}) {
      for (const double s : {-margin, double(length) + margin}) {
        box.extend(corner + u * grid.step_u_W + v * grid.step_v_W + s * direction);
      }
    }
  }
  const BandFrame frame(corner, to_column, to_row, direction, margin, margin_columns, margin_rows);
  return {rows,
          cols,
          frame,
          corner,
          to_column,
          to_row,
          direction,
          margin,
          margin_columns,
          margin_rows,
          (box.min().array() - margin).cast<float>(),
          (box.max().array() + margin).cast<float>(),
          _mm_setr_ps(frame.margin_columns, frame.margin_rows, frame.margin, 0.0f),
          _mm_setr_ps(float(cols), float(rows), kHuge, kHuge),
          _mm_setr_ps(float(cols - 1), float(rows - 1), length, kHuge)};
}

// Queues the triangle with these corners (Bullet frame) against each ray of
// the band whose cell its shadow on the grid covers.
void QueueTriangle(const Eigen::Vector3f corners[3], int surface, const BandArea& area,
                   void (*hit_pairs)(GridBand*), GridBand* band) {
  const BandFrame& frame = area.frame;
  const int cols = area.cols;
  // Columns u, rows v and depths s of the corners (SSE, a lane each).
  const __m128 x = Sub(_mm_setr_ps(corners[0].x(), corners[1].x(), corners[2].x(), corners[2].x()),
                       frame.corner[0]);
  const __m128 y = Sub(_mm_setr_ps(corners[0].y(), corners[1].y(), corners[2].y(), corners[2].y()),
                       frame.corner[1]);
  const __m128 z = Sub(_mm_setr_ps(corners[0].z(), corners[1].z(), corners[2].z(), corners[2].z()),
                       frame.corner[2]);
  const __m128 column = frame.Along(0, x, y, z), row = frame.Along(1, x, y, z);
  // A corner a vector (column, row, depth, depth), then their least and
  // greatest coordinates, widened by the margins.
  __m128 p0 = column, p1 = row, p2 = frame.Along(2, x, y, z), p3 = p2;
  _MM_TRANSPOSE4_PS(p0, p1, p2, p3);
  const __m128 low = Sub(_mm_min_ps(_mm_min_ps(p0, p1), p2), area.lane_margins);
  const __m128 high = Add(_mm_max_ps(_mm_max_ps(p0, p1), p2), area.lane_margins);
  // The columns, rows and depths within the grid that it spans, if any:
  // from the least whole column and row at or above `span_from`, to the
  // greatest at or below `span_to`.
  const __m128 span_from = _mm_min_ps(_mm_max_ps(low, _mm_setzero_ps()), area.cap);
  const __m128 span_to = _mm_min_ps(area.top, high);
  if ((_mm_movemask_ps(_mm_cmpge_ps(span_to, span_from)) & 7) != 7) return;
  const __m128i whole = _mm_cvttps_epi32(span_from);
  const __m128i least =
      _mm_sub_epi32(whole, _mm_castps_si128(_mm_cmplt_ps(_mm_cvtepi32_ps(whole), span_from)));
  const __m128i last = _mm_cvttps_epi32(span_to);
  if (_mm_movemask_ps(_mm_castsi128_ps(_mm_cmpgt_epi32(least, last))) & 3) return;
  alignas(16) std::int32_t firsts[4], lasts[4];
  _mm_store_si128(reinterpret_cast<__m128i*>(firsts), least);
  _mm_store_si128(reinterpret_cast<__m128i*>(lasts), last);
  const int c0 = firsts[0], r0 = firsts[1], c1 = lasts[0], r1 = lasts[1];
  const float near = _mm_cvtss_f32(_mm_movehl_ps(low, low));
  auto add = [&](int r, int c) { band->Add(corners, surface, r * cols + c, near, hit_pairs); };
  if ((r1 - r0 + 1) * (c1 - c0 + 1) <= 4) {  // the box's few cells
    for (int r = r0; r <= r1; ++r) {
      for (int c = c0; c <= c1; ++c) add(r, c);
    }
    return;
  }
  // Row by row, the cells within the triangle's span.
  alignas(16) float u[4], v[4];
  _mm_store_ps(u, column), _mm_store_ps(v, row);
  for (int r = r0; r <= r1; ++r) {
    float from, to;
    if (!RowSpan(u, v, float(r), frame.margin_rows, &from, &to)) continue;
    const int first_column = std::max(c0, CeilNotBelowZero(from - frame.margin_columns, cols));
    const int last_column = std::min(c1, FloorNotAbove(to + frame.margin_columns, cols - 1));
    for (int c = first_column; c <= last_column; ++c) add(r, c);
  }
}

// The rays of one band against the targets `wanted` lets them see, by
// `hit_pairs`, into `hits`.
void CastBand(const BandJob& this_band, const RayBatch& rays, const Eigen::Vector3f& origin_B,
              const Eigen::Vector3d& world_origin, const std::vector<Target>& targets,
              const Visible& wanted, void (*hit_pairs)(GridBand*), RayHits* hits) {
  const RayGrid& grid = *this_band.grid;
  const BandArea area = AreaOf(this_band, world_origin);
  const std::size_t first = grid.first + std::size_t(this_band.row_begin) * std::size_t(grid.cols);
  const std::size_t count = std::size_t(area.rows) * std::size_t(grid.cols);
  const Eigen::Vector3f d = grid.direction;
  const float length = grid.length_m;
  thread_local GridBand band;
  band.dx = _mm_set1_ps(d.x()), band.dy = _mm_set1_ps(d.y()), band.dz = _mm_set1_ps(d.z());
  band.ox = _mm_set1_ps(origin_B.x()), band.oy = _mm_set1_ps(origin_B.y());
  band.oz = _mm_set1_ps(origin_B.z());
  band.start = rays.start.data() + first;
  const std::size_t offset = std::size_t(this_band.row_begin) * std::size_t(grid.cols);
  const bool into = grid.into.distance_m != nullptr;
  band.t_max = into ? grid.into.distance_m + offset : hits->distance_m.data() + first;
  band.surface = into ? grid.into.surface + offset : hits->surface.data() + first;
  std::fill(band.t_max, band.t_max + count, length);
  std::fill(band.surface, band.surface + count, RayHits::kNoHit);
  band.normal = !hits->with_normals ? nullptr
                : into              ? grid.into.normal_W + offset
                                    : hits->normal_W.data() + first;
  if (band.normal != nullptr) std::fill(band.normal, band.normal + count, Eigen::Vector3f::Zero());
  band.pairs.count = 0;
  for (const Target& target : targets) {
    if (!wanted(target) || (target.aabb_min.array() > area.box_max.array()).any() ||
        (target.aabb_max.array() < area.box_min.array()).any()) {
      continue;
    }
    const Eigen::Vector3d* axes[3] = {&area.to_column, &area.to_row, &area.direction};
    const double limit[3] = {double(area.cols - 1), double(area.rows - 1), double(length)};
    const double margins[3] = {area.margin_columns, area.margin_rows, area.margin};
    const GridCull cull = CullForWide(target, area.corner, axes, 3, limit, margins, true);
    ForEachTriangleOverGridWide(target, cull, [&](const Eigen::Vector3f* corners, int surface) {
      QueueTriangle(corners, surface, area, hit_pairs, &band);
    });
  }
  hit_pairs(&band);
}

// The bands of rows CastGrids() casts, each a chunk of work (each band walks
// the BVH from its root, so fewer is less work; at least four rows each).
// Without a history: four a thread over all blocks. After a call over the
// same blocks (a scanner's next scan), by what each block took then
// (`costs`): a block gets as many bands as it took threads' shares of the
// total (rounded up), and the costliest bands are taken first, so that the
// threads end together.
std::vector<BandJob> PlanBands(const std::vector<RayGrid>& grids,
                               const std::vector<BlockCost>& costs, int threads) {
  std::vector<BandJob> bands;
  bool known = threads > 1 && costs.size() == grids.size();
  double total = 0.0;
  for (std::size_t b = 0; known && b < grids.size(); ++b) {
    known = costs[b].rows == grids[b].rows;
    total += costs[b].seconds;
  }
  known = known && total > 0.0;
  const int even_split = (4 * threads + int(grids.size()) - 1) / std::max(1, int(grids.size()));
  for (std::size_t b = 0; b < grids.size(); ++b) {
    const RayGrid& grid = grids[b];
    const double cost = known ? costs[b].seconds : 1.0;
    const int split = known ? int(std::ceil(cost / (total / threads))) : even_split;
    const int rows_per_band = std::max(4, (grid.rows + split - 1) / std::max(1, split));
    for (int r = 0; r < grid.rows; r += rows_per_band) {
      const int end = std::min(grid.rows, r + rows_per_band);
      bands.push_back({&grid, int(b), r, end, cost * (end - r) / std::max(1, grid.rows)});
    }
  }
  if (known) {
    std::stable_sort(bands.begin(), bands.end(),
                     [](const BandJob& a, const BandJob& b) { return a.cost > b.cost; });
  }
  return bands;
}

// Throws std::invalid_argument unless the blocks cover the batch's n rays in
// order, each with a unit direction, a positive length and, if it has an
// `into`, every output the call writes.
void CheckGrids(const std::vector<RayGrid>& grids, std::size_t n, bool with_normals) {
  std::size_t next = 0;
  for (const RayGrid& grid : grids) {
    if (grid.first != next || grid.rows < 0 || grid.cols <= 0 ||
        grid.first + std::size_t(grid.rows) * std::size_t(grid.cols) > n) {
      throw std::invalid_argument("RayCaster::CastGrids(): the blocks do not cover the batch's " +
                                  std::to_string(n) + " rays in order");
    }
    next = grid.first + std::size_t(grid.rows) * std::size_t(grid.cols);
    if (!(std::abs(grid.direction.norm() - 1.0f) < 1e-5f) ||
        !(std::isfinite(grid.length_m) && grid.length_m > 0.0f)) {
      throw std::invalid_argument(
          "RayCaster::CastGrids(): a block's direction must be unit and its length positive");
    }
    const RayGrid::Into& into = grid.into;
    const bool any =
        into.distance_m != nullptr || into.surface != nullptr || into.normal_W != nullptr;
    if (any && (into.distance_m == nullptr || into.surface == nullptr ||
                (with_normals && into.normal_W == nullptr))) {
      throw std::invalid_argument(
          "RayCaster::CastGrids(): a block's `into` needs its distances, surfaces" +
          std::string(with_normals ? " and normals" : ""));
    }
  }
  if (next != n) {
    throw std::invalid_argument("RayCaster::CastGrids(): the blocks cover " + std::to_string(next) +
                                " of the batch's " + std::to_string(n) + " rays");
  }
}

}  // namespace

struct RayCaster::Targets {
  std::uint64_t instance{0}, revision{0};
  std::vector<Target> all;
  // The merged static objects' target and every other, or empty when the
  // world has no merged objects (scene::MergedStatic).
  std::vector<Target> merged;
  const std::vector<bool>* merged_actors{nullptr};  // by actor: in the merged target

  // The kernels that walk the objects' own hierarchies read `merged` unless
  // the filter leaves out one of its actors.
  const std::vector<Target>& For(const RayFilter& filter) const {
    const bool ignores_merged = filter.ignore_actor >= 0 && merged_actors != nullptr &&
                                std::size_t(filter.ignore_actor) < merged_actors->size() &&
                                (*merged_actors)[std::size_t(filter.ignore_actor)];
    return merged.empty() || ignores_merged ? all : merged;
  }
};

const char* RayCaster::kernel() { return ChosenKernel().name; }

void RayBatch::Resize(std::size_t n) {
  start.resize(n);
  direction.resize(n);
  length_m.resize(n);
}

RayCaster::RayCaster(int threads) : pool_(threads) {}

RayCaster::~RayCaster() = default;

void RayCaster::RunParallel(int count, const std::function<void(int)>& job) {
  pool_.RunParallel(count, job);
}

const RayCaster::Targets& RayCaster::TargetsOf(const scene::CollisionWorld& world) {
  if (!targets_) targets_ = std::make_unique<Targets>();
  if (targets_->instance != world.instance() || targets_->revision != world.revision()) {
    targets_->all = CollectTargets(world);
    targets_->merged.clear();
    const scene::CollisionWorld::Impl& w = world.internals();
    if (w.merged_static.bvh != nullptr) {
      targets_->merged.push_back(MergedTarget(world));
      for (std::size_t i = 0; i < w.objects.size(); ++i) {
        if (!w.objects[i].merged) targets_->merged.push_back(targets_->all[i]);
      }
      targets_->merged_actors = &w.merged_static.holds_actor;
    }
    targets_->instance = world.instance();
    targets_->revision = world.revision();
  }
  return *targets_;
}

void RayCaster::Cast(const scene::CollisionWorld& world, const RayBatch& rays,
                     const RayFilter& filter, RayHits* hits) {
  const std::size_t n = rays.size();
  rays_cast_ += std::int64_t(n);
  SizeHits(n, hits);
  if (n == 0) return;
  // The batch in Bullet's frame (world minus the floating origin).
  const Eigen::Vector3f origin_B = (rays.origin_W - world.origin()).cast<float>();
  const Visible wanted{filter, world.internals().num_actors};
  // The objects the rays may see; when they are a few bodies (a packet
  // tests each body's box, then each object's), every chunk takes them all.
  std::vector<const Target*> seen;
  int bodies_seen = 0;
  for (const Target& target : TargetsOf(world).For(filter)) {
    if (!wanted(target)) continue;
    bodies_seen += seen.empty() || seen.back()->body != target.body;
    seen.push_back(&target);
  }
  constexpr int kFewBodies = 8;
  const auto cast_rays = ChosenKernel().cast_rays;
  RunParallel(static_cast<int>((n + kRaysPerChunk - 1) / kRaysPerChunk), [&](int chunk) {
    const std::size_t first = std::size_t(chunk) * kRaysPerChunk;
    const std::size_t end = std::min(n, first + kRaysPerChunk);
    if (bodies_seen <= kFewBodies) {
      cast_rays(rays, origin_B, first, end, seen.data(), seen.size(), hits);
      return;
    }
    thread_local std::vector<const Target*> near;
    TargetsNear(rays, origin_B, first, end, seen, &near);
    cast_rays(rays, origin_B, first, end, near.data(), near.size(), hits);
  });
}

void RayCaster::CastGrids(const scene::CollisionWorld& world, const RayBatch& rays,
                          const std::vector<RayGrid>& grids, const RayFilter& filter,
                          RayHits* hits) {
  const std::size_t n = rays.size();
  CheckGrids(grids, n, hits->with_normals);
  if (hits->with_reflectivity) {
    throw std::invalid_argument("RayCaster::CastGrids(): with_reflectivity is Cast()'s only");
  }
  rays_cast_ += std::int64_t(n);
  const bool all_into = std::all_of(grids.begin(), grids.end(), [](const RayGrid& grid) {
    return grid.into.distance_m != nullptr;
  });
  if (!all_into) SizeHits(n, hits);
  if (n == 0) return;
  const Eigen::Vector3f origin_B = (rays.origin_W - world.origin()).cast<float>();
  const std::vector<Target>& targets = TargetsOf(world).For(filter);
  const Visible wanted{filter, world.internals().num_actors};
  const auto hit_pairs = ChosenKernel().hit_pairs;
  const std::vector<BandJob> bands = PlanBands(grids, grid_costs_, threads());
  std::vector<double> band_seconds(bands.size(), 0.0);
  RunParallel(static_cast<int>(bands.size()), [&](int b) {
    const auto started = std::chrono::steady_clock::now();
    CastBand(bands[std::size_t(b)], rays, origin_B, world.origin(), targets, wanted, hit_pairs,
             hits);
    band_seconds[std::size_t(b)] =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  });
  grid_costs_.assign(grids.size(), BlockCost{});
  for (std::size_t b = 0; b < grids.size(); ++b) grid_costs_[b].rows = grids[b].rows;
  for (std::size_t i = 0; i < bands.size(); ++i) {
    grid_costs_[std::size_t(bands[i].block)].seconds += band_seconds[i];
  }
}

}  // namespace sandbox::sensors
