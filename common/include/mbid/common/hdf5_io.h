#pragma once

#include <Eigen/Core>
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
// without Commit() leaves no file.
class H5Writer {
 public:
  explicit H5Writer(const std::string& path);
  ~H5Writer();
  H5Writer(const H5Writer&) = delete;
  H5Writer& operator=(const H5Writer&) = delete;

  void WriteMeasurement(const Measurement& measurement);
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

// Reads /measurement; errors (not HDF5, wrong format attribute, missing channel, missing units,
// non-uniform or decreasing time, NaN/Inf, empty) name the file and the dataset or attribute.
Measurement ReadMeasurementH5(const std::string& path);

// Reads the /scenario yaml attribute, or an empty string if the file has none.
std::string ReadScenarioYaml(const std::string& path);

// Dispatches on the extension: ".h5"/".hdf5" or ".csv"; anything else is an InputError.
Measurement ReadMeasurement(const std::string& path);

}  // namespace mbid
