// mbid's HDF5 measurement files: the record and the scenario stored with it, as `mbid` reads
// them (records import, then the embedded scenario text).
#include "harness.h"
#include "mbid/common/hdf5_io.h"
#include "mbid/records/records.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = mbid::fuzz::WriteInput(data, size, ".h5");
  mbid::fuzz::ExpectContractErrorsOnly([&] { mbid::records::ImportMeasurement(path); });
  mbid::fuzz::ExpectContractErrorsOnly([&] { mbid::ReadScenarioYaml(path); });
  return 0;
}
