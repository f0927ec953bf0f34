#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "mbid/campaign/campaign.h"

namespace mbid::campaign::internal {

// The output folder of a campaign and the rules that make it safe to kill and resume:
//
//   DIR/campaign.json      manifest: the campaign's name, fingerprint and case count; written
//                          first, so that --resume can refuse a different campaign
//   DIR/cases/<id>.<crc>.h5  one file per finished case, written under a temporary name,
//                          then renamed to a name carrying the CRC-32 of its bytes: a case
//                          exists entirely or not at all, and a damaged one is recognised
//   DIR/campaign.h5        the merged results, renamed into place last: it exists only when
//                          the campaign is complete (then cases/ is removed)
//   DIR/summary.csv, DIR/report.md, DIR/*.png   written just before campaign.h5
//
// After kill -9 at any moment, the folder holds committed cases and perhaps temporaries;
// --resume deletes the temporaries, checks each committed case against its checksum (case files
// are not fsynced: a power cut can leave zeroed blocks behind a committed name), and runs the
// rest. rename() within one folder is atomic on POSIX file systems.
class ResultsFolder {
 public:
  enum class State { kNew, kResumed, kComplete };

  explicit ResultsFolder(std::string dir) : dir_(std::move(dir)) {}

  // Creates the folder and its manifest for a new campaign, or checks that a resumed folder
  // belongs to this campaign. Errors (a folder holding something else, another campaign, a
  // campaign without --resume) are InputErrors naming the folder.
  State Prepare(const Campaign& campaign, bool resume) const;
  struct Scan {
    std::vector<bool> committed;       // one flag per case of the campaign
    std::vector<std::string> damaged;  // "<id>: <why>" for each case file removed to run again
  };
  // Which cases are committed, after removing temporaries and case files that fail their
  // checksum or do not read back (a file system that lost data).
  Scan ScanCommitted(const Campaign& campaign) const;

  // Writes a case's file under its final name: to a temporary, then renamed with the checksum
  // of its bytes in the name. `write` writes the complete file at the path it is given.
  void CommitCase(const std::string& case_id,
                  const std::function<void(const std::string& path)>& write) const;
  // The committed file of each case found in cases/, by case id.
  std::map<std::string, std::string> FindCommittedCases() const;
  std::string Path(const std::string& name) const;  // DIR/<name>
  // Removes the case files once campaign.h5 holds them, and cases/ when nothing else is in it
  // (a file of the user's there stays).
  void RemoveCases() const;

 private:
  std::string dir_;
};

}  // namespace mbid::campaign::internal
