#pragma once

#include <chrono>
#include <string>

namespace mbid::campaign::internal {

// Progress of a campaign on standard error: cases done of the total, failures, the rate of
// this run and the time left at that rate. On a terminal one line is rewritten in place;
// otherwise (a log file, CI) a line is printed every few seconds. Nothing with --quiet.
class CampaignProgress {
 public:
  CampaignProgress(std::string name, int total, int already_done, bool quiet);

  void Say(const std::string& message) const;
  // Reports `done` (this run's cases, all ranks) and `failed` at most every so often.
  void Update(int done, int failed);
  // The last line: cases, failures, wall time and rate.
  void Finish(int done, int failed);

 private:
  std::string Line(int done, int failed) const;
  double Elapsed() const;

  std::string name_;
  int total_;
  int already_done_;
  bool quiet_;
  bool terminal_;
  std::chrono::steady_clock::time_point start_;
  double last_print_s_ = -1e9;
  int last_done_ = -1;
};

}  // namespace mbid::campaign::internal
