#include "sensors/ray_caster.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "scene/collision_world_internal.h"

namespace sandbox::sensors {
namespace {

constexpr int kRaysPerChunk = 256;
constexpr float kBarycentricSlack = 1e-6f;  // closes cracks between neighbouring triangles

// One Bullet object as a ray sees it: where it is, its BVH nodes and triangles.
struct Target {
  int body{-1};
  Eigen::Vector3f aabb_min, aabb_max;  // in the Bullet frame (world minus origin)
  Eigen::Matrix3f R_LB;                // local from Bullet frame
  Eigen::Vector3f p_LB;
  Eigen::Matrix3f R_BL;
  const btQuantizedBvhNode* nodes{nullptr};
  Eigen::Vector3f bvh_min, quantization;  // quantized = (local - bvh_min) * quantization
  struct Part {
    const unsigned char* vertices;
    int vertex_stride;
    const unsigned char* indices;
    int index_stride;
  };
  std::vector<Part> parts;
};

Eigen::Vector3f ToEigen(const btVector3& v) { return {float(v.x()), float(v.y()), float(v.z())}; }

std::vector<Target> CollectTargets(const scene::CollisionWorld& world, const RayFilter& filter) {
  const scene::CollisionWorld::Impl& w = world.internals();
  std::vector<Target> targets;
  for (const scene::MeshObject& object : w.objects) {
    const btCollisionObject& o = *object.object;
    const int body = o.getUserIndex();
    const int group = o.getBroadphaseHandle()->m_collisionFilterGroup;
    if ((static_cast<std::uint32_t>(group) & filter.group_mask) == 0) continue;
    if (body == filter.ignore_actor && filter.ignore_actor >= 0) continue;
    if (filter.ignore_robot >= 0 && body == w.num_actors + filter.ignore_robot) continue;
    Target t;
    t.body = body;
    t.aabb_min = ToEigen(o.getBroadphaseHandle()->m_aabbMin);
    t.aabb_max = ToEigen(o.getBroadphaseHandle()->m_aabbMax);
    const btTransform& X = o.getWorldTransform();
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) t.R_BL(r, c) = float(X.getBasis()[r][c]);
    }
    t.R_LB = t.R_BL.transpose();
    t.p_LB = -(t.R_LB * ToEigen(X.getOrigin()));
    btQuantizedBvh* bvh = object.shape->getOptimizedBvh();
    t.nodes = &bvh->getQuantizedNodeArray()[0];
    // Quantization from the two ends of the range: one quantum apart would
    // lose the scale to float rounding.
    const unsigned short zero[3] = {0, 0, 0}, top[3] = {65534, 65534, 65534};
    t.bvh_min = ToEigen(bvh->unQuantize(zero));
    t.quantization = 65534.0f * (ToEigen(bvh->unQuantize(top)) - t.bvh_min).cwiseInverse();
    const IndexedMeshArray& meshes = object.mesh_interface->getIndexedMeshArray();
    for (int m = 0; m < meshes.size(); ++m) {
      t.parts.push_back({meshes[m].m_vertexBase, meshes[m].m_vertexStride,
                         meshes[m].m_triangleIndexBase, meshes[m].m_triangleIndexStride});
    }
    targets.push_back(std::move(t));
  }
  return targets;
}

// Entry distance of a ray into a quantized box (grown by one quantum against
// rounding), or +inf when it misses or enters beyond t_max.
inline float EnterBox(const btQuantizedBvhNode& node, const Eigen::Vector3f& qo,
                      const Eigen::Vector3f& inverse, float t_max) {
  float t_enter = 0.0f, t_exit = t_max;
  for (int k = 0; k < 3; ++k) {
    const float t1 = (float(node.m_quantizedAabbMin[k]) - 1.0f - qo[k]) * inverse[k];
    const float t2 = (float(node.m_quantizedAabbMax[k]) + 1.0f - qo[k]) * inverse[k];
    t_enter = std::max(t_enter, std::min(t1, t2));
    t_exit = std::min(t_exit, std::max(t1, t2));
  }
  return t_enter <= t_exit ? t_enter : std::numeric_limits<float>::infinity();
}

