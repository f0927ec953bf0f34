#pragma once

// What H5Reader's files share: the problem a read reports, the raw reads and H5Reader::Impl.
// Not part of the public API. The raw reads of an attribute's or dataset's strings and numbers
// are defined in hdf5_read_data.cc (also used by the child probe, hdf5_probe.cc); H5Reader's
// members in hdf5_reader.cc (objects, attributes, datasets) and hdf5_measurement_reader.cc
// (mbid's measurement and scenario).

#include <H5Cpp.h>

#include <string>
#include <vector>

#include "hdf5_internal.h"
#include "mbid/common/error.h"
#include "mbid/common/hdf5_io.h"

namespace mbid {
namespace internal {

// A problem found while reading one object; the caller adds the file and object.
struct ReadProblem {
  std::string problem;
  std::string expected;
};

std::string TypeClassName(H5T_class_t type_class);

// Strings of an attribute or dataset, variable- or fixed-length (h5py and MATLAB write both),
// each checked as UTF-8 (they become channel names, units and scenario text).
std::vector<std::string> ReadStringData(hid_t id, bool is_attribute);

// A numeric attribute or dataset as row-major doubles, its dimensions in `dims`; the rank is
// checked against `rank` unless that is negative.
std::vector<double> ReadNumericData(hid_t id, bool is_attribute, int rank,
                                    std::vector<hsize_t>* dims);

}  // namespace internal

struct H5Reader::Impl {
  std::string path;
  H5::H5File file;

  // Runs HDF5 calls about `object`, turning every failure into an InputError naming it.
  template <typename Body>
  auto Run(const std::string& object, Body&& body) const {
    internal::H5Lock lock(internal::H5Mutex());
    try {
      return body();
    } catch (const H5::Exception& e) {
      throw InputError(path, object, "HDF5 error: " + internal::Describe(e), internal::kExpectedH5);
    } catch (const internal::ReadProblem& p) {
      throw InputError(path, object, p.problem, p.expected);
    }
  }

  H5::DataSet OpenDataSet(const std::string& object, const std::string& expected) const {
    if (!internal::ObjectExists(file, object) || file.childObjType(object) != H5O_TYPE_DATASET) {
      throw internal::ReadProblem{"missing dataset", expected};
    }
    return file.openDataSet(object);
  }

  H5::Attribute OpenAttribute(const std::string& object, const std::string& name) const {
    if (!internal::ObjectExists(file, object))
      throw internal::ReadProblem{"missing object " + object, "an attribute"};
    const internal::OpenedObject target(file, object);
    if (!target.get().attrExists(name)) {
      throw internal::ReadProblem{"missing", "an attribute '" + name + "'"};
    }
    return target.get().openAttribute(name);
  }

  // Numeric dataset of the given rank, read as row-major doubles; dims returned in `dims`.
  std::vector<double> ReadNumeric(const std::string& object, int rank,
                                  std::vector<hsize_t>* dims) const {
    const H5::DataSet dataset = OpenDataSet(object, "a float64 dataset");
    return internal::ReadNumericData(dataset.getId(), false, rank, dims);
  }
};

}  // namespace mbid
