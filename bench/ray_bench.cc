// Rays per second of the sandbox's caster (sensors::RayCaster, walking Bullet's
// own BVH) and of Embree on the same triangles, same rays, same thread count,
// run in the same process; plus hit/miss mismatches and the largest hit-point
// difference between the two. Scenes: the sample level and a generated
// 1M-triangle level. Ray sets: a full face scan (15,606 rays), lidar sweeps of
// 16 x 1024 and 64 x 2048.
//
//   bench_rays [--seconds S]   (time per measurement, default 0.3)

#include <embree3/rtcore.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "bench/bench_levels.h"
#include "scene/collision_world_internal.h"
#include "scene/level.h"
#include "sensors/face_scanner.h"
#include "sensors/lidar.h"
#include "sensors/ray_caster.h"

namespace {

namespace fs = std::filesystem;
using namespace sandbox;
using Clock = std::chrono::steady_clock;

// The world's collision triangles in Embree, in Bullet's frame (world minus origin).
class EmbreeScene {
 public:
  explicit EmbreeScene(const scene::CollisionWorld& world) {
    device_ = rtcNewDevice(nullptr);
    scene_ = rtcNewScene(device_);
    for (const scene::MeshObject& object : world.internals().objects) {
      const btTransform& X = object.object->getWorldTransform();
      const IndexedMeshArray& parts = object.mesh_interface->getIndexedMeshArray();
      for (int p = 0; p < parts.size(); ++p) {
        const btIndexedMesh& part = parts[p];
        RTCGeometry geometry = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
        auto* vertices = static_cast<float*>(
            rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                    3 * sizeof(float), std::size_t(part.m_numVertices)));
        for (int v = 0; v < part.m_numVertices; ++v) {
          const auto* in = reinterpret_cast<const float*>(part.m_vertexBase +
                                                          std::ptrdiff_t(v) * part.m_vertexStride);
          const btVector3 w = X * btVector3(in[0], in[1], in[2]);
          vertices[3 * v] = w.x(), vertices[3 * v + 1] = w.y(), vertices[3 * v + 2] = w.z();
        }
        auto* indices = static_cast<unsigned*>(
            rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                    3 * sizeof(unsigned), std::size_t(part.m_numTriangles)));
        std::memcpy(indices, part.m_triangleIndexBase,
                    std::size_t(part.m_numTriangles) * 3 * sizeof(unsigned));
        rtcCommitGeometry(geometry);
        rtcAttachGeometry(scene_, geometry);
        rtcReleaseGeometry(geometry);
      }
    }
    rtcCommitScene(scene_);
  }
  ~EmbreeScene() {
    rtcReleaseScene(scene_);
    rtcReleaseDevice(device_);
  }

  // Casts rays [first, end); writes distance (or length) and whether it hit.
  void Cast(const sensors::RayBatch& rays, const Eigen::Vector3f& origin_B, std::size_t first,
            std::size_t end, std::vector<float>* distance, std::vector<char>* hit) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    for (std::size_t i = first; i < end; ++i) {
      RTCRayHit rh;
      const Eigen::Vector3f o = origin_B + rays.start[i];
      rh.ray.org_x = o.x(), rh.ray.org_y = o.y(), rh.ray.org_z = o.z();
      rh.ray.dir_x = rays.direction[i].x(), rh.ray.dir_y = rays.direction[i].y();
      rh.ray.dir_z = rays.direction[i].z();
      rh.ray.tnear = 0.0f;
      rh.ray.tfar = rays.length_m[i];
      rh.ray.mask = 0xFFFFFFFFu;
      rh.ray.flags = 0;
      rh.ray.time = 0.0f;
      rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
      rtcIntersect1(scene_, &context, &rh);
      (*hit)[i] = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
      (*distance)[i] = (*hit)[i] ? rh.ray.tfar : rays.length_m[i];
    }
  }

 private:
  RTCDevice device_;
  RTCScene scene_;
};

