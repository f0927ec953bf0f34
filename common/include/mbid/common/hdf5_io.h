#pragma once

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "mbid/common/measurement.h"

namespace mbid {

// The measurement/result HDF5 file of docs/interfaces:
//   /  attrs format = "mbid", format_version = 1
//   /measurement  attrs channels, sample_interval_s, source; datasets time and <channel>,
//                 each with attr units
//   /scenario     attr yaml (resolved scenario text)
//   other groups  (/truth, /identification, ...): one dataset per quantity, attr units.
// The file is written under a temporary name and renamed by Commit(); an H5Writer destroyed
// without Commit() leaves no file. Writing an object that exists replaces it. HDF5 failures
// throw std::runtime_error naming the file and object; WriteMeasurement() Validate()s first.
// Strings are variable-length UTF-8 (h5py reads them as str); matrices are stored row-major
// [rows, cols] as numpy expects. Calls into HDF5 are serialized by a process-wide lock because
// the serial HDF5 library is not thread-safe.
class H5Writer {
 public:
  // `sync`: as for AtomicFile.
  explicit H5Writer(const std::string& path, bool sync = true);
  ~H5Writer();
  H5Writer(const H5Writer&) = delete;
  H5Writer& operator=(const H5Writer&) = delete;

  // `group` other than /measurement: a further record in the same layout (a run's other tests).
  void WriteMeasurement(const Measurement& measurement, const std::string& group = "/measurement");
  void WriteScenarioYaml(const std::string& yaml_text);

  // `group` is an absolute path ("/truth/modes"); missing groups are created.
  void WriteVector(const std::string& group, const std::string& name, const Eigen::VectorXd& v,
                   const std::string& units);
  void WriteMatrix(const std::string& group, const std::string& name, const Eigen::MatrixXd& m,
                   const std::string& units);
  void WriteScalar(const std::string& group, const std::string& name, double value,
                   const std::string& units);
  void WriteStrings(const std::string& group, const std::string& name,
                    const std::vector<std::string>& values);
  void WriteStringAttribute(const std::string& group, const std::string& name,
                            const std::string& value);
  void WriteDoubleAttribute(const std::string& group, const std::string& name, double value);

  // Closes the file and renames it into place.
  void Commit();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The factor from the time unit a file states ("" when it states none) to seconds, for a
// reader that converts units (the records library); it throws InputError naming `field` for a
// unit it cannot convert, and sets `*unit` to the unit it read the times in.
using SecondsPerTimeUnit =
    std::function<double(const std::string& stated, const std::string& field, std::string* unit)>;

// Read access to an HDF5 file written by H5Writer (or by h5py, MATLAB, ... in the same layout).
// Every failure is an InputError naming the file and the dataset or attribute. Object paths
// are absolute ("/truth/modes"); the root is "/". Float datasets of any precision are read as
// double; strings may be variable- or fixed-length.
class H5Reader {
 public:
  // How the constructor guards against files that crash libhdf5 (docs/reliability.md).
  enum class Probe {
    kEverything,  // every attribute and dataset is read in a child process first
    kNone,        // nothing (a file this program wrote, or a caller that probed the exact reads)
  };
  // Throws InputError if the file cannot be opened or is not an HDF5 file, or if reading it
  // crashes or hangs libhdf5 in the child process.
  explicit H5Reader(const std::string& path, Probe probe = Probe::kEverything);
  ~H5Reader();
  H5Reader(const H5Reader&) = delete;
  H5Reader& operator=(const H5Reader&) = delete;

  const std::string& path() const;
  // Whether the group or dataset `object` exists ("/measurement/psi").
  bool Exists(const std::string& object) const;
  bool HasAttribute(const std::string& object, const std::string& name) const;

  Eigen::VectorXd ReadVector(const std::string& group, const std::string& name) const;
  Eigen::MatrixXd ReadMatrix(const std::string& group, const std::string& name) const;
  double ReadScalar(const std::string& group, const std::string& name) const;
  std::vector<std::string> ReadStrings(const std::string& group, const std::string& name) const;
  // The "units" attribute of dataset group/name.
  std::string ReadUnits(const std::string& group, const std::string& name) const;
  std::string ReadStringAttribute(const std::string& object, const std::string& name) const;
  std::vector<std::string> ReadStringArrayAttribute(const std::string& object,
                                                    const std::string& name) const;
  double ReadDoubleAttribute(const std::string& object, const std::string& name) const;
  long long ReadIntAttribute(const std::string& object, const std::string& name) const;

  // See ReadMeasurementH5 and ReadScenarioYaml.
  Measurement ReadMeasurement(const SecondsPerTimeUnit& seconds_per_unit = {}) const;
  std::string ReadScenarioYaml() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Reads /measurement; errors (not HDF5, wrong format attribute, missing channel, missing units,
// non-uniform or decreasing time, NaN/Inf, empty) name the file and the dataset or attribute.
// The sample interval is the sample_interval_s attribute, which must agree with the time
// dataset to the uniformity tolerance; the start time is the first time sample. The time is
// in s, or in any unit `seconds_per_unit` converts.
Measurement ReadMeasurementH5(const std::string& path,
                              const SecondsPerTimeUnit& seconds_per_unit = {});

// Reads the /scenario yaml attribute, or an empty string if the file has none.
std::string ReadScenarioYaml(const std::string& path);

// Dispatches on the extension: ".h5"/".hdf5" or ".csv"; anything else is an InputError.
Measurement ReadMeasurement(const std::string& path);

}  // namespace mbid