// Möller-Trumbore, both faces; updates t_max and the normal on a closer hit.
inline bool HitTriangle(const Target& target, int part_id, int triangle, const Eigen::Vector3f& o,
                        const Eigen::Vector3f& d, float* t_max, Eigen::Vector3f* normal) {
  const Target::Part& part = target.parts[static_cast<std::size_t>(part_id)];
  const auto* index = reinterpret_cast<const std::uint32_t*>(
      part.indices + std::ptrdiff_t(triangle) * part.index_stride);
  auto vertex = [&](std::uint32_t i) {
    const auto* p =
        reinterpret_cast<const float*>(part.vertices + std::ptrdiff_t(i) * part.vertex_stride);
    return Eigen::Vector3f(p[0], p[1], p[2]);
  };
  const Eigen::Vector3f v0 = vertex(index[0]);
  const Eigen::Vector3f e1 = vertex(index[1]) - v0, e2 = vertex(index[2]) - v0;
  const Eigen::Vector3f p = d.cross(e2);
  const float det = e1.dot(p);
  if (std::abs(det) < 1e-20f) return false;
  const float inverse = 1.0f / det;
  const Eigen::Vector3f s = o - v0;
  const float u = s.dot(p) * inverse;
  if (u < -kBarycentricSlack || u > 1.0f + kBarycentricSlack) return false;
  const Eigen::Vector3f q = s.cross(e1);
  const float v = d.dot(q) * inverse;
  if (v < -kBarycentricSlack || u + v > 1.0f + kBarycentricSlack) return false;
  const float t = e2.dot(q) * inverse;
  if (t < 0.0f || t >= *t_max) return false;
  *t_max = t;
  *normal = e1.cross(e2);
  return true;
}

// Nearest-first walk of one object's quantized BVH, shortening the ray at
// every hit. Returns true when the object holds a hit closer than *t_max.
bool WalkTarget(const Target& target, const Eigen::Vector3f& o_B, const Eigen::Vector3f& d_B,
                float* t_max, Eigen::Vector3f* normal_B) {
  const Eigen::Vector3f o = target.R_LB * o_B + target.p_LB;
  const Eigen::Vector3f d = target.R_LB * d_B;
  const Eigen::Vector3f qo = (o - target.bvh_min).cwiseProduct(target.quantization);
  Eigen::Vector3f inverse;
  for (int k = 0; k < 3; ++k) {
    const float qd = d[k] * target.quantization[k];
    inverse[k] = 1.0f / (std::abs(qd) > 1e-30f ? qd : std::copysign(1e-30f, qd));
  }
  struct Entry {
    int node;
    float t_enter;
  };
  Entry stack[128];
  int top = 0;
  bool hit = false;
  Eigen::Vector3f normal_L;
  const btQuantizedBvhNode* nodes = target.nodes;
  if (EnterBox(nodes[0], qo, inverse, *t_max) <= *t_max) stack[top++] = {0, 0.0f};
  while (top > 0) {
    const Entry entry = stack[--top];
    if (entry.t_enter > *t_max) continue;
    const btQuantizedBvhNode& node = nodes[entry.node];
    if (node.isLeafNode()) {
      const int packed = node.m_escapeIndexOrTriangleIndex;
      hit |= HitTriangle(target, packed >> 21, packed & ((1 << 21) - 1), o, d, t_max, &normal_L);
      continue;
    }
    const int left = entry.node + 1;
    const int right = left + (nodes[left].isLeafNode() ? 1 : nodes[left].getEscapeIndex());
    const float t_left = EnterBox(nodes[left], qo, inverse, *t_max);
    const float t_right = EnterBox(nodes[right], qo, inverse, *t_max);
    // Push the far child first so that the near one is walked first.
    const bool left_first = t_left <= t_right;
    const Entry near_child = left_first ? Entry{left, t_left} : Entry{right, t_right};
    const Entry far_child = left_first ? Entry{right, t_right} : Entry{left, t_left};
    if (std::isfinite(far_child.t_enter) && top < 127) stack[top++] = far_child;
    if (std::isfinite(near_child.t_enter) && top < 127) stack[top++] = near_child;
  }
  if (hit) *normal_B = target.R_BL * normal_L;
  return hit;
}