// Calls `work` until `seconds` have passed; returns calls per second.
template <typename Work>
double CallsPerSecond(double seconds, Work work) {
  work();  // warm up
  int calls = 0;
  const auto start = Clock::now();
  double elapsed = 0.0;
  do {
    work();
    ++calls;
    elapsed = std::chrono::duration<double>(Clock::now() - start).count();
  } while (elapsed < seconds);
  return calls / elapsed;
}

// Whether ray i, moved 1 mm sideways (two ways), still gets different answers
// from the two casters: a mismatch that is not a ray grazing an edge.
bool DisagreeWhenMoved(const scene::CollisionWorld& world, const EmbreeScene& embree,
                       const sensors::RayBatch& rays, std::size_t i) {
  const Eigen::Vector3f d = rays.direction[i];
  const Eigen::Vector3f side = d.unitOrthogonal(), up = d.cross(side);
  sensors::RayBatch moved;
  moved.origin_W = rays.origin_W;
  for (const Eigen::Vector3f& offset :
       {Eigen::Vector3f(1e-3f * (side + up)), Eigen::Vector3f(-1e-3f * (side - up))}) {
    moved.start.push_back(rays.start[i] + offset);
    moved.direction.push_back(d);
    moved.length_m.push_back(rays.length_m[i]);
  }
  sensors::RayCaster caster(1);
  sensors::RayHits ours;
  caster.Cast(world, moved, {}, &ours);
  std::vector<float> distance(2);
  std::vector<char> hit(2);
  embree.Cast(moved, (moved.origin_W - world.origin()).cast<float>(), 0, 2, &distance, &hit);
  for (int k = 0; k < 2; ++k) {
    if ((ours.body[std::size_t(k)] != sensors::RayHits::kNoHit) != bool(hit[std::size_t(k)]))
      return true;
  }
  return false;
}

void Compare(const char* level, const char* name, const scene::CollisionWorld& world,
             const EmbreeScene& embree, const sensors::RayBatch& rays, double seconds) {
  const std::size_t n = rays.size();
  const Eigen::Vector3f origin_B = (rays.origin_W - world.origin()).cast<float>();
  for (const int threads : {1, 2}) {
    sensors::RayCaster caster(threads);
    sensors::RayHits ours;
    const double ours_rate =
        n * CallsPerSecond(seconds, [&] { caster.Cast(world, rays, {}, &ours); });
    // Embree: each thread casts its share over and over until a common
    // deadline, with no synchronisation between calls (the most favourable
    // way to count for it); the rate is all rays cast over the wall time.
    std::vector<float> distance(n);
    std::vector<char> hit(n);
    embree.Cast(rays, origin_B, 0, n, &distance, &hit);  // warm up
    std::vector<double> rays_cast(std::size_t(threads), 0.0);
    const auto start = Clock::now();
    const auto deadline = start + std::chrono::duration<double>(seconds);
    {
      std::vector<std::thread> pool;
      for (int t = 0; t < threads; ++t) {
        pool.emplace_back([&, t] {
          // Interleaved chunks of 64 rays, so that each thread gets a like mix.
          do {
            for (std::size_t first = 64 * std::size_t(t); first < n;
                 first += 64 * std::size_t(threads)) {
              const std::size_t end = std::min(n, first + 64);
              embree.Cast(rays, origin_B, first, end, &distance, &hit);
              rays_cast[std::size_t(t)] += double(end - first);
            }
          } while (Clock::now() < deadline);
        });
      }
      for (std::thread& worker : pool) worker.join();
    }
    double total = 0.0;
    for (const double count : rays_cast) total += count;
    const double embree_rate = total / std::chrono::duration<double>(Clock::now() - start).count();
    embree.Cast(rays, origin_B, 0, n, &distance, &hit);  // all rays, for the comparison
    int mismatches = 0, off_edge = 0;
    double worst_mm = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const bool ours_hit = ours.body[i] != sensors::RayHits::kNoHit;
      if (ours_hit != bool(hit[i])) {
        ++mismatches;
        off_edge += DisagreeWhenMoved(world, embree, rays, i) ? 1 : 0;
      } else if (ours_hit) {
        worst_mm = std::max(worst_mm, 1e3 * std::abs(double(ours.distance_m[i]) - distance[i]));
      }
    }
    // Bullet's own btCollisionWorld::rayTest, one ray at a time (one thread only:
    // it is not thread-safe), for perspective.
    std::string ray_test = "-";
    if (threads == 1) {
      const double rate =
          n * CallsPerSecond(seconds, [&] {
            for (std::size_t i = 0; i < n; ++i) {
              const Eigen::Vector3d from = rays.origin_W + rays.start[i].cast<double>();
              world.CastRay(from,
                            from + double(rays.length_m[i]) * rays.direction[i].cast<double>());
            }
          });
      char text[32];
      std::snprintf(text, sizeof(text), "%.2f (%.2fx)", rate / 1e6, rate / embree_rate);
      ray_test = text;
    }
    std::printf("%-12s %-14s %7zu %2d %12.2f %12.2f %7.2fx %6d (%d) %11.3f %16s\n", level, name, n,
                threads, ours_rate / 1e6, embree_rate / 1e6, ours_rate / embree_rate, mismatches,
                off_edge, worst_mm, ray_test.c_str());
  }
}

