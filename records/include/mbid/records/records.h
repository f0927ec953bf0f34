#pragma once

// Measured records in: mbid's own CSV and HDF5, logger CSV dialects, UFF58 (ASCII and binary),
// LabVIEW .lvm and MATLAB .mat, converted to SI with udunits2; records out as UFF58 and .mat.

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "mbid/common/measurement.h"

namespace mbid::records {

// What to do with empty or NaN cells.
enum class GapFill { kRefuse, kLinear };

// Everything a scenario's `record:` entry or the command line can say about how a file's columns
// become a record (docs/records.md).
struct ImportOptions {
  // Record channel -> file column (the column's name, or its 1-based number among the data
  // columns). Empty: every data column, under its own name.
  std::vector<std::pair<std::string, std::string>> channel_columns;
  // File column or record channel -> unit, completing or overriding the units in the file.
  std::map<std::string, std::string> units;
  std::string time_unit;  // overrides the time column's unit from the file when not empty
  // For files without a time column: samples at j / sample_rate_hz (0: such files are refused).
  double sample_rate_hz = 0.0;
  GapFill fill_gaps = GapFill::kRefuse;
  // Record channel -> the SI unit its consumer needs ("rad", "m/s^2"), from the model. A
  // channel listed here must come with a unit convertible to it; others go to the SI unit of
  // their own dimension.
  std::map<std::string, std::string> target_units;
};

// What the import did, for the user to check.
struct ImportReport {
  std::string format;                // "mbid-csv", "csv", "uff58", "lvm", "mat", "hdf5"
  std::string dialect;               // text files: "';'-separated, decimal comma, ..."
  std::vector<std::string> mapping;  // e.g. "psi <- column 3 (Boom angle)"
  int filled_samples = 0;            // cells interpolated by GapFill::kLinear
  // The samples with an interpolated cell, as indices of the record as read: no measurement
  // there, which the updating leaves out of its look for spikes.
  std::vector<int> filled_rows;
  int samples = 0;                       // the samples read
  std::vector<std::string> conversions;  // e.g. "theta: deg -> rad (x 0.0174533)"
  // What the file does not say and may have been misread: a column named `time` without a unit
  // is in seconds by the contract, and a step of 0.1 s or more is then more likely ms.
  std::vector<std::string> warnings;
  // The time was read in s without a unit in the file (a column named `time`, a MAT or LVM time).
  bool time_unit_assumed = false;
};

// Reads any supported file (chosen by its extension and contents), converts it to SI and
// checks it (Measurement::Validate). Invalid input is an InputError naming the file and the
// line, column, key or object.
Measurement ImportMeasurement(const std::string& path, const ImportOptions& options = {},
                              ImportReport* report = nullptr);

// Converts `measurement`'s channels in place from their units (Measurement::units, as a file
// would state them: "deg", "mm/s^2", "g") to the SI unit of each one's dimension, through
// udunits2 as ImportMeasurement does; the units become the SI ones. An unknown unit is an
// InputError naming `source` and "units/<channel>". Returns the conversions made, as
// ImportReport::conversions.
std::vector<std::string> ConvertToSi(Measurement* measurement, const std::string& source);

// `name` without the unit suffix ImportMeasurement reads a unit from (`tip_z_mm` -> `tip_z`;
// records.md), or `name` itself where it has none.
std::string NameWithoutUnitSuffix(const std::string& name);

// The file name extensions ImportMeasurement reads (".csv", ".h5", ...), and whether `path`
// has one of them (case ignored).
std::vector<std::string> SupportedExtensions();
// The name of an HDF5 output (-o): one that says another record format is refused (InputError
// naming -o), so that no HDF5 file ends up named .csv or .mat, which mbid would then read as that
// format. "" and "-" pass.
void CheckHdf5OutputName(const std::string& path);
bool IsSupportedFile(const std::string& path);
// The extension of `path`'s file name in lower case, with its dot (".csv"); "" if none.
std::string LowerExtension(const std::string& path);

// Writers for other tools. Both write atomically (a temporary name renamed when complete).
void WriteUff58(const Measurement& measurement, const std::string& path, bool binary = false);
void WriteMat(const Measurement& measurement, const std::string& path);

}  // namespace mbid::records
