#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <memory>

#include "work_queue.h"

namespace mbid::campaign::internal {

// Cases finished by this process's workers.
struct Tally {
  std::atomic<int> done{0};
  std::atomic<int> failed{0};
};

// The processes that share a campaign: one process alone, or the ranks of an MPI job
// (`mpirun -n K mbid campaign ...`). Rank 0 owns the list of pending cases and hands them out
// one at a time on request, so that fast ranks take more cases (each rank keeps one case per
// worker queued ahead, which hides the answer's delay); every rank writes its cases'
// files itself, and rank 0 merges them at the end. Only the main thread of a rank calls MPI
// (MPI_THREAD_FUNNELED); worker threads never do.
class Cluster {
 public:
  virtual ~Cluster() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  bool is_root() const { return rank() == 0; }
  // Started by mpirun (even with one rank): the job's launcher placed the processes on cores.
  virtual bool distributed() const = 0;

  // Rank 0's `value`, on every rank.
  virtual int Broadcast(int value) = 0;
  // One round of distribution, called by the main thread of every rank while its workers run.
  // Rank 0 answers other ranks' requests and feeds its own workers from `next` (the next
  // pending case, -1 when none is left); other ranks ask rank 0 for a case for each worker
  // that waits. Returns true when this rank's part is over: its workers have finished
  // (`workers_running` false) and, on rank 0, every other rank has reported that it finished.
  virtual bool Pump(const std::function<int()>& next, WorkQueue& local, const Tally& tally,
                    bool workers_running) = 0;
  // Cases that other ranks finished, as far as rank 0 knows (0 elsewhere).
  virtual int remote_done() const { return 0; }
  virtual int remote_failed() const { return 0; }
  // How long the main thread may wait for its workers between two rounds.
  virtual std::chrono::milliseconds poll_interval() const = 0;
  // Ends every rank at once (a rank that cannot write its results).
  [[noreturn]] virtual void Abort(int exit_code) = 0;
};

// MPI when this process was started by mpirun and mbid was built with MPI; otherwise a single
// process. Throws InputError if started by mpirun with several ranks but built without MPI
// (every rank would run the whole campaign into the same folder).
std::unique_ptr<Cluster> JoinCluster();

// This process alone, whatever launched it.
std::unique_ptr<Cluster> MakeSingleProcess();

// Defined only in builds with MPI (mpi_cluster.cc).
std::unique_ptr<Cluster> MakeMpiCluster();

}  // namespace mbid::campaign::internal
