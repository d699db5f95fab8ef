// Rays per second of the sandbox's caster (sensors::RayCaster, walking Bullet's
// own BVH) and of Embree on the same triangles, same rays, same thread count,
// run in the same process; plus hit/miss mismatches and the largest hit-point
// difference between the two. Scenes: the sample level and a generated
// 1M-triangle level and, where ../shared/assets is, its Quake 3 map. Ray
// sets: a full face scan (15,606 rays) cast as a bag of rays and by the
// structured kernel ("face, grid": RayCaster::CastGrids), lidar sweeps of
// 16 x 1024 and 64 x 2048; and on the sample level the
// high-resolution face scan (6 x 501 x 501 at 0.1 m) with the face scanner's whole scans a second.
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

// How Embree casts: one ray at a time (rtcIntersect1), packets of 4/8/16
// coherent rays (rtcIntersect4/8/16 with the coherent flag), or a stream of
// coherent rays (rtcIntersect1M).
enum class EmbreeMode { kOne, kPacket4, kPacket8, kPacket16, kStream };
const char* Name(EmbreeMode mode) {
  switch (mode) {
    case EmbreeMode::kOne:
      return "1";
    case EmbreeMode::kPacket4:
      return "4";
    case EmbreeMode::kPacket8:
      return "8";
    case EmbreeMode::kPacket16:
      return "16";
    case EmbreeMode::kStream:
      return "1M";
  }
  return "?";
}

// The world's collision triangles in Embree, in Bullet's frame (world minus
// origin). `robust`: RTC_SCENE_FLAG_ROBUST, Embree's watertight mode (the
// reference for hits); without it, its fastest mode (the reference for speed).
// Embree's device configuration (`--isa`: "max_isa=avx2", say); empty: its defaults.
std::string embree_config;
// The cases run (`--only`): both, or "face" or "lidar" alone.
std::string only_cases;
bool Runs(const char* cases) { return only_cases.empty() || only_cases == cases; }

