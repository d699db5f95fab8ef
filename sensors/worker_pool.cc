#include "sensors/worker_pool.h"

#include <algorithm>
#include <chrono>

namespace sandbox::sensors {

WorkerPool::WorkerPool(int threads) {
  if (threads <= 0) threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  for (int i = 1; i < threads; ++i) workers_.emplace_back([this] { WorkerLoop(); });
}

WorkerPool::~WorkerPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  for (std::thread& worker : workers_) worker.join();
}

void WorkerPool::WorkerLoop() {
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
    const std::function<void(int)>* job;
    int chunks;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (stop_) return;
      seen = generation_.load();
      job = job_;
      chunks = chunks_;
    }
    for (int chunk; Claim(seen, chunks, &chunk);) {
      (*job)(chunk);
      unfinished_.fetch_sub(1, std::memory_order_release);
    }
  }
}

bool WorkerPool::Claim(std::uint64_t generation, int chunks, int* chunk) {
  std::uint64_t claim = claim_.load(std::memory_order_acquire);
  while ((claim >> 32) == (generation & 0xFFFFFFFFu) && int(claim & 0xFFFFFFFFu) < chunks) {
    if (claim_.compare_exchange_weak(claim, claim + 1, std::memory_order_acq_rel)) {
      *chunk = int(claim & 0xFFFFFFFFu);
      return true;
    }
  }
  return false;
}

void WorkerPool::RunParallel(int chunks, const std::function<void(int)>& job) {
  std::uint64_t generation;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    job_ = &job;
    chunks_ = chunks;
    unfinished_.store(chunks);
    generation = generation_.load() + 1;
    claim_.store((generation & 0xFFFFFFFFu) << 32);
    generation_.store(generation, std::memory_order_release);
  }
  wake_.notify_all();
  // The calling thread works too, then waits for the chunks others took.
  for (int chunk; Claim(generation, chunks, &chunk);) {
    job(chunk);
    unfinished_.fetch_sub(1, std::memory_order_release);
  }
  while (unfinished_.load(std::memory_order_acquire) > 0) std::this_thread::yield();
}

}  // namespace sandbox::sensors
