#pragma once

// The file readers formats.cc dispatches to; each returns the file as it is (raw_table.h).

#include <string>

#include "raw_table.h"

namespace mbid::records::internal {

// CSV and text exports of loggers in any dialect (csv_dialect.h), mbid's own CSV included.
RawTable ReadCsv(const std::string& path);
// mbid's HDF5 measurement file (/measurement), SI by contract; its time in the unit the time
// dataset states, or in `time_unit` when that is not empty (--time-unit).
RawTable ReadHdf5(const std::string& path, const std::string& time_unit);

}  // namespace mbid::records::internal