class EmbreeScene {
 public:
  EmbreeScene(const scene::CollisionWorld& world, bool robust) {
    device_ = rtcNewDevice(embree_config.empty() ? nullptr : embree_config.c_str());
    scene_ = rtcNewScene(device_);
    if (robust) rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_ROBUST);
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
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  // Casts rays [first, end); writes distance (or length) and whether it hit.
  void Cast(EmbreeMode mode, const sensors::RayBatch& rays, const Eigen::Vector3f& origin_B,
            std::size_t first, std::size_t end, std::vector<float>* distance,
            std::vector<char>* hit) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    if (mode != EmbreeMode::kOne) context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    switch (mode) {
      case EmbreeMode::kOne:
        for (std::size_t i = first; i < end; ++i) {
          RTCRayHit rh = RayHit(rays, origin_B, i);
          rtcIntersect1(scene_, &context, &rh);
          Store(rays, i, rh.hit.geomID, rh.ray.tfar, distance, hit);
        }
        break;
      case EmbreeMode::kPacket4:
        CastPackets<4, RTCRayHit4>(rtcIntersect4, &context, rays, origin_B, first, end, distance,
                                   hit);
        break;
      case EmbreeMode::kPacket8:
        CastPackets<8, RTCRayHit8>(rtcIntersect8, &context, rays, origin_B, first, end, distance,
                                   hit);
        break;
      case EmbreeMode::kPacket16:
        CastPackets<16, RTCRayHit16>(rtcIntersect16, &context, rays, origin_B, first, end, distance,
                                     hit);
        break;
      case EmbreeMode::kStream: {
        std::vector<RTCRayHit> stream;
        stream.reserve(end - first);
        for (std::size_t i = first; i < end; ++i) stream.push_back(RayHit(rays, origin_B, i));
        rtcIntersect1M(scene_, &context, stream.data(), unsigned(stream.size()), sizeof(RTCRayHit));
        for (std::size_t i = first; i < end; ++i) {
          const RTCRayHit& rh = stream[i - first];
          Store(rays, i, rh.hit.geomID, rh.ray.tfar, distance, hit);
        }
        break;
      }
    }
  }

 private:
  static RTCRayHit RayHit(const sensors::RayBatch& rays, const Eigen::Vector3f& origin_B,
                          std::size_t i) {
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
    rh.ray.id = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    return rh;
  }
  static void Store(const sensors::RayBatch& rays, std::size_t i, unsigned geom_id, float tfar,
                    std::vector<float>* distance, std::vector<char>* hit) {
    (*hit)[i] = geom_id != RTC_INVALID_GEOMETRY_ID;
    (*distance)[i] = (*hit)[i] ? tfar : rays.length_m[i];
  }
  template <int N, typename RayHitN, typename Intersect>
  void CastPackets(Intersect intersect, RTCIntersectContext* context, const sensors::RayBatch& rays,
                   const Eigen::Vector3f& origin_B, std::size_t first, std::size_t end,
                   std::vector<float>* distance, std::vector<char>* hit) const {
    for (std::size_t i = first; i < end; i += N) {
      alignas(64) RayHitN packet;
      alignas(64) int valid[N];
      for (int l = 0; l < N; ++l) {
        const std::size_t r = i + std::size_t(l);
        valid[l] = r < end ? -1 : 0;
        const std::size_t k = std::min(r, end - 1);
        const Eigen::Vector3f o = origin_B + rays.start[k];
        packet.ray.org_x[l] = o.x(), packet.ray.org_y[l] = o.y(), packet.ray.org_z[l] = o.z();
        packet.ray.dir_x[l] = rays.direction[k].x(), packet.ray.dir_y[l] = rays.direction[k].y();
        packet.ray.dir_z[l] = rays.direction[k].z();
        packet.ray.tnear[l] = 0.0f;
        packet.ray.tfar[l] = rays.length_m[k];
        packet.ray.mask[l] = 0xFFFFFFFFu;
        packet.ray.flags[l] = 0;
        packet.ray.time[l] = 0.0f;
        packet.ray.id[l] = 0;
        packet.hit.geomID[l] = RTC_INVALID_GEOMETRY_ID;
        packet.hit.instID[0][l] = RTC_INVALID_GEOMETRY_ID;
      }
      intersect(valid, scene_, context, &packet);
      for (int l = 0; l < N && i + std::size_t(l) < end; ++l) {
        Store(rays, i + std::size_t(l), packet.hit.geomID[l], packet.ray.tfar[l], distance, hit);
      }
    }
  }

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
  embree.Cast(EmbreeMode::kOne, moved, (moved.origin_W - world.origin()).cast<float>(), 0, 2,
              &distance, &hit);
  for (int k = 0; k < 2; ++k) {
    if ((ours.surface[std::size_t(k)] != sensors::RayHits::kNoHit) != bool(hit[std::size_t(k)]))
      return true;
  }
  return false;
}

// Embree's rate in `mode` on `threads` threads: each thread casts its share
// over and over until a common deadline, with no synchronisation between
// calls (the most favourable way to count for it); all rays cast over the
// wall time.
double EmbreeRate(const EmbreeScene& embree, EmbreeMode mode, const sensors::RayBatch& rays,
                  const Eigen::Vector3f& origin_B, int threads, double seconds) {
  const std::size_t n = rays.size();
  std::vector<float> distance(n);
  std::vector<char> hit(n);
  embree.Cast(mode, rays, origin_B, 0, n, &distance, &hit);  // warm up
  std::vector<double> rays_cast(std::size_t(threads), 0.0);
  const auto start = Clock::now();
  const auto deadline = start + std::chrono::duration<double>(seconds);
  std::vector<std::thread> pool;
  for (int t = 0; t < threads; ++t) {
    pool.emplace_back([&, t] {
      // Interleaved chunks of 256 rays (the caster's own chunk), so that each
      // thread gets a like mix.
      std::vector<float> my_distance(n);
      std::vector<char> my_hit(n);
      do {
        for (std::size_t first = 256 * std::size_t(t); first < n;
             first += 256 * std::size_t(threads)) {
          const std::size_t end = std::min(n, first + 256);
          embree.Cast(mode, rays, origin_B, first, end, &my_distance, &my_hit);
          rays_cast[std::size_t(t)] += double(end - first);
        }
      } while (Clock::now() < deadline);
    });
  }
  for (std::thread& worker : pool) worker.join();
  double total = 0.0;
  for (const double count : rays_cast) total += count;
  return total / std::chrono::duration<double>(Clock::now() - start).count();
}

