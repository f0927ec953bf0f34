// Scenario files: YAML syntax, every section's reader and the model built from it.
#include "harness.h"
#include "mbid/validation/scenario.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  // A folder that does not exist: record files and structure alternatives named relative to
  // the scenario are refused instead of read from wherever the fuzzer runs.
  mbid::fuzz::ExpectContractErrorsOnly([&] {
    mbid::validation::LoadScenarioFromText(text, "/nonexistent-mbid-fuzz/scenario.yaml");
  });
  return 0;
}