// Whether the ray enters an axis-aligned box before t_max.
inline bool RayMeetsBox(const Eigen::Vector3f& o, const Eigen::Vector3f& inverse_d,
                        const Eigen::Vector3f& lo, const Eigen::Vector3f& hi, float t_max) {
  float t_enter = 0.0f, t_exit = t_max;
  for (int k = 0; k < 3; ++k) {
    const float t1 = (lo[k] - o[k]) * inverse_d[k], t2 = (hi[k] - o[k]) * inverse_d[k];
    t_enter = std::max(t_enter, std::min(t1, t2));
    t_exit = std::min(t_exit, std::max(t1, t2));
  }
  return t_enter <= t_exit;
}

#if defined(__SSE2__)
// Four rays walked together (SSE2): a node is visited when any of them
// enters it, and every test is done for the four at once. Rays of a sensor
// are coherent (neighbouring beams or grid points), so the four mostly agree.
struct Packet {
  __m128 ox, oy, oz, dx, dy, dz;  // Bullet frame
  __m128 t_max;                   // per lane
  __m128 active;                  // all bits set in lanes that hold a ray
  int body[4];
  Eigen::Vector3f normal[4];  // in the Bullet frame, unnormalised
};

inline __m128 AwayFromZero(__m128 x) {
  const __m128 sign = _mm_and_ps(x, _mm_set1_ps(-0.0f));
  const __m128 magnitude = _mm_max_ps(_mm_andnot_ps(_mm_set1_ps(-0.0f), x), _mm_set1_ps(1e-30f));
  return _mm_or_ps(magnitude, sign);
}

inline __m128 Mul(__m128 a, __m128 b) { return _mm_mul_ps(a, b); }
inline __m128 Add(__m128 a, __m128 b) { return _mm_add_ps(a, b); }
inline __m128 Sub(__m128 a, __m128 b) { return _mm_sub_ps(a, b); }

// Lanes whose rays enter the box [lo, hi] (quantized space) before their t_max.
inline __m128 EnterBox4(const btQuantizedBvhNode& node, const __m128 qo[3], const __m128 inverse[3],
                        __m128 t_max) {
  __m128 t_enter = _mm_setzero_ps(), t_exit = t_max;
  for (int k = 0; k < 3; ++k) {
    const __m128 t1 =
        Mul(Sub(_mm_set1_ps(float(node.m_quantizedAabbMin[k]) - 1.0f), qo[k]), inverse[k]);
    const __m128 t2 =
        Mul(Sub(_mm_set1_ps(float(node.m_quantizedAabbMax[k]) + 1.0f), qo[k]), inverse[k]);
    t_enter = _mm_max_ps(t_enter, _mm_min_ps(t1, t2));
    t_exit = _mm_min_ps(t_exit, _mm_max_ps(t1, t2));
  }
  return _mm_cmple_ps(t_enter, t_exit);
}

