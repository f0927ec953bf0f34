#pragma once

#include <functional>
#include <string>

#include "mbid/validation/cycle.h"
#include "mbid/validation/scenario.h"

namespace mbid::report {

// Writes the results of a validation cycle into `folder` (an existing, empty folder, normally
// OutputFolder's temporary one): run.h5, summary.json (layout: docs/interfaces.md), report.md
// and its figures. Returns the number of figures drawn.
int WriteRunFolder(const validation::CycleResult& cycle, const validation::Scenario& scenario,
                   const std::string& folder, const std::function<void(const std::string&)>& say);

// Whether `folder` holds the results of an earlier `mbid run` and nothing else: run.h5 and
// summary.json (or the marker file of this version), report.md, PNG figures, and subfolders of
// figures for several tests.
bool IsRunFolder(const std::string& folder);

}  // namespace mbid::report
