#include "app/scan_files.h"

#include <filesystem>
#include <fstream>
#include <iomanip>
#include <stdexcept>

#include "app/scan_sheet.h"

namespace sandbox::app {

void WriteFaceScanPly(const sensors::FaceScan& scan, const std::string& path) {
  std::size_t count = 0;
  for (const sensors::ScanFace& face : scan.faces) {
    for (const std::int8_t o : face.occupancy) count += o != sensors::kUnvisited;
  }
  std::ofstream out(path);
  out << "ply\nformat ascii 1.0\ncomment sandbox face scan: occupied red, free green; world "
         "frame, metres\nelement vertex "
      << count
      << "\nproperty double x\nproperty double y\nproperty double z\nproperty uchar red\n"
         "property uchar green\nproperty uchar blue\nend_header\n"
      << std::setprecision(10);
  for (int f = 0; f < 6; ++f) {
    const sensors::ScanFace& face = scan.faces[std::size_t(f)];
    for (std::size_t i = 0; i < face.occupancy.size() && i < face.distance_m.size(); ++i) {
      if (face.occupancy[i] == sensors::kUnvisited) continue;
      const Eigen::Vector3d p = scan.PointW(f, i);
      out << p.x() << ' ' << p.y() << ' ' << p.z() << ' '
          << (face.occupancy[i] == sensors::kOccupied ? "255 0 0" : "0 255 0") << '\n';
    }
  }
  out.close();  // the last buffer's write errors show here
  if (!out) throw std::runtime_error("cannot write " + path);
}

ScanFileWriter::ScanFileWriter() : thread_([this] { Loop(); }) {}

ScanFileWriter::~ScanFileWriter() { Finish(); }

void ScanFileWriter::Finish() {
  if (!thread_.joinable()) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_one();
  thread_.join();
}

void ScanFileWriter::Submit(sensors::FaceScan scan, std::string path, double half_extent_m) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (queue_.size() >= 4) {
      queue_.pop_front();
      ++dropped_;
    }
    queue_.push_back({std::move(scan), std::move(path), half_extent_m});
  }
  wake_.notify_one();
}

std::string ScanFileWriter::error() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return first_error_;
}

void ScanFileWriter::Loop() {
  for (;;) {
    Item item;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
      if (queue_.empty()) return;
      item = std::move(queue_.front());
      queue_.pop_front();
    }
    try {
      WriteFaceScanPly(item.scan, item.path + ".ply");
      WriteFaceScanSheet(item.scan, item.half_extent_m, item.path + ".png",
                         std::filesystem::path(item.path).filename().string());
      ++written_;
    } catch (const std::exception& e) {
      if (failed_++ == 0) {
        std::lock_guard<std::mutex> lock(mutex_);
        first_error_ = e.what();
      }
    }
  }
}

}  // namespace sandbox::app
