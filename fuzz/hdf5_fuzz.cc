// mbid's HDF5 measurement files: the record and the scenario stored with it, as `mbid` reads
// them (records import, then the embedded scenario text).
#include "harness.h"
#include "mbid/common/hdf5_io.h"
#include "mbid/records/records.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = mbid::fuzz::WriteInput(data, size, ".h5");
  bool whole_file_refused = false;
  mbid::fuzz::ExpectContractErrorsOnly([&] {
    try {
      mbid::records::ImportMeasurement(path);
    } catch (const mbid::InputError& e) {
      // Refused as a whole (not HDF5, or libhdf5 crashed or looped in the child process): the
      // scenario's reader opens it the same way, and a second 5 s wait would pass -timeout=10.
      whole_file_refused = e.field().empty();
      throw;
    }
  });
  if (!whole_file_refused) {
    mbid::fuzz::ExpectContractErrorsOnly([&] { mbid::ReadScenarioYaml(path); });
  }
  return 0;
}
