#pragma once

// The registry of identification methods (docs/extending.md): one file per method under
// methods/, listed in method_registry.cc. Not part of the public API.

#include <string>
#include <vector>

#include "estimate.h"
#include "mbid/identification/options.h"
#include "record.h"

namespace mbid::identification {

struct MethodDefinition {
  const char* name;  // as in `--method`, the scenario's `method` and the JSON field `method`
  // Samples of the decimated record the method's order needs, and what needs them (the input
  // error's "expected at least N for <requirement>").
  int (*required_samples)(const IdentificationOptions& options, int channels);
  std::string (*requirement)(const IdentificationOptions& options, int channels);
  // The poles, their significance and the amplitude fit on the decimated record; a
  // NumericalError (NoModes) when nothing significant is there.
  Estimate (*estimate)(const AnalysisRecord& record, const IdentificationOptions& options);
};

// Every registered method, in the order the choices are listed.
const std::vector<MethodDefinition>& MethodRegistry();
// The method of that name; nullptr if none is registered.
const MethodDefinition* FindMethod(const std::string& name);

}  // namespace mbid::identification
