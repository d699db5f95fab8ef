#include "sensors/face_scanner.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace sandbox::sensors {
namespace {

std::string Format(double value) {
  std::ostringstream out;
  out.precision(12);
  out << value;
  return out.str();
}

}  // namespace

void FaceGridAxes(int face, Eigen::Vector3d* u, Eigen::Vector3d* v) {
  if (face < 2) {
    *u = Eigen::Vector3d::UnitY(), *v = Eigen::Vector3d::UnitZ();
  } else if (face < 4) {
    *u = Eigen::Vector3d::UnitX(), *v = Eigen::Vector3d::UnitZ();
  } else {
    *u = Eigen::Vector3d::UnitX(), *v = Eigen::Vector3d::UnitY();
  }
}

Eigen::Vector3d FaceAxis(int face) {
  Eigen::Vector3d axis = Eigen::Vector3d::Zero();
  axis[face / 2] = face % 2 == 0 ? 1.0 : -1.0;
  return axis;
}

void FaceScannerConfig::ValidateOrThrow() const {
  if (!(std::isfinite(resolution_m) && resolution_m > 0.0)) {
    throw std::invalid_argument("resolution_m must be positive, got " + Format(resolution_m));
  }
  if (!(std::isfinite(half_extent_m) && half_extent_m > 0.0)) {
    throw std::invalid_argument("half_extent_m must be positive, got " + Format(half_extent_m));
  }
  if (!(sample_budget >= 6.0 && sample_budget <= kMaxSampleBudget)) {
    throw std::invalid_argument("sample_budget must be 6 to " + Format(kMaxSampleBudget) +
                                ", got " + Format(sample_budget));
  }
  const double steps = 2.0 * half_extent_m / resolution_m;
  const double samples = 6.0 * (steps + 1.0) * (steps + 1.0);
  if (samples > sample_budget) {
    const std::string n = Format(std::floor(steps + 1.5));
    throw std::invalid_argument("half_extent_m " + Format(half_extent_m) + " at resolution_m " +
                                Format(resolution_m) + " makes 6 x " + n + " x " + n + " = " +
                                Format(std::floor(samples + 0.5)) +
                                " samples a scan, over sample_budget " + Format(sample_budget));
  }
  if (std::abs(steps - std::round(steps)) > 1e-6) {
    throw std::invalid_argument("half_extent_m (" + Format(half_extent_m) +
                                ") must be a whole number of resolution_m / 2 (" +
                                Format(resolution_m) + ")");
  }
}

int FaceScannerConfig::points_per_side() const {
  return static_cast<int>(std::lround(2.0 * half_extent_m / resolution_m)) + 1;
}

FaceScanner::FaceScanner(const FaceScannerConfig& config) : config_(config) {
  config_.ValidateOrThrow();
  n_ = config_.points_per_side();
}

FaceScan FaceScanner::EmptyScan() const {
  FaceScan scan;
  scan.n = n_;
  scan.resolution_m = config_.resolution_m;
  scan.half_extent_m = config_.half_extent_m;
  scan.encoding = config_.encoding;
  scan.surface_ids = config_.surface_ids;
  scan.normals = config_.normals;
  const Eigen::Vector3d nan = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  for (ScanFace& face : scan.faces) {
    face.occupancy.assign(std::size_t(n_) * std::size_t(n_), kUnvisited);
    face.distance_m.assign(std::size_t(n_) * std::size_t(n_), nan.x());
    face.surface.assign(std::size_t(n_) * std::size_t(n_), RayHits::kNoHit);
    if (config_.normals)
      face.normal_W.assign(std::size_t(n_) * std::size_t(n_), Eigen::Vector3f::Zero());
  }
  return scan;
}

Eigen::Isometry3d FaceScanner::BoxFrame(const Eigen::Isometry3d& X_WS) const {
  Eigen::Isometry3d X_WB = Eigen::Isometry3d::Identity();
  if (config_.alignment == Alignment::kBody) X_WB.linear() = X_WS.linear();
  X_WB.translation() = X_WS.translation();
  return X_WB;
}

