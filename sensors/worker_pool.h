#pragma once
// A pool of worker threads that run the chunks of one job at a time, the
// calling thread too: RunParallel(count, job) calls job(k) for k = 0 ..
// count-1, each once, and returns when all are done. Workers draw chunks from
// an atomic counter tagged with the job's generation (a late worker cannot
// take a chunk of the next job for the one it woke for), spin briefly
// between jobs (back-to-back jobs start at once), then sleep.
//
// Threads: one thread calls RunParallel at a time; a job must not use the
// pool it runs on.

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace sandbox::sensors {

class WorkerPool {
 public:
  // Starts `threads` - 1 workers (0: one per core); the caller is the last.
  explicit WorkerPool(int threads = 0);
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  void RunParallel(int count, const std::function<void(int)>& job);
  int threads() const { return static_cast<int>(workers_.size()) + 1; }

 private:
  void WorkerLoop();
  // Takes the next chunk of job `generation` into *chunk; false once that
  // job's chunks are all taken or a newer job has begun.
  bool Claim(std::uint64_t generation, int chunks, int* chunk);

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_;
  const std::function<void(int)>* job_{nullptr};
  int chunks_{0};
  std::atomic<std::uint64_t> claim_{0};  // generation << 32 | next chunk
  std::atomic<int> unfinished_{0};
  std::atomic<std::uint64_t> generation_{0};
  std::atomic<bool> stop_{false};
};

}  // namespace sandbox::sensors
