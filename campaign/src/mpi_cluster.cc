// The ranks of an MPI job (OpenMPI). Built only when CMake finds MPI.
#include <mpi.h>

#include <stdexcept>
#include <vector>

#include "cluster.h"

namespace mbid::campaign::internal {
namespace {

// Messages: a request for a case or the final report of a rank carries {cases finished,
// cases failed} since the rank's previous message; the answer is a case index or -1.
constexpr int kTagRequest = 1;
constexpr int kTagAssign = 2;
constexpr int kTagFinished = 3;

class MpiCluster final : public Cluster {
 public:
  MpiCluster() {
    int initialized = 0;
    MPI_Initialized(&initialized);
    if (!initialized) {
      int provided = 0;
      MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
      if (provided < MPI_THREAD_FUNNELED) {
        throw std::runtime_error("MPI does not support MPI_THREAD_FUNNELED");
      }
      owns_mpi_ = true;
    }
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
  }
  ~MpiCluster() override {
    if (owns_mpi_) MPI_Finalize();
  }

  int rank() const override { return rank_; }
  int size() const override { return size_; }
  bool distributed() const override { return true; }

  int Broadcast(int value) override {
    MPI_Bcast(&value, 1, MPI_INT, 0, MPI_COMM_WORLD);
    return value;
  }

  bool Pump(const std::function<int()>& next, WorkQueue& local, const Tally& tally,
            bool workers_running) override {
    return rank_ == 0 ? PumpRoot(next, local, workers_running)
                      : PumpOther(local, tally, workers_running);
  }

  int remote_done() const override { return remote_done_; }
  int remote_failed() const override { return remote_failed_; }
  // Cases are fetched one per worker ahead, but a request and its answer each wait for a poll
  // on their side: at 10 ms the two could outlast a case (about 18 ms on the reference crane),
  // and 2 ranks ran 88-96 cases/s where 2 threads ran 103-114; at 2 ms they run 98-108, for no
  // measurable CPU (an MPI_Iprobe or MPI_Test per poll; docs/performance.md).
  std::chrono::milliseconds poll_interval() const override { return std::chrono::milliseconds(2); }
  [[noreturn]] void Abort(int exit_code) override {
    MPI_Abort(MPI_COMM_WORLD, exit_code);
    std::abort();
  }

 private:
  bool PumpRoot(const std::function<int()>& next, WorkQueue& local, bool workers_running) {
    int flag = 0;
    MPI_Status status;
    while (MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &status), flag) {
      int counts[2] = {0, 0};
      MPI_Recv(counts, 2, MPI_INT, status.MPI_SOURCE, status.MPI_TAG, MPI_COMM_WORLD,
               MPI_STATUS_IGNORE);
      remote_done_ += counts[0];
      remote_failed_ += counts[1];
      if (status.MPI_TAG == kTagRequest) {
        int index = next();
        MPI_Send(&index, 1, MPI_INT, status.MPI_SOURCE, kTagAssign, MPI_COMM_WORLD);
      } else if (status.MPI_TAG == kTagFinished) {
        ++finished_ranks_;
      }
    }
    for (int wanted = local.Wanted(); wanted > 0; --wanted) {
      const int index = next();
      if (index < 0) {
        local.Close();
        break;
      }
      local.Push(index);
    }
    return !workers_running && finished_ranks_ == size_ - 1;
  }

  bool PumpOther(WorkQueue& local, const Tally& tally, bool workers_running) {
    if (finished_) return true;
    if (waiting_for_case_) {
      int flag = 0;
      MPI_Test(&request_, &flag, MPI_STATUS_IGNORE);
      if (!flag) return false;
      waiting_for_case_ = false;
      if (assigned_ < 0) {
        local.Close();
      } else {
        local.Push(assigned_);
      }
    }
    if (local.Wanted() > 0) {
      int counts[2];
      TakeCounts(tally, counts);
      MPI_Send(counts, 2, MPI_INT, 0, kTagRequest, MPI_COMM_WORLD);
      MPI_Irecv(&assigned_, 1, MPI_INT, 0, kTagAssign, MPI_COMM_WORLD, &request_);
      waiting_for_case_ = true;
      return false;
    }
    if (local.closed() && !workers_running) {
      int counts[2];
      TakeCounts(tally, counts);
      MPI_Send(counts, 2, MPI_INT, 0, kTagFinished, MPI_COMM_WORLD);
      finished_ = true;
    }
    return finished_;
  }

  // The counts since the previous message.
  void TakeCounts(const Tally& tally, int counts[2]) {
    const int done = tally.done.load();
    const int failed = tally.failed.load();
    counts[0] = done - reported_done_;
    counts[1] = failed - reported_failed_;
    reported_done_ = done;
    reported_failed_ = failed;
  }

  bool owns_mpi_ = false;
  int rank_ = 0;
  int size_ = 1;
  // Rank 0.
  int remote_done_ = 0;
  int remote_failed_ = 0;
  int finished_ranks_ = 0;
  // Other ranks.
  bool waiting_for_case_ = false;
  bool finished_ = false;
  int assigned_ = -1;
  MPI_Request request_ = MPI_REQUEST_NULL;
  int reported_done_ = 0;
  int reported_failed_ = 0;
};

}  // namespace

std::unique_ptr<Cluster> MakeMpiCluster() { return std::make_unique<MpiCluster>(); }

}  // namespace mbid::campaign::internal