// Möller-Trumbore for four rays against one triangle; updates the lanes it hits.
inline void HitTriangle4(const Target& target, int part_id, int triangle, const __m128 o[3],
                         const __m128 d[3], __m128 lanes, Packet* packet, __m128* t_max) {
  const Target::Part& part = target.parts[static_cast<std::size_t>(part_id)];
  const auto* index = reinterpret_cast<const std::uint32_t*>(
      part.indices + std::ptrdiff_t(triangle) * part.index_stride);
  auto vertex = [&](std::uint32_t i) {
    return reinterpret_cast<const float*>(part.vertices + std::ptrdiff_t(i) * part.vertex_stride);
  };
  const float* a = vertex(index[0]);
  const float* b = vertex(index[1]);
  const float* c = vertex(index[2]);
  const float e1s[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const float e2s[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const __m128 e1[3] = {_mm_set1_ps(e1s[0]), _mm_set1_ps(e1s[1]), _mm_set1_ps(e1s[2])};
  const __m128 e2[3] = {_mm_set1_ps(e2s[0]), _mm_set1_ps(e2s[1]), _mm_set1_ps(e2s[2])};
  // p = d x e2, det = e1 . p
  const __m128 px = Sub(Mul(d[1], e2[2]), Mul(d[2], e2[1]));
  const __m128 py = Sub(Mul(d[2], e2[0]), Mul(d[0], e2[2]));
  const __m128 pz = Sub(Mul(d[0], e2[1]), Mul(d[1], e2[0]));
  const __m128 det = Add(Add(Mul(e1[0], px), Mul(e1[1], py)), Mul(e1[2], pz));
  const __m128 inverse = _mm_div_ps(_mm_set1_ps(1.0f), det);
  const __m128 sx = Sub(o[0], _mm_set1_ps(a[0])), sy = Sub(o[1], _mm_set1_ps(a[1])),
               sz = Sub(o[2], _mm_set1_ps(a[2]));
  const __m128 u = Mul(Add(Add(Mul(sx, px), Mul(sy, py)), Mul(sz, pz)), inverse);
  // q = s x e1
  const __m128 qx = Sub(Mul(sy, e1[2]), Mul(sz, e1[1]));
  const __m128 qy = Sub(Mul(sz, e1[0]), Mul(sx, e1[2]));
  const __m128 qz = Sub(Mul(sx, e1[1]), Mul(sy, e1[0]));
  const __m128 v = Mul(Add(Add(Mul(d[0], qx), Mul(d[1], qy)), Mul(d[2], qz)), inverse);
  const __m128 t = Mul(Add(Add(Mul(e2[0], qx), Mul(e2[1], qy)), Mul(e2[2], qz)), inverse);
  const __m128 slack = _mm_set1_ps(kBarycentricSlack);
  const __m128 one = _mm_set1_ps(1.0f + kBarycentricSlack);
  __m128 hit =
      _mm_and_ps(lanes, _mm_cmpgt_ps(_mm_andnot_ps(_mm_set1_ps(-0.0f), det), _mm_set1_ps(1e-20f)));
  hit = _mm_and_ps(hit, _mm_cmpge_ps(u, _mm_sub_ps(_mm_setzero_ps(), slack)));
  hit = _mm_and_ps(hit, _mm_cmple_ps(u, one));
  hit = _mm_and_ps(hit, _mm_cmpge_ps(v, _mm_sub_ps(_mm_setzero_ps(), slack)));
  hit = _mm_and_ps(hit, _mm_cmple_ps(Add(u, v), one));
  hit = _mm_and_ps(hit, _mm_cmpge_ps(t, _mm_setzero_ps()));
  hit = _mm_and_ps(hit, _mm_cmplt_ps(t, *t_max));
  const int mask = _mm_movemask_ps(hit);
  if (mask == 0) return;
  *t_max = _mm_or_ps(_mm_and_ps(hit, t), _mm_andnot_ps(hit, *t_max));
  const Eigen::Vector3f normal_L =
      Eigen::Vector3f(e1s[0], e1s[1], e1s[2]).cross(Eigen::Vector3f(e2s[0], e2s[1], e2s[2]));
  const Eigen::Vector3f normal_B = target.R_BL * normal_L;
  for (int lane = 0; lane < 4; ++lane) {
    if (mask & (1 << lane)) {
      packet->body[lane] = target.body;
      packet->normal[lane] = normal_B;
    }
  }
}

// The packet's walk of one object's quantized BVH, nearest child first (by
// the first lane's direction), shortening the lanes' rays at every hit.
void WalkTarget4(const Target& target, Packet* packet) {
  const Eigen::Matrix3f& R = target.R_LB;
  auto transform = [&](int row, __m128 x, __m128 y, __m128 z, float offset) {
    return Add(Add(Mul(_mm_set1_ps(R(row, 0)), x), Mul(_mm_set1_ps(R(row, 1)), y)),
               Add(Mul(_mm_set1_ps(R(row, 2)), z), _mm_set1_ps(offset)));
  };
  const __m128 o[3] = {transform(0, packet->ox, packet->oy, packet->oz, target.p_LB[0]),
                       transform(1, packet->ox, packet->oy, packet->oz, target.p_LB[1]),
                       transform(2, packet->ox, packet->oy, packet->oz, target.p_LB[2])};
  const __m128 d[3] = {transform(0, packet->dx, packet->dy, packet->dz, 0.0f),
                       transform(1, packet->dx, packet->dy, packet->dz, 0.0f),
                       transform(2, packet->dx, packet->dy, packet->dz, 0.0f)};
  __m128 qo[3], inverse[3];
  float lane0_qd[3];
  int axis = 0;  // the first lane's dominant axis orders the children
  for (int k = 0; k < 3; ++k) {
    const __m128 quantization = _mm_set1_ps(target.quantization[k]);
    qo[k] = Mul(Sub(o[k], _mm_set1_ps(target.bvh_min[k])), quantization);
    const __m128 qd = AwayFromZero(Mul(d[k], quantization));
    inverse[k] = _mm_div_ps(_mm_set1_ps(1.0f), qd);
    lane0_qd[k] = _mm_cvtss_f32(qd);
  }
  for (int k = 1; k < 3; ++k) {
    if (std::abs(lane0_qd[k]) > std::abs(lane0_qd[axis])) axis = k;
  }
  const bool positive = lane0_qd[axis] > 0.0f;
  __m128 t_max = packet->t_max;
  const btQuantizedBvhNode* nodes = target.nodes;
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const int index = stack[--top];
    const btQuantizedBvhNode& node = nodes[index];
    const __m128 lanes = _mm_and_ps(packet->active, EnterBox4(node, qo, inverse, t_max));
    if (_mm_movemask_ps(lanes) == 0) continue;
    if (node.isLeafNode()) {
      const int packed = node.m_escapeIndexOrTriangleIndex;
      HitTriangle4(target, packed >> 21, packed & ((1 << 21) - 1), o, d, lanes, packet, &t_max);
      continue;
    }
    const int left = index + 1;
    const int right = left + (nodes[left].isLeafNode() ? 1 : nodes[left].getEscapeIndex());
    // The child whose box starts further along the dominant axis is walked second.
    const bool right_is_further =
        (nodes[right].m_quantizedAabbMin[axis] >= nodes[left].m_quantizedAabbMin[axis]) == positive;
    if (top > 125) continue;  // deeper than any tree Bullet builds
    if (right_is_further) {
      stack[top++] = right;
      stack[top++] = left;
    } else {
      stack[top++] = left;
      stack[top++] = right;
    }
  }
  packet->t_max = t_max;
}

// Lanes whose rays enter an axis-aligned box (Bullet frame) before their t_max.
inline int PacketMeetsBox(const Packet& packet, const __m128 inverse[3], const Target& target) {
  const __m128 o[3] = {packet.ox, packet.oy, packet.oz};
  __m128 t_enter = _mm_setzero_ps(), t_exit = packet.t_max;
  for (int k = 0; k < 3; ++k) {
    const __m128 t1 = Mul(Sub(_mm_set1_ps(target.aabb_min[k]), o[k]), inverse[k]);
    const __m128 t2 = Mul(Sub(_mm_set1_ps(target.aabb_max[k]), o[k]), inverse[k]);
    t_enter = _mm_max_ps(t_enter, _mm_min_ps(t1, t2));
    t_exit = _mm_min_ps(t_exit, _mm_max_ps(t1, t2));
  }
  return _mm_movemask_ps(_mm_and_ps(packet.active, _mm_cmple_ps(t_enter, t_exit)));
}
#endif

}  // namespace