// The two Embree scenes of a level: the fastest, and the watertight reference.
struct Reference {
  const EmbreeScene& fast;
  const EmbreeScene& watertight;
};

// Hits of ours against the watertight reference: rays that hit in one and
// miss in the other, those of them that are not grazing an edge, the largest
// distance difference where both hit; the first few mismatches printed when
// `show` is set.
struct Agreement {
  int mismatches{0}, off_edge{0};
  double worst_mm{0.0};
};
Agreement Agree(const scene::CollisionWorld& world, const EmbreeScene& watertight,
                const sensors::RayBatch& rays, const sensors::RayHits& ours, int show) {
  const std::size_t n = rays.size();
  std::vector<float> distance(n);
  std::vector<char> hit(n);
  watertight.Cast(EmbreeMode::kOne, rays, (rays.origin_W - world.origin()).cast<float>(), 0, n,
                  &distance, &hit);
  Agreement agreement;
  for (std::size_t i = 0; i < n; ++i) {
    const bool ours_hit = ours.surface[i] != sensors::RayHits::kNoHit;
    const double diff_mm = 1e3 * std::abs(double(ours.distance_m[i]) - distance[i]);
    if (ours_hit != bool(hit[i]) || (ours_hit && diff_mm > 1.0)) {
      if (agreement.mismatches < show) {
        const Eigen::Vector3d o = rays.origin_W + rays.start[i].cast<double>();
        std::printf(
            "  ray %zu from (%.6g, %.6g, %.6g) along (%.6g, %.6g, %.6g): ours %s %.6g, "
            "Embree %s %.6g\n",
            i, o.x(), o.y(), o.z(), rays.direction[i].x(), rays.direction[i].y(),
            rays.direction[i].z(), ours_hit ? "hit at" : "miss", ours.distance_m[i],
            hit[i] ? "hit at" : "miss", distance[i]);
      }
    }
    if (ours_hit != bool(hit[i])) {
      ++agreement.mismatches;
      agreement.off_edge += DisagreeWhenMoved(world, watertight, rays, i) ? 1 : 0;
    } else if (ours_hit) {
      if (diff_mm > 1.0) ++agreement.mismatches;
      agreement.worst_mm = std::max(agreement.worst_mm, diff_mm);
    }
  }
  return agreement;
}

