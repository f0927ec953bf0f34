#pragma once

#include <string>

#include "mbid/app/commands.h"

namespace mbid::app {

// `mbid run [SCENARIO] [-o DIR] [--overwrite]`: the validation cycle (simulate the test ->
// identify -> update -> re-simulate -> compare) with its report. Everything is written into a
// temporary folder beside DIR and renamed into place at the end: a failed run leaves no partial
// results. DIR defaults to results/<scenario name, made a safe folder name>; an existing DIR is
// replaced only if it is empty, or holds an earlier run's results and common.overwrite is set
// (OutputFolder). Returns the exit code.
int RunValidationCycle(const std::string& scenario_path, const std::string& output_dir,
                       const CommonOptions& common);

}  // namespace mbid::app