std::vector<FaceScanner::Part> FaceScanner::DueAt(std::int64_t tick) const {
  const auto t = static_cast<std::uint64_t>(tick < 0 ? 0 : tick);
  switch (config_.refresh) {
    case Refresh::kFull:
      return {{0, 0, n_}, {1, 0, n_}, {2, 0, n_}, {3, 0, n_}, {4, 0, n_}, {5, 0, n_}};
    case Refresh::kSixStage:
      return {{int(t % 6), 0, n_}};
    case Refresh::kTwelveStage: {
      const int face = int((t / 2) % 6), half = n_ / 2;
      return t % 2 == 0 ? std::vector<Part>{{face, 0, half}} : std::vector<Part>{{face, half, n_}};
    }
  }
  return {};
}

void FaceScanner::AppendRays(const Part& part, const Eigen::Isometry3d& X_WS,
                             RayBatch* rays) const {
  const std::size_t first = rays->start.size();
  const std::size_t count = std::size_t(part.row_end - part.row_begin) * std::size_t(n_);
  rays->start.resize(first + count);
  rays->direction.resize(first + count);
  rays->length_m.resize(first + count);
  FillRays(part, X_WS, rays->origin_W, rays, first, false);
}

void FaceScanner::FillRays(const Part& part, const Eigen::Isometry3d& X_WS,
                           const Eigen::Vector3d& origin_W, RayBatch* rays, std::size_t first,
                           bool starts_only) const {
  const Eigen::Matrix3d R_WS = config_.alignment == Alignment::kBody
                                   ? Eigen::Matrix3d(X_WS.linear())
                                   : Eigen::Matrix3d::Identity();
  Eigen::Vector3d u, v;
  FaceGridAxes(part.face, &u, &v);
  const Eigen::Vector3f axis_W = (R_WS * FaceAxis(part.face)).cast<float>();
  const Eigen::Vector3d u_W = R_WS * u, v_W = R_WS * v;
  const double E = config_.half_extent_m, res = config_.resolution_m;
  const Eigen::Vector3d offset = X_WS.translation() - origin_W;
  // Start c, r = offset + u (-E + c res) + v (-E + r res), summed in that
  // order; the columns' first two terms are the same on every row.
  thread_local std::vector<Eigen::Vector3d> columns;
  columns.resize(std::size_t(n_));
  for (int c = 0; c < n_; ++c) columns[std::size_t(c)] = offset + u_W * (-E + c * res);
  const std::size_t count = std::size_t(part.row_end - part.row_begin) * std::size_t(n_);
  if (!starts_only) {
    std::fill_n(rays->direction.begin() + std::ptrdiff_t(first), count, axis_W);
    std::fill_n(rays->length_m.begin() + std::ptrdiff_t(first), count, static_cast<float>(E));
  }
  Eigen::Vector3f* start = rays->start.data() + first;
  for (int r = part.row_begin; r < part.row_end; ++r) {
    const Eigen::Vector3d row = v_W * (-E + r * res);
    for (int c = 0; c < n_; ++c) *start++ = (columns[std::size_t(c)] + row).cast<float>();
  }
}

RayGrid FaceScanner::GridOf(const Part& part, const Eigen::Isometry3d& X_WS,
                            std::size_t first) const {
  const Eigen::Matrix3d R_WS = config_.alignment == Alignment::kBody
                                   ? Eigen::Matrix3d(X_WS.linear())
                                   : Eigen::Matrix3d::Identity();
  Eigen::Vector3d u, v;
  FaceGridAxes(part.face, &u, &v);
  const double E = config_.half_extent_m, res = config_.resolution_m;
  RayGrid grid;
  grid.first = first;
  grid.rows = part.row_end - part.row_begin;
  grid.cols = n_;
  grid.corner_W = X_WS.translation() + R_WS * (u * -E + v * (-E + part.row_begin * res));
  grid.step_u_W = R_WS * u * res;
  grid.step_v_W = R_WS * v * res;
  // As FillRays gives them to the batch's rays.
  grid.direction = (R_WS * FaceAxis(part.face)).cast<float>();
  grid.length_m = static_cast<float>(E);
  return grid;
}