// With `grids`, ours is the structured kernel (RayCaster::CastGrids) on them.
void Compare(const char* level, const char* name, const scene::CollisionWorld& world,
             const Reference& embree, const sensors::RayBatch& rays, double seconds, int show,
             const std::vector<sensors::RayGrid>* grids = nullptr) {
  const std::size_t n = rays.size();
  const Eigen::Vector3f origin_B = (rays.origin_W - world.origin()).cast<float>();
  for (const int threads : {1, 2}) {
    sensors::RayCaster caster(threads);
    sensors::RayHits ours;
    ours.with_normals = false;  // distance and body, as the sensors ask (and Embree is asked)
    // Ours and each of Embree's modes in turns (kRounds rounds of a share of
    // `seconds` each), the best round of each: the machine's slow moments
    // fall on all of them alike, and its fast ones count for each.
    constexpr int kRounds = 3;
    const double share = seconds / kRounds;
    double ours_rate = 0.0, one_rate = 0.0, best_rate = 0.0;
    double mode_rate[4] = {0.0, 0.0, 0.0, 0.0};
    const EmbreeMode modes[4] = {EmbreeMode::kPacket4, EmbreeMode::kPacket8, EmbreeMode::kPacket16,
                                 EmbreeMode::kStream};
    for (int round = 0; round < kRounds; ++round) {
      ours_rate = std::max(ours_rate, n * CallsPerSecond(share, [&] {
                                        if (grids != nullptr) {
                                          caster.CastGrids(world, rays, *grids, {}, &ours);
                                        } else {
                                          caster.Cast(world, rays, {}, &ours);
                                        }
                                      }));
      one_rate = std::max(
          one_rate, EmbreeRate(embree.fast, EmbreeMode::kOne, rays, origin_B, threads, share));
      for (int m = 0; m < 4; ++m) {
        mode_rate[m] = std::max(mode_rate[m],
                                EmbreeRate(embree.fast, modes[m], rays, origin_B, threads, share));
      }
    }
    EmbreeMode best = EmbreeMode::kOne;
    for (int m = 0; m < 4; ++m) {
      if (mode_rate[m] > best_rate) best_rate = mode_rate[m], best = modes[m];
    }
    const Agreement agreement =
        Agree(world, embree.watertight, rays, ours, threads == 1 ? show : 0);
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
      std::snprintf(text, sizeof(text), "%.2f (%.2fx)", rate / 1e6, rate / one_rate);
      ray_test = text;
    }
    std::printf("%-12s %-14s %7zu %2d %7.2f %7.2f %6.2fx %7.2f %-3s %6.2fx %6d (%d) %8.3f %14s\n",
                level, name, n, threads, ours_rate / 1e6, one_rate / 1e6, ours_rate / one_rate,
                best_rate / 1e6, Name(best), ours_rate / best_rate, agreement.mismatches,
                agreement.off_edge, agreement.worst_mm, ray_test.c_str());
    std::fflush(stdout);
  }
}

struct FaceCase {
  double resolution_m{1.0}, half_extent_m{25.0};
};

// Face scans at X_WS; lidar sweeps at X_WL (where each beam meets a surface
// some way off, not at its start).
void RunLevel(const char* name, const fs::path& file, const Eigen::Isometry3d& X_WS,
              const FaceCase& face_case, double seconds, int show,
              const Eigen::Isometry3d* X_WL = nullptr) {
  const Eigen::Isometry3d& X_WLidar = X_WL != nullptr ? *X_WL : X_WS;
  const scene::Level level = scene::LoadLevel(file);
  const scene::CollisionWorld world(level);
  const EmbreeScene fast(world, false), watertight(world, true);
  const Reference embree{fast, watertight};
  sensors::FaceScannerConfig face_config;
  face_config.refresh = sensors::Refresh::kFull;
  face_config.resolution_m = face_case.resolution_m;
  face_config.half_extent_m = face_case.half_extent_m;
  const sensors::FaceScanner face(face_config);
  sensors::RayBatch face_rays;
  std::vector<sensors::RayGrid> face_grids;
  face.GridRays(0, X_WS, &face_rays, &face_grids);
  if (Runs("face")) {
    Compare(name, "face scan", world, embree, face_rays, seconds, show);
    Compare(name, "face, grid", world, embree, face_rays, seconds, show, &face_grids);
  }
  if (!Runs("lidar")) return;
  const sensors::Lidar lidar16(sensors::LidarConfig::Uniform(16, -15, 15, 1024, 100.0));
  const sensors::RayBatch rays16 = lidar16.Rays(X_WLidar, X_WLidar);
  Compare(name, "lidar 16x1024", world, embree, rays16, seconds, show);
  const sensors::Lidar lidar64(sensors::LidarConfig::Uniform(64, -25, 15, 2048, 100.0));
  const sensors::RayBatch rays64 = lidar64.Rays(X_WLidar, X_WLidar);
  Compare(name, "lidar 64x2048", world, embree, rays64, seconds, show);
}

