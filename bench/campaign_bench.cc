// Campaign throughput (issue 7): 200 cases of simulate + identify on the reference crane
// (reference-crane.yaml: 8 s initial-deflection decay at 100 Hz, all four modes), with 1 and 2
// worker threads and with 2 MPI ranks of one worker each, in one run. Counters:
//   cases_per_s        cases over the time of the case phase (first case handed out to the last
//                      one committed)
//   total_cases_per_s  cases over the whole command (folder checks, merge into campaign.h5,
//                      summary.csv, report figures)
//   efficiency         cases_per_s / (units * cases_per_s with 1 worker). Case files are committed
//                      on a thread of their own, so 1 worker already overlaps writing with
//                      computing on a second core: this understates what a second worker adds;
//                      cpu_ratio is the fairer measure
//   cpu_ms_per_case    CPU time (user + system, all threads or all ranks and mpiexec) of the
//                      whole command per case: unlike rates, unaffected by other load on a
//                      shared host
//   cpu_ratio          cpu_ms_per_case / the same with 1 worker: what running in parallel costs
// The MPI run is the mbid binary under mpiexec; its case-phase rate is the one mbid reports.
#include <benchmark/benchmark.h>
#include <fcntl.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "mbid/campaign/campaign.h"
#include "mbid/campaign/campaign_runner.h"

extern char** environ;

namespace {

namespace fs = std::filesystem;

constexpr int kCases = 200;  // 10 elevations x 20 noise realizations

const fs::path& WorkDir() {
  static const fs::path dir = [] {
    const fs::path path =
        fs::temp_directory_path() / ("mbid_campaign_bench_" + std::to_string(::getpid()));
    fs::remove_all(path);
    fs::create_directories(path);
    std::ofstream(path / "bench.yaml")
        << "name: bench\nbase: " << MBID_SOURCE_DIR << R"(/scenarios/reference-crane.yaml
steps: [simulate, identify]
sweep:
  - grid:
      model.configuration.boom_elevation_deg: [5, 10, 15, 20, 25, 30, 35, 40, 45, 50]
  - repeat: 20
)";
    return path;
  }();
  return dir;
}

double& SingleWorkerRate() {
  static double rate = 0;
  return rate;
}
double& SingleWorkerCpu() {
  static double cpu = 0;
  return cpu;
}

// User + system CPU seconds of this process (RUSAGE_SELF) or of its waited-for children.
double CpuSeconds(int who) {
  rusage usage{};
  ::getrusage(who, &usage);
  auto seconds = [](const timeval& t) { return static_cast<double>(t.tv_sec) + 1e-6 * t.tv_usec; };
  return seconds(usage.ru_utime) + seconds(usage.ru_stime);
}

void Report(benchmark::State& state, int units, double cases_s, double total_s, double cpu_s) {
  const double rate = kCases / cases_s;
  const double cpu_ms = 1e3 * cpu_s / kCases;
  if (units == 1) {
    SingleWorkerRate() = rate;
    SingleWorkerCpu() = cpu_ms;
  }
  state.counters["cases_per_s"] = rate;
  state.counters["total_cases_per_s"] = kCases / total_s;
  state.counters["cpu_ms_per_case"] = cpu_ms;
  if (SingleWorkerRate() > 0) state.counters["efficiency"] = rate / (units * SingleWorkerRate());
  if (SingleWorkerCpu() > 0) state.counters["cpu_ratio"] = cpu_ms / SingleWorkerCpu();
}

void BM_CampaignThreads(benchmark::State& state) {
  const int workers = static_cast<int>(state.range(0));
  const mbid::campaign::Campaign campaign =
      mbid::campaign::LoadCampaign((WorkDir() / "bench.yaml").string());
  for (auto _ : state) {
    const fs::path out = WorkDir() / ("threads_" + std::to_string(workers));
    fs::remove_all(out);
    mbid::campaign::CampaignRunOptions options;
    options.workers = workers;
    options.quiet = true;
    const auto start = std::chrono::steady_clock::now();
    const double cpu_start = CpuSeconds(RUSAGE_SELF);
    const mbid::campaign::CampaignRunSummary summary =
        mbid::campaign::RunCampaign(campaign, out.string(), options);
    const double cpu = CpuSeconds(RUSAGE_SELF) - cpu_start;
    const double total =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    state.SetIterationTime(total);
    if (summary.failed > 0) state.SkipWithError("some cases failed");
    Report(state, workers, summary.cases_wall_s, total, cpu);
  }
}
BENCHMARK(BM_CampaignThreads)
    ->ArgName("workers")
    ->Arg(1)
    ->Arg(2)
    ->Iterations(1)
    ->UseManualTime()
    ->Unit(benchmark::kSecond);

void BM_CampaignMpiRanks(benchmark::State& state) {
#ifndef MBID_MPIEXEC
  state.SkipWithError("built without MPI");
  for (auto _ : state) {
  }
#else
  const int ranks = static_cast<int>(state.range(0));
  // Root in containers and a 2-core machine: allowed here only.
  ::setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
  ::setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
  ::setenv("OMPI_MCA_rmaps_base_oversubscribe", "1", 1);
  for (auto _ : state) {
    const fs::path out = WorkDir() / ("mpi_" + std::to_string(ranks));
    const fs::path log = WorkDir() / "mpi.log";
    fs::remove_all(out);
    // An argument vector, no shell; mbid's stderr (its "ran ... cases" line) into the log.
    const std::vector<std::string> args{MBID_MPIEXEC,
                                        "-n",
                                        std::to_string(ranks),
                                        std::string(MBID_BINARY_DIR) + "/app/mbid",
                                        "campaign",
                                        (WorkDir() / "bench.yaml").string(),
                                        "-o",
                                        out.string(),
                                        "--workers",
                                        "1"};
    std::vector<char*> argv;
    for (const std::string& arg : args) argv.push_back(const_cast<char*>(arg.c_str()));
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, log.c_str(),
                                     O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const auto start = std::chrono::steady_clock::now();
    const double cpu_start = CpuSeconds(RUSAGE_CHILDREN);
    pid_t pid = -1;
    int status = -1;
    if (posix_spawnp(&pid, argv[0], &actions, nullptr, argv.data(), environ) == 0) {
      while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
      }
    }
    posix_spawn_file_actions_destroy(&actions);
    const double cpu = CpuSeconds(RUSAGE_CHILDREN) - cpu_start;
    const double total =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    state.SetIterationTime(total);
    std::ifstream in(log);
    std::stringstream text;
    text << in.rdbuf();
    // "ran 200 cases in 12.34 s": the case phase as mbid measured it on rank 0.
    std::smatch match;
    const std::string err = text.str();
    if (status != 0 ||
        !std::regex_search(err, match, std::regex(R"(ran (\d+) cases in ([0-9.]+) s)"))) {
      state.SkipWithError(("mpiexec failed: " + err).c_str());
      continue;
    }
    Report(state, ranks, std::stod(match[2].str()), total, cpu);
  }
#endif
}
BENCHMARK(BM_CampaignMpiRanks)
    ->ArgName("ranks")
    ->Arg(2)
    ->Iterations(1)
    ->UseManualTime()
    ->Unit(benchmark::kSecond);

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  std::error_code ignored;
  fs::remove_all(WorkDir(), ignored);
  return 0;
}