void FaceScanner::GridRays(std::int64_t tick, const Eigen::Isometry3d& X_WS, RayBatch* rays,
                           std::vector<RayGrid>* grids) const {
  rays->origin_W = X_WS.translation();
  rays->start.clear(), rays->direction.clear(), rays->length_m.clear();
  grids->clear();
  for (const Part& part : DueAt(tick)) {
    grids->push_back(GridOf(part, X_WS, rays->size()));
    AppendRays(part, X_WS, rays);
  }
}

void FaceScanner::Scan(const scene::CollisionWorld& world, RayCaster& caster,
                       const RayFilter& filter, const Eigen::Isometry3d& X_WS, std::int64_t tick,
                       FaceScan* scan) const {
  if (!X_WS.matrix().allFinite())
    throw std::invalid_argument("FaceScanner::Scan(): non-finite pose");
  if (scan->n != n_ || scan->normals != config_.normals) *scan = EmptyScan();
  const std::vector<Part> parts = DueAt(tick);
  // The rays keep their memory from scan to scan (no allocation a tick); the
  // hits go straight into the faces (RayGrid::into), `hits` stays empty.
  thread_local RayBatch rays;
  thread_local RayHits hits;
  hits.with_normals = config_.normals;
  thread_local std::vector<RayGrid> grids;
  // The rays of GridRays, made in pieces of rows on the caster's threads:
  // their starts only (the structured kernel takes the direction and the
  // length from the grids).
  grids.clear();
  std::size_t total = 0;
  for (const Part& part : parts) {
    // The caster writes the part's rows of its face directly.
    ScanFace& face = scan->faces[std::size_t(part.face)];
    const std::size_t k0 = std::size_t(part.row_begin) * std::size_t(n_);
    RayGrid grid = GridOf(part, X_WS, total);
    grid.into.distance_m = face.distance_m.data() + k0;
    grid.into.surface = face.surface.data() + k0;
    if (config_.normals) grid.into.normal_W = face.normal_W.data() + k0;
    grids.push_back(grid);
    total += std::size_t(part.row_end - part.row_begin) * std::size_t(n_);
  }
  // (The jobs reach this thread's thread_local batch and grids through
  // references: in a job, `rays` would be the job thread's own.)
  RayBatch& batch = rays;
  const std::vector<RayGrid>& blocks = grids;
  batch.origin_W = X_WS.translation();
  batch.Resize(total);
  constexpr int kPiecesPerPart = 8;
  caster.RunParallel(int(parts.size()) * kPiecesPerPart, [&](int job) {
    const Part& part = parts[std::size_t(job / kPiecesPerPart)];
    const int piece = job % kPiecesPerPart, rows = part.row_end - part.row_begin;
    const Part rows_of{part.face, part.row_begin + rows * piece / kPiecesPerPart,
                       part.row_begin + rows * (piece + 1) / kPiecesPerPart};
    const std::size_t first = blocks[std::size_t(job / kPiecesPerPart)].first +
                              std::size_t(rows_of.row_begin - part.row_begin) * std::size_t(n_);
    FillRays(rows_of, X_WS, batch.origin_W, &batch, first, true);
  });
  caster.CastGrids(world, rays, grids, filter, &hits);
  // Each part's occupancy from its surfaces (a part a job).
  caster.RunParallel(int(parts.size()), [&](int p) {
    const Part& part = parts[std::size_t(p)];
    ScanFace& face = scan->faces[std::size_t(part.face)];
    face.tick = tick;
    face.X_WS = X_WS;
    face.X_WB = BoxFrame(X_WS);
    const std::size_t k0 = std::size_t(part.row_begin) * std::size_t(n_);
    const std::size_t end = std::size_t(part.row_end) * std::size_t(n_);
    for (std::size_t k = k0; k < end; ++k) {
      face.occupancy[k] = face.surface[k] == RayHits::kNoHit ? kFree : kOccupied;
    }
  });
}

