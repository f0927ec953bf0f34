// CSV files, mbid's own and loggers' dialects, through the reader `mbid identify` uses.
#include "harness.h"
#include "mbid/common/csv_io.h"
#include "mbid/records/records.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = mbid::fuzz::WriteInput(data, size, ".csv");
  mbid::fuzz::ExpectContractErrorsOnly([&] { mbid::records::ImportMeasurement(path); });
  // mbid's strict CSV reader (the simulate/update round trip) on the same bytes.
  mbid::fuzz::ExpectContractErrorsOnly([&] { mbid::ReadMeasurementCsv(path); });
  return 0;
}
