#include "progress.h"

#include <fmt/format.h>
#include <unistd.h>

#include <cstdio>

namespace mbid::campaign::internal {
namespace {

std::string Duration(double seconds) {
  if (seconds < 90) return fmt::format("{:.0f} s", seconds);
  if (seconds < 5400) return fmt::format("{:.0f} min", seconds / 60);
  return fmt::format("{:.1f} h", seconds / 3600);
}

}  // namespace

CampaignProgress::CampaignProgress(std::string name, int total, int already_done, bool quiet)
    : name_(std::move(name)),
      total_(total),
      already_done_(already_done),
      quiet_(quiet),
      terminal_(::isatty(STDERR_FILENO) != 0),
      start_(std::chrono::steady_clock::now()) {}

double CampaignProgress::Elapsed() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void CampaignProgress::Say(const std::string& message) const {
  if (quiet_) return;
  std::fprintf(stderr, "%smbid: campaign %s: %s\n", terminal_ ? "\r\x1b[K" : "", name_.c_str(),
               message.c_str());
}

std::string CampaignProgress::Line(int done, int failed) const {
  const double elapsed = Elapsed();
  const int finished = already_done_ + done;
  std::string line = fmt::format("{}/{} cases", finished, total_);
  if (failed > 0) line += fmt::format(" ({} failed)", failed);
  if (done > 0 && elapsed > 0) {
    const double rate = done / elapsed;
    line += fmt::format(", {:.3g} cases/s", rate);
    if (finished < total_) line += ", about " + Duration((total_ - finished) / rate) + " left";
  }
  return line;
}

void CampaignProgress::Update(int done, int failed) {
  if (quiet_ || done == 0 || done == last_done_) return;
  const double elapsed = Elapsed();
  // A terminal line is cheap to rewrite; a log gets a line every 5 s.
  if (elapsed - last_print_s_ < (terminal_ ? 0.25 : 5.0)) return;
  last_print_s_ = elapsed;
  last_done_ = done;
  if (terminal_) {
    std::fprintf(stderr, "\r\x1b[Kmbid: campaign %s: %s", name_.c_str(),
                 Line(done, failed).c_str());
  } else {
    std::fprintf(stderr, "mbid: campaign %s: %s\n", name_.c_str(), Line(done, failed).c_str());
  }
  std::fflush(stderr);
}

void CampaignProgress::Finish(int done, int failed) {
  if (quiet_) return;
  const double elapsed = Elapsed();
  std::string line = fmt::format("ran {} cases in {:.2f} s", done, elapsed);
  if (done > 0 && elapsed > 0) line += fmt::format(" ({:.3g} cases/s)", done / elapsed);
  if (failed > 0) line += fmt::format("; {} failed (see summary.csv)", failed);
  Say(line);
}

}  // namespace mbid::campaign::internal
