#include "sensors/ray_caster.h"

#include <algorithm>
#include <cmath>
#include <limits>

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

std::vector<Target> CollectTargets(const scene::CollisionWorld& world, const RayFilter& filter,
                                   const Eigen::Vector3f& batch_min,
                                   const Eigen::Vector3f& batch_max) {
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
    if ((t.aabb_min.array() > batch_max.array()).any() ||
        (t.aabb_max.array() < batch_min.array()).any()) {
      continue;  // no ray of the batch comes near it
    }
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
  const auto* index = reinterpret_cast<const std::uint32_t*>(part.indices +
                                                            std::ptrdiff_t(triangle) * part.index_stride);
  auto vertex = [&](std::uint32_t i) {
    const auto* p = reinterpret_cast<const float*>(part.vertices + std::ptrdiff_t(i) * part.vertex_stride);
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
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    wake_.wait(lock, [&] { return stop_ || generation_ != seen; });
    if (stop_) return;
    seen = generation_;
    ++busy_;
    while (next_chunk_ < chunks_) {
      const int chunk = next_chunk_++;
      lock.unlock();
      (*job_)(chunk);
      lock.lock();
    }
    if (--busy_ == 0) done_.notify_all();
  }
}

void RayCaster::RunParallel(int chunks, const std::function<void(int)>& job) {
  std::unique_lock<std::mutex> lock(mutex_);
  job_ = &job;
  chunks_ = chunks;
  next_chunk_ = 0;
  ++generation_;
  wake_.notify_all();
  // The calling thread works too.
  while (next_chunk_ < chunks_) {
    const int chunk = next_chunk_++;
    lock.unlock();
    job(chunk);
    lock.lock();
  }
  done_.wait(lock, [&] { return busy_ == 0; });
  job_ = nullptr;
}

void RayCaster::Cast(const scene::CollisionWorld& world, const RayBatch& rays,
                     const RayFilter& filter, RayHits* hits) {
  const std::size_t n = rays.size();
  hits->distance_m.resize(n);
  hits->normal_W.resize(n);
  hits->body.resize(n);
  if (n == 0) return;
  // The batch in Bullet's frame (world minus the floating origin), and its bounds.
  const Eigen::Vector3f origin_B = (rays.origin_W - world.origin()).cast<float>();
  Eigen::Vector3f batch_min = Eigen::Vector3f::Constant(std::numeric_limits<float>::max());
  Eigen::Vector3f batch_max = -batch_min;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3f a = origin_B + rays.start[i];
    const Eigen::Vector3f b = a + rays.length_m[i] * rays.direction[i];
    batch_min = batch_min.cwiseMin(a.cwiseMin(b));
    batch_max = batch_max.cwiseMax(a.cwiseMax(b));
  }
  const std::vector<Target> targets = CollectTargets(world, filter, batch_min, batch_max);

  const std::function<void(int)> job = [&](int chunk) {
    const std::size_t first = std::size_t(chunk) * kRaysPerChunk;
    const std::size_t end = std::min(n, first + kRaysPerChunk);
    for (std::size_t i = first; i < end; ++i) {
      const Eigen::Vector3f o = origin_B + rays.start[i];
      const Eigen::Vector3f& d = rays.direction[i];
      const Eigen::Vector3f inverse_d = d.unaryExpr(
          [](float x) { return 1.0f / (std::abs(x) > 1e-30f ? x : std::copysign(1e-30f, x)); });
      float t_max = rays.length_m[i];
      int body = RayHits::kNoHit;
      Eigen::Vector3f normal = Eigen::Vector3f::Zero();
      for (const Target& target : targets) {
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