Eigen::Vector3d FaceScan::PointW(int face, std::size_t k) const {
  const ScanFace& f = faces[std::size_t(face)];
  Eigen::Vector3d u, v;
  FaceGridAxes(face, &u, &v);
  const double E = half_extent_m, res = resolution_m;
  const int r = int(k / std::size_t(n)), c = int(k % std::size_t(n));
  return f.X_WB * (u * (-E + c * res) + v * (-E + r * res) + FaceAxis(face) * f.distance_m[k]);
}

std::vector<Eigen::Vector3d> FaceScan::PointsW(int face) const {
  std::vector<Eigen::Vector3d> points(faces[std::size_t(face)].distance_m.size());
  for (std::size_t k = 0; k < points.size(); ++k) points[k] = PointW(face, k);
  return points;
}

FaceScannerConfig FaceScannerConfig::Read(scene::SettingsReader& read) {
  FaceScannerConfig face;
  face.resolution_m = read.Number("resolution_m", face.resolution_m);
  face.half_extent_m = read.Number("half_extent_m", face.half_extent_m);
  face.sample_budget = read.Number("sample_budget", face.sample_budget);
  const std::string refresh = read.Text("refresh", "six_stage");
  if (refresh == "full") {
    face.refresh = Refresh::kFull;
  } else if (refresh == "six_stage") {
    face.refresh = Refresh::kSixStage;
  } else if (refresh == "twelve_stage") {
    face.refresh = Refresh::kTwelveStage;
  } else {
    read.Fail("refresh",
              "'refresh' must be full, six_stage or twelve_stage, got '" + refresh + "'");
  }
  const std::string aligned = read.Text("aligned", "body");
  if (aligned != "body" && aligned != "world") {
    read.Fail("aligned", "'aligned' must be body or world, got '" + aligned + "'");
  }
  face.alignment = aligned == "body" ? Alignment::kBody : Alignment::kWorld;
  const std::string encoding = read.Text("encoding", "points");
  if (encoding == "points") {
    face.encoding = FaceEncoding::kPoints;
  } else if (encoding == "mm") {
    face.encoding = FaceEncoding::kMillimetres;
  } else if (encoding == "float") {
    face.encoding = FaceEncoding::kFloat;
  } else {
    read.Fail("encoding", "'encoding' must be points, mm or float, got '" + encoding + "'");
  }
  face.surface_ids = read.Flag("surface_ids", face.surface_ids);
  face.normals = read.Flag("normals", face.normals);
  if (face.normals && face.encoding != FaceEncoding::kPoints) {
    read.Fail("normals",
              "'normals' needs encoding = \"points\" (the compact encodings carry "
              "a distance and an id a sample)");
  }
  return face;
}

std::string FaceScannerConfig::Summary() const {
  std::ostringstream out;
  const int n = points_per_side();
  out << n << "x" << n << "x6 at " << resolution_m << " m";
  if (encoding == FaceEncoding::kMillimetres) out << ", compact in mm";
  if (encoding == FaceEncoding::kFloat) out << ", compact in float";
  return out.str();
}

void FaceScanner::Run(const SensorContext& at, FaceScan* scan) const {
  if (scan->n != n_ || scan->normals != config_.normals) *scan = EmptyScan();
  Scan(at.world, at.caster, at.filter, at.X_WS, at.tick, scan);
}

FaceFrames FaceScanner::LatestFrames(const FaceScan& scan, const Eigen::Isometry3d& X_WS) const {
  FaceFrames X_WF;
  for (std::size_t f = 0; f < 6; ++f) {
    const ScanFace& face = scan.faces[f];
    X_WF[f] = face.tick >= 0 ? face.X_WB : BoxFrame(X_WS);
  }
  return X_WF;
}

}  // namespace sandbox::sensors
