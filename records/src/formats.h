#pragma once

// Which reader reads a file: one table from extensions to readers (formats.cc).

#include <string>
#include <vector>

#include "raw_table.h"

namespace mbid::records::internal {

// The file as its reader returns it; an unsupported extension is an InputError listing the
// supported ones.
RawTable ReadRawTable(const std::string& path);

}  // namespace mbid::records::internal