void RayBatch::Resize(std::size_t n) {
  start.resize(n);
  direction.resize(n);
  length_m.resize(n);
}

RayCaster::RayCaster(int threads) {
  if (threads <= 0) threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  for (int i = 1; i < threads; ++i) workers_.emplace_back([this] { WorkerLoop(); });
}

RayCaster::~RayCaster() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  for (std::thread& worker : workers_) worker.join();
}

void RayCaster::WorkerLoop() {
  std::uint64_t seen = 0;
  while (true) {
    // Wait for a new job: spin briefly (back-to-back casts, a free-running
    // loop), then sleep, so that a 100 Hz loop does not keep a core busy.
    const auto spin_until = std::chrono::steady_clock::now() + std::chrono::microseconds(200);
    while (generation_.load(std::memory_order_acquire) == seen &&
           !stop_.load(std::memory_order_relaxed) &&
           std::chrono::steady_clock::now() < spin_until) {
      std::this_thread::yield();
    }
    if (generation_.load(std::memory_order_acquire) == seen) {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [&] { return stop_ || generation_.load() != seen; });
    }
    if (stop_) return;
    seen = generation_.load(std::memory_order_acquire);
    for (int chunk = next_chunk_.fetch_add(1); chunk < chunks_; chunk = next_chunk_.fetch_add(1)) {
      (*job_)(chunk);
      unfinished_.fetch_sub(1, std::memory_order_release);
    }
  }
}