// The high-resolution face scan (six faces of 501 x 501 at 0.1 m, 1.5 million
// samples) on the sample level: whole scans a second by the face scanner
// (rays, kernel, occupancy and distances) on 1 and 2 threads, taken before any
// Embree scene exists (after Embree's runs they measured up to a third lower),
// then both kernels against Embree.
void RunHighResolution(const fs::path& file, const Eigen::Isometry3d& X_WS, double seconds) {
  const scene::Level level = scene::LoadLevel(file);
  const scene::CollisionWorld world(level);
  sensors::FaceScannerConfig config;
  config.refresh = sensors::Refresh::kFull;
  config.resolution_m = 0.1;
  const sensors::FaceScanner face(config);
  sensors::RayBatch rays;
  std::vector<sensors::RayGrid> grids;
  face.GridRays(0, X_WS, &rays, &grids);
  // Whole scans on 1 and 2 threads in turns, the best of three rounds each.
  sensors::RayCaster casters[2] = {sensors::RayCaster(1), sensors::RayCaster(2)};
  double rates[2] = {0.0, 0.0};
  sensors::FaceScan scan;
  for (int round = 0; round < 3; ++round) {
    for (int t = 0; t < 2; ++t) {
      rates[t] = std::max(rates[t], CallsPerSecond(seconds / 3.0, [&] {
                            face.Scan(world, casters[t], {}, X_WS, 0, &scan);
                          }));
    }
  }
  for (const int threads : {1, 2}) {
    const double rate = rates[threads - 1];
    std::printf(
        "face scanner, 6 x 501 x 501 full scans, %d thread%s: %.1f scans/s (%.0f Msample/s)\n",
        threads, threads == 1 ? "" : "s", rate, rate * double(rays.size()) / 1e6);
  }
  const EmbreeScene fast(world, false), watertight(world, true);
  Compare("sample", "face 501^2", world, {fast, watertight}, rays, seconds, 0);
  Compare("sample", "501^2, grid", world, {fast, watertight}, rays, seconds, 0, &grids);
}