void RunLevel(const char* name, const fs::path& file, const Eigen::Isometry3d& X_WS,
              double seconds) {
  const scene::Level level = scene::LoadLevel(file);
  const scene::CollisionWorld world(level);
  const EmbreeScene embree(world);
  sensors::FaceScannerConfig face_config;
  face_config.refresh = sensors::Refresh::kFull;
  const sensors::FaceScanner face(face_config);
  sensors::RayBatch face_rays;
  face_rays.origin_W = X_WS.translation();
  for (const auto& part : face.DueAt(0)) face.AppendRays(part, X_WS, &face_rays);
  Compare(name, "face scan", world, embree, face_rays, seconds);
  const sensors::Lidar lidar16(sensors::LidarConfig::Uniform(16, -15, 15, 1024, 100.0));
  Compare(name, "lidar 16x1024", world, embree, lidar16.Rays(X_WS, X_WS), seconds);
  const sensors::Lidar lidar64(sensors::LidarConfig::Uniform(64, -25, 15, 2048, 100.0));
  Compare(name, "lidar 64x2048", world, embree, lidar64.Rays(X_WS, X_WS), seconds);
}

}  // namespace

int main(int argc, char** argv) {
  double seconds = 0.3;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--seconds") == 0 && i + 1 < argc) {
      seconds = std::max(0.01, std::atof(argv[++i]));
    } else {
      std::fprintf(stderr, "usage: bench_rays [--seconds S]\n");
      return 2;
    }
  }
  std::printf("%-12s %-14s %7s %2s %12s %12s %8s %12s %11s %16s\n", "level", "rays", "count", "th",
              "ours Mray/s", "Embree Mray/s", "ratio", "mismatches", "max diff mm",
              "rayTest Mray/s");
  RunLevel("sample", fs::path(SANDBOX_SOURCE_DIR) / "assets/sample/level.toml",
           Eigen::Translation3d(20, -25, 22) * Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()),
           seconds);
  const fs::path dir = fs::temp_directory_path() / "sandbox-bench-rays";
  const fs::path million = bench::WriteMillionTriangleLevel(dir);
  RunLevel("1M-triangle", million, Eigen::Isometry3d(Eigen::Translation3d(500, 250, 8)), seconds);
  fs::remove_all(dir);
  std::printf(
      "\nsame rays, same triangles, same thread count; mismatches: hit in one, miss in "
      "the other,\n(in brackets: those that stay when the ray moves 1 mm sideways, i.e. "
      "not a ray grazing an edge);\nmax diff: largest hit distance difference where both "
      "hit\n");
  return 0;
}