void RayCaster::RunParallel(int chunks, const std::function<void(int)>& job) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    job_ = &job;
    chunks_ = chunks;
    unfinished_.store(chunks);
    next_chunk_.store(0);
    generation_.fetch_add(1, std::memory_order_release);
  }
  wake_.notify_all();
  // The calling thread works too, then waits for the chunks others took.
  for (int chunk = next_chunk_.fetch_add(1); chunk < chunks; chunk = next_chunk_.fetch_add(1)) {
    job(chunk);
    unfinished_.fetch_sub(1, std::memory_order_release);
  }
  while (unfinished_.load(std::memory_order_acquire) > 0) std::this_thread::yield();
}

void RayCaster::Cast(const scene::CollisionWorld& world, const RayBatch& rays,
                     const RayFilter& filter, RayHits* hits) {
  const std::size_t n = rays.size();
  rays_cast_ += std::int64_t(n);
  hits->distance_m.resize(n);
  hits->normal_W.resize(n);
  hits->body.resize(n);
  if (n == 0) return;
  // The batch in Bullet's frame (world minus the floating origin).
  const Eigen::Vector3f origin_B = (rays.origin_W - world.origin()).cast<float>();
  const std::vector<Target> all_targets = CollectTargets(world, filter);

  const std::function<void(int)> job = [&](int chunk) {
    const std::size_t first = std::size_t(chunk) * kRaysPerChunk;
    const std::size_t end = std::min(n, first + kRaysPerChunk);
    // Only the objects whose bounds meet this chunk's rays' bounds.
    Eigen::Vector3f chunk_min = Eigen::Vector3f::Constant(std::numeric_limits<float>::max());
    Eigen::Vector3f chunk_max = -chunk_min;
    for (std::size_t r = first; r < end; ++r) {
      const Eigen::Vector3f a = origin_B + rays.start[r];
      const Eigen::Vector3f b = a + rays.length_m[r] * rays.direction[r];
      chunk_min = chunk_min.cwiseMin(a.cwiseMin(b));
      chunk_max = chunk_max.cwiseMax(a.cwiseMax(b));
    }
    const Target* targets_here[64];
    std::vector<const Target*> many;
    std::size_t count = 0;
    for (const Target& target : all_targets) {
      if ((target.aabb_min.array() > chunk_max.array()).any() ||
          (target.aabb_max.array() < chunk_min.array()).any()) {
        continue;
      }
      if (count < 64) {
        targets_here[count++] = &target;
      } else {
        if (many.empty()) many.assign(targets_here, targets_here + 64);
        many.push_back(&target);
      }
    }
    const Target* const* targets = many.empty() ? targets_here : many.data();
    const std::size_t num_targets = many.empty() ? count : many.size();
    std::size_t i = first;
#if defined(__SSE2__)
    // Four rays at a time; the last packet of the batch may be partly empty.
    for (; i < end; i += 4) {
      alignas(16) float lane[7][4];
      alignas(16) std::uint32_t active[4];
      for (int l = 0; l < 4; ++l) {
        const std::size_t r = std::min(i + std::size_t(l), end - 1);
        const Eigen::Vector3f o = origin_B + rays.start[r];
        lane[0][l] = o.x(), lane[1][l] = o.y(), lane[2][l] = o.z();
        lane[3][l] = rays.direction[r].x(), lane[4][l] = rays.direction[r].y();
        lane[5][l] = rays.direction[r].z(), lane[6][l] = rays.length_m[r];
        active[l] = i + std::size_t(l) < end ? 0xFFFFFFFFu : 0u;
      }
      Packet packet;
      packet.ox = _mm_load_ps(lane[0]), packet.oy = _mm_load_ps(lane[1]);
      packet.oz = _mm_load_ps(lane[2]), packet.dx = _mm_load_ps(lane[3]);
      packet.dy = _mm_load_ps(lane[4]), packet.dz = _mm_load_ps(lane[5]);
      packet.t_max = _mm_load_ps(lane[6]);
      packet.active = _mm_load_ps(reinterpret_cast<const float*>(active));
      const __m128 inverse[3] = {_mm_div_ps(_mm_set1_ps(1.0f), AwayFromZero(packet.dx)),
                                 _mm_div_ps(_mm_set1_ps(1.0f), AwayFromZero(packet.dy)),
                                 _mm_div_ps(_mm_set1_ps(1.0f), AwayFromZero(packet.dz))};
      for (int l = 0; l < 4; ++l) packet.body[l] = RayHits::kNoHit;
      for (std::size_t t = 0; t < num_targets; ++t) {
        if (PacketMeetsBox(packet, inverse, *targets[t]) != 0) WalkTarget4(*targets[t], &packet);
      }
      alignas(16) float t_max[4];
      _mm_store_ps(t_max, packet.t_max);
      for (int l = 0; l < 4 && i + std::size_t(l) < end; ++l) {
        const std::size_t r = i + std::size_t(l);
        hits->distance_m[r] = t_max[l];
        hits->body[r] = packet.body[l];
        if (packet.body[l] != RayHits::kNoHit) {
          const Eigen::Vector3f normal = packet.normal[l].normalized();
          hits->normal_W[r] = normal.dot(rays.direction[r]) > 0.0f ? -normal : normal;
        } else {
          hits->normal_W[r].setZero();
        }
      }
    }
#endif
    for (; i < end; ++i) {
      const Eigen::Vector3f o = origin_B + rays.start[i];
      const Eigen::Vector3f& d = rays.direction[i];
      const Eigen::Vector3f inverse_d = d.unaryExpr(
          [](float x) { return 1.0f / (std::abs(x) > 1e-30f ? x : std::copysign(1e-30f, x)); });
      float t_max = rays.length_m[i];
      int body = RayHits::kNoHit;
      Eigen::Vector3f normal = Eigen::Vector3f::Zero();
      for (std::size_t t = 0; t < num_targets; ++t) {
        const Target& target = *targets[t];
        if (!RayMeetsBox(o, inverse_d, target.aabb_min, target.aabb_max, t_max)) continue;
        if (WalkTarget(target, o, d, &t_max, &normal)) body = target.body;
      }
      hits->distance_m[i] = t_max;
      hits->body[i] = body;
      if (body != RayHits::kNoHit) {
        normal.normalize();
        hits->normal_W[i] = normal.dot(d) > 0.0f ? -normal : normal;
      } else {
        hits->normal_W[i].setZero();
      }
    }
  };
  RunParallel(static_cast<int>((n + kRaysPerChunk - 1) / kRaysPerChunk), job);
}

}  // namespace sandbox::sensors
