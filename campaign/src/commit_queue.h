#pragma once

#include <condition_variable>
#include <deque>
#include <mutex>
#include <optional>

#include "mbid/campaign/campaign_case.h"

namespace mbid::campaign::internal {

// Computed cases on their way to the one thread that commits their files. Case files are written
// under HDF5's process-wide lock (serial HDF5), a fifth of a reference-crane case: workers that
// committed themselves queued for it and left their core idle meanwhile. Now they hand the outcome
// over and compute the next case; the committer's writes fill the gaps. At most `capacity`
// outcomes wait (Push blocks beyond), so memory stays bounded when writing falls behind.
class CommitQueue {
 public:
  explicit CommitQueue(int capacity) : capacity_(capacity < 1 ? 1 : capacity) {}

  // False when the queue was closed (the committer failed): the outcome is dropped and the
  // worker should stop.
  bool Push(CaseOutcome outcome) {
    std::unique_lock<std::mutex> lock(mutex_);
    not_full_.wait(lock, [this] { return closed_ || static_cast<int>(queue_.size()) < capacity_; });
    if (closed_) return false;
    queue_.push_back(std::move(outcome));
    not_empty_.notify_one();
    return true;
  }
  // The next outcome, or nothing once the queue is closed and empty.
  std::optional<CaseOutcome> Pop() {
    std::unique_lock<std::mutex> lock(mutex_);
    not_empty_.wait(lock, [this] { return closed_ || !queue_.empty(); });
    if (queue_.empty()) return std::nullopt;
    CaseOutcome outcome = std::move(queue_.front());
    queue_.pop_front();
    not_full_.notify_one();
    return outcome;
  }
  // No more outcomes come (the last worker finished) or may be taken (the committer failed):
  // Pop drains what is queued, Push refuses.
  void Close() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closed_ = true;
    }
    not_empty_.notify_all();
    not_full_.notify_all();
  }

 private:
  std::mutex mutex_;
  std::condition_variable not_empty_, not_full_;
  const int capacity_;
  std::deque<CaseOutcome> queue_;
  bool closed_ = false;
};

}  // namespace mbid::campaign::internal
