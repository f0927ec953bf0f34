// gnuplot processes started ahead of the figures they will draw (gnuplot.h, PrepareGnuplot).
#pragma once

#include <spawn.h>
#include <sys/types.h>

#include <optional>
#include <string>

namespace mbid::report::internal {

// A gnuplot reading commands from a pipe, its pngcairo terminal already set up: drawing into it
// skips the process start and cairo's font set-up, about 20 ms of a 40 ms figure.
struct StandbyGnuplot {
  pid_t pid = -1;
  int input = -1;   // its standard input
  int output = -1;  // its standard output and error
};

// posix_spawnp of argv[0] with `actions`, the child's signal mask emptied: mbid blocks SIGINT
// and SIGTERM in its threads (interrupt_cleanup.h), and a gnuplot that inherited that would not
// stop at Ctrl-C. Returns posix_spawnp's error number (0 on success).
int SpawnUnblocked(pid_t* pid, const posix_spawn_file_actions_t& actions, char* const argv[]);

// Starts standby processes until `count` wait (at most that many are kept); each runs
// `warm_up` at once (its terminal's set-up).
void StartStandbyGnuplot(int count, const std::string& warm_up);

// A waiting process, if one is still alive; the caller runs it with RunStandby.
std::optional<StandbyGnuplot> TakeStandbyGnuplot();

// Has `process` run `commands` and exit; its messages go to `log`. Returns the wait status, or
// -1 if the process was gone before it took the commands (the caller then starts a fresh one).
int RunStandby(const StandbyGnuplot& process, const std::string& commands, std::string* log);

}  // namespace mbid::report::internal
