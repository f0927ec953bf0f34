#pragma once

// The time base of a record read from a file (time_base.cc), and what import.cc shares with it.

#include <Eigen/Core>
#include <string>

#include "mbid/common/measurement.h"
#include "mbid/records/records.h"
#include "raw_table.h"

namespace mbid::records::internal {

// "column 3 (Boom angle)": where a column is, and its name.
std::string DescribeColumn(const RawColumn& column);
// "line 12" (or "sample 11") of sample j, with `where` after it when given.
std::string SampleField(const RawTable& table, const std::string& where, Eigen::Index j);

// The table's time column (or interval, or `options.sample_rate_hz` without either) as m's
// start_time_s and sample_interval_s, in the user's unit over the file's; a time read in s
// without a unit is doubted in `report` where its step is 0.1 s or more. InputError on a time
// that is no uniform grid.
void ReadTimeBase(const RawTable& table, const std::string& path, const ImportOptions& options,
                  const std::string& user_time_unit, Measurement* m, ImportReport* report);

// A time read in s without a unit, a step of 0.02-0.1 s, and a record that swings over 1000
// samples per period: doubted in `report` as a ms clock of 10-50 kHz.
void SayIfOversampled(const Measurement& m, ImportReport* report);

}  // namespace mbid::records::internal