// "x,y,z[,yaw_deg]" as a pose.
bool ParsePose(const char* text, Eigen::Isometry3d* X_WS) {
  double v[4] = {0, 0, 0, 0};
  int count = 0;
  for (const char* p = text; count < 4 && *p != '\0';) {
    char* end = nullptr;
    v[count++] = std::strtod(p, &end);
    if (end == p) return false;
    p = *end == ',' ? end + 1 : end;
    if (*end != ',' && *end != '\0') return false;
  }
  if (count < 3) return false;
  *X_WS = Eigen::Translation3d(v[0], v[1], v[2]) *
          Eigen::AngleAxisd(v[3] * M_PI / 180.0, Eigen::Vector3d::UnitZ());
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  double seconds = 0.3;
  int show = 0;
  const char* level = nullptr;
  Eigen::Isometry3d X_WS = Eigen::Isometry3d::Identity();
  FaceCase face_case;
  bool posed = false;
  for (int i = 1; i < argc; ++i) {
    const bool more = i + 1 < argc;
    if (std::strcmp(argv[i], "--seconds") == 0 && more) {
      seconds = std::max(0.01, std::atof(argv[++i]));
    } else if (std::strcmp(argv[i], "--level") == 0 && more) {
      level = argv[++i];
    } else if (std::strcmp(argv[i], "--at") == 0 && more) {
      posed = ParsePose(argv[++i], &X_WS);
      if (!posed) break;
    } else if (std::strcmp(argv[i], "--resolution") == 0 && more) {
      face_case.resolution_m = std::atof(argv[++i]);
    } else if (std::strcmp(argv[i], "--half-extent") == 0 && more) {
      face_case.half_extent_m = std::atof(argv[++i]);
    } else if (std::strcmp(argv[i], "--show") == 0 && more) {
      show = std::atoi(argv[++i]);
    } else if (std::strcmp(argv[i], "--isa") == 0 && more &&
               (std::strcmp(argv[i + 1], "avx2") == 0 || std::strcmp(argv[i + 1], "sse2") == 0)) {
      // As on a CPU without AVX-512 (or without AVX): ours the widest kernel
      // for it, Embree at most that set.
      const bool avx2 = std::strcmp(argv[++i], "avx2") == 0;
      setenv("SANDBOX_RAY_KERNEL", avx2 ? "avx2" : "sse2", 1);
      embree_config = avx2 ? "max_isa=avx2" : "max_isa=sse2";
    } else if (std::strcmp(argv[i], "--only") == 0 && more &&
               (std::strcmp(argv[i + 1], "face") == 0 || std::strcmp(argv[i + 1], "lidar") == 0)) {
      only_cases = argv[++i];
    } else {
      level = nullptr, posed = false, argc = -1;
      break;
    }
  }
  if (argc < 0 || (level != nullptr) != posed) {
    std::fprintf(stderr,
                 "usage: bench_rays [--seconds S] [--level FILE --at x,y,z[,yaw_deg] "
                 "[--resolution R] [--half-extent E]] [--show N] [--isa avx2|sse2]\n"
                 "                  [--only face|lidar]\n"
                 "  without --level: the sample level and a generated 1M-triangle terrain\n"
                 "  --show N: print the first N rays that disagree with watertight Embree\n"
                 "  --isa avx2|sse2: as on a CPU with no wider set (ours and Embree's kernels)\n"
                 "  --only face|lidar: the face scans or the lidar sweeps alone\n");
    return 2;
  }
  std::printf("%s\nray kernel: %s%s%s\n", bench::Machine().c_str(), sensors::RayCaster::kernel(),
              embree_config.empty() ? "" : ", Embree ", embree_config.c_str());
  std::printf("%-12s %-14s %7s %2s %7s %7s %7s %11s %7s %12s %8s %14s\n", "level", "rays", "count",
              "th", "ours", "Embree1", "ratio", "Embree best", "ratio", "mismatches", "diff mm",
              "rayTest");
  try {
    if (level != nullptr) {
      const std::string name = fs::path(level).stem().string().substr(0, 12);
      RunLevel(name.c_str(), level, X_WS, face_case, seconds, show);
    } else {
      const fs::path sample = fs::path(SANDBOX_SOURCE_DIR) / "assets/sample/level.toml";
      const Eigen::Isometry3d over_valley(Eigen::Translation3d(20, -25, 22) *
                                          Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()));
      if (Runs("face")) RunHighResolution(sample, over_valley, std::max(seconds, 1.0));
      RunLevel("sample", sample, over_valley, face_case, seconds, show);
      const fs::path dir = fs::temp_directory_path() / "sandbox-bench-rays";
      const fs::path million = bench::WriteMillionTriangleLevel(dir);
      RunLevel("1M-triangle", million, Eigen::Isometry3d(Eigen::Translation3d(500, 250, 8)),
               face_case, seconds, show);
      fs::remove_all(dir);
      // The Quake 3 map of ../shared/assets (beside the repository on the
      // development machines), scanned from the middle of its box.
      const fs::path q3 = fs::path(SANDBOX_SHARED_ASSETS) / "q3-de4th-run1/de4th_run1.pk3";
      if (fs::exists(q3)) {
        const Eigen::Vector3d middle = scene::LoadLevel(q3).bounds_W().center();
        // The middle lies on a wall's plane (every beam from it hits at 0 m);
        // the lidar stands in the hall below, where every beam hits 7-56 m off.
        const Eigen::Isometry3d hall(Eigen::Translation3d(middle + Eigen::Vector3d(0, -10, -30)));
        RunLevel("quake3-map", q3, Eigen::Isometry3d(Eigen::Translation3d(middle)), face_case,
                 seconds, show, &hall);
      }
    }
  } catch (const std::exception& error) {
    std::fprintf(stderr, "bench_rays: %s\n", error.what());
    return 1;
  }
  std::printf(
      "\nMray/s, the best of three rounds each, taken in turns; same rays, same triangles, same "
      "thread count.\nEmbree1: rtcIntersect1; Embree best: the fastest\nof rtcIntersect4/8/16 with "
      "the coherent flag and rtcIntersect1M (its "
      "packet width or 1M shown);\nratio: ours over it. Mismatches against Embree's watertight "
      "mode (RTC_SCENE_FLAG_ROBUST): hit\nin one and miss in the other, or hit distances more "
      "than 1 mm apart (in brackets: those that stay\nwhen the ray moves 1 mm sideways, i.e. "
      "not a ray grazing an edge); diff mm: the largest hit\ndistance difference where both "
      "hit. rayTest: Bullet's btCollisionWorld::rayTest (ratio to Embree1).\n");
  return 0;
}
