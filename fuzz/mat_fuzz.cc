// MATLAB .mat files (v5 and v7.3, the latter HDF5) through matio.
#include "harness.h"
#include "mbid/records/records.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = mbid::fuzz::WriteInput(data, size, ".mat");
  mbid::fuzz::ExpectContractErrorsOnly([&] { mbid::records::ImportMeasurement(path); });
  return 0;
}
