// Logger formats other than CSV: LabVIEW .lvm and UFF58 (ASCII and binary 58b).
#include <cstring>

#include "harness.h"
#include "mbid/records/records.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // The extension picks the reader: LVM files start with their signature, the rest go to UFF.
  const bool lvm = size >= 7 && std::memcmp(data, "LabVIEW", 7) == 0;
  const std::string path = mbid::fuzz::WriteInput(data, size, lvm ? ".lvm" : ".uff");
  mbid::fuzz::ExpectContractErrorsOnly([&] { mbid::records::ImportMeasurement(path); });
  return 0;
}
