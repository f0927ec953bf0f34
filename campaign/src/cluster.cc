#include "cluster.h"

#include <cstdlib>
#include <string>

#include "mbid/common/error.h"

namespace mbid::campaign::internal {
namespace {

// This process alone: every pending case goes to its own workers.
class SingleProcess final : public Cluster {
 public:
  int rank() const override { return 0; }
  int size() const override { return 1; }
  bool distributed() const override { return false; }
  int Broadcast(int value) override { return value; }
  // Queues every pending case at once: the workers never wait for the main thread.
  bool Pump(const std::function<int()>& next, WorkQueue& local, const Tally& /*tally*/,
            bool workers_running) override {
    if (!local.closed()) {
      for (int index = next(); index >= 0; index = next()) local.Push(index);
      local.Close();
    }
    return !workers_running;
  }
  std::chrono::milliseconds poll_interval() const override {
    return std::chrono::milliseconds(200);
  }
  [[noreturn]] void Abort(int exit_code) override { std::exit(exit_code); }
};

// The world size mpirun (OpenMPI), PMI (MPICH, Slurm) or PMIx announce, or 0 if none does.
int LauncherWorldSize() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"}) {
    if (const char* value = std::getenv(name)) return std::atoi(value);
  }
  return std::getenv("PMIX_RANK") != nullptr ? 1 : 0;
}

}  // namespace

std::unique_ptr<Cluster> MakeSingleProcess() { return std::make_unique<SingleProcess>(); }

std::unique_ptr<Cluster> JoinCluster() {
  const int world_size = LauncherWorldSize();
#ifdef MBID_HAVE_MPI
  if (world_size > 0) return MakeMpiCluster();
#else
  if (world_size > 1) {
    throw InputError("mpirun", "", "this mbid was built without MPI",
                     "a build with OpenMPI (libopenmpi-dev installed when configuring), or "
                     "mbid campaign without mpirun");
  }
#endif
  return std::make_unique<SingleProcess>();
}

}  // namespace mbid::campaign::internal
