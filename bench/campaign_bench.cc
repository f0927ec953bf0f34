// Campaign throughput (issue 7): 200 cases of simulate + identify on the reference crane
// (reference-crane.yaml: 8 s initial-deflection decay at 100 Hz, all four modes), with 1 and 2
// worker threads and with 2 MPI ranks of one worker each, in one run. Counters:
//   cases_per_s        cases over the time of the case phase (first case handed out to the last
//                      one committed)
//   total_cases_per_s  cases over the whole command (folder checks, merge into campaign.h5,
//                      summary.csv, report figures)
//   efficiency         cases_per_s / (units * cases_per_s with 1 worker): the parallel efficiency
// The MPI run is the mbid binary under mpiexec; its case-phase rate is the one mbid reports.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "mbid/campaign/campaign.h"
#include "mbid/campaign/campaign_runner.h"

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

void Report(benchmark::State& state, int units, double cases_s, double total_s) {
  const double rate = kCases / cases_s;
  if (units == 1) SingleWorkerRate() = rate;
  state.counters["cases_per_s"] = rate;
  state.counters["total_cases_per_s"] = kCases / total_s;
  if (SingleWorkerRate() > 0) state.counters["efficiency"] = rate / (units * SingleWorkerRate());
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
    const mbid::campaign::CampaignRunSummary summary =
        mbid::campaign::RunCampaign(campaign, out.string(), options);
    const double total =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    state.SetIterationTime(total);
    if (summary.failed > 0) state.SkipWithError("some cases failed");
    Report(state, workers, summary.cases_wall_s, total);
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
    const std::string command = std::string(MBID_MPIEXEC) + " -n " + std::to_string(ranks) + " " +
                                MBID_BINARY_DIR + "/app/mbid campaign " +
                                (WorkDir() / "bench.yaml").string() + " -o " + out.string() +
                                " --workers 1 2> " + log.string();
    const auto start = std::chrono::steady_clock::now();
    const int status = std::system(command.c_str());
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
    Report(state, ranks, std::stod(match[2].str()), total);
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
