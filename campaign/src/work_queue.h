#pragma once

#include <algorithm>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <optional>

namespace mbid::campaign::internal {

// The case indices waiting for this process's worker threads. The main thread pushes (all at
// once, or on demand when cases come from MPI rank 0) and closes; workers pop, blocking until a
// case comes or the queue is closed and empty. A worker that starts waiting wakes the main
// thread through `main_wakeup`, so that it can fetch more work at once.
class WorkQueue {
 public:
  // `prefetch`: how many cases to keep queued ahead of the workers when fetching on demand
  // (one per worker hides the time a case takes to arrive from rank 0).
  WorkQueue(std::condition_variable& main_wakeup, int prefetch)
      : main_wakeup_(main_wakeup), prefetch_(prefetch) {}

  void Push(int index) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      queue_.push_back(index);
    }
    workers_.notify_one();
  }
  void Close() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closed_ = true;
    }
    workers_.notify_all();
  }
  // The next case, or nothing when the queue is closed and empty.
  std::optional<int> Pop() {
    std::unique_lock<std::mutex> lock(mutex_);
    ++waiting_;
    main_wakeup_.notify_all();
    workers_.wait(lock, [this] { return !queue_.empty() || closed_; });
    --waiting_;
    if (queue_.empty()) return std::nullopt;
    const int index = queue_.front();
    queue_.pop_front();
    return index;
  }
  // How many more cases to fetch now: up to `prefetch` queued ahead of the workers.
  int Wanted() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return closed_ ? 0 : std::max(0, prefetch_ - static_cast<int>(queue_.size()));
  }
  bool closed() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return closed_;
  }

 private:
  mutable std::mutex mutex_;
  std::condition_variable workers_;
  std::condition_variable& main_wakeup_;
  const int prefetch_;
  std::deque<int> queue_;
  int waiting_ = 0;
  bool closed_ = false;
};

}  // namespace mbid::campaign::internal
