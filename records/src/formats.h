#pragma once

// Which reader reads a file: one table from extensions to readers (formats.cc).

#include <string>
#include <vector>

#include "raw_table.h"

namespace mbid::records::internal {

// The file as its reader returns it; an unsupported extension is an InputError listing the
// supported ones. `time_unit` (--time-unit, "" for none) reaches readers that apply it themselves.
RawTable ReadRawTable(const std::string& path, const std::string& time_unit);

}  // namespace mbid::records::internal
