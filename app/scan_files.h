#pragma once
// Scans as files: a face scan as a PLY point cloud (world frame, metres;
// occupied points red, free points green, unvisited points left out), as
// `sandbox scan` writes one and `sandbox run --scans-every` writes them, each
// with its sheet (scan_sheet.h) beside it.

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <string>
#include <thread>
#include <utility>

#include "sensors/face_scanner.h"

namespace sandbox::app {

// Throws std::runtime_error naming the file when it cannot be written.
void WriteFaceScanPly(const sensors::FaceScan& scan, const std::string& path);

// Writes face scans on a thread of its own (a PLY of 15k points takes about
// 15 ms, longer than a tick): PATH.ply and its sheet PATH.png. At most four
// wait; beyond that the oldest is dropped and counted. Failures are counted
// and the first one kept.
class ScanFileWriter {
 public:
  ScanFileWriter();
  ~ScanFileWriter();  // writes what is queued
  ScanFileWriter(const ScanFileWriter&) = delete;
  ScanFileWriter& operator=(const ScanFileWriter&) = delete;

  // `path` without its extension; `half_extent_m`: the scanner's. Never blocks.
  void Submit(sensors::FaceScan scan, std::string path, double half_extent_m);
  void Finish();  // writes what is queued

  std::int64_t written() const { return written_; }
  std::int64_t dropped() const { return dropped_; }
  std::int64_t failed() const { return failed_; }
  std::string error() const;

 private:
  void Loop();
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  struct Item {
    sensors::FaceScan scan;
    std::string path;
    double half_extent_m;
  };
  std::deque<Item> queue_;
  bool stopping_{false};
  std::string first_error_;
  std::atomic<std::int64_t> written_{0}, dropped_{0}, failed_{0};
  std::thread thread_;
};

}  // namespace sandbox::app
