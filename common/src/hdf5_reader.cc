// H5Reader: mbid's HDF5 files and others' (h5py, MATLAB), every problem an InputError naming
// the file and object (docs/file-formats.md).
// This file: opening a file and reading its objects, attributes and datasets.
#include <H5Cpp.h>
#include <fmt/format.h>

#include <memory>
#include <string>
#include <vector>

#include "hdf5_internal.h"
#include "hdf5_reader_impl.h"
#include "internal.h"
#include "mbid/common/error.h"
#include "mbid/common/hdf5_io.h"

namespace mbid {
using internal::AttributeField;
using internal::Describe;
using internal::H5Lock;
using internal::H5Mutex;
using internal::JoinPath;
using internal::kExpectedH5;
using internal::ObjectExists;
using internal::OpenedObject;
using internal::ReadProblem;
using internal::ReadStringData;
using internal::TypeClassName;

namespace {

void CheckNumeric(H5T_class_t type_class) {
  if (type_class != H5T_FLOAT && type_class != H5T_INTEGER) {
    throw ReadProblem{"is of " + TypeClassName(type_class) + " type", "float64 numbers"};
  }
}

}  // namespace

H5Reader::H5Reader(const std::string& path, Probe probe) {
  H5Lock lock(H5Mutex());
  H5::Exception::dontPrint();
  internal::CheckReadable(path, kExpectedH5);
  bool is_hdf5 = false;
  try {
    is_hdf5 = H5::H5File::isHdf5(path);
  } catch (const H5::Exception&) {
    H5Eclear2(H5E_DEFAULT);
  }
  if (!is_hdf5) throw InputError(path, "", "not an HDF5 file", kExpectedH5);
  if (probe == Probe::kEverything) internal::ProbeHdf5InChild(path, kExpectedH5);
  impl_ = std::make_unique<Impl>();
  impl_->path = path;
  try {
    impl_->file.openFile(path, H5F_ACC_RDONLY);
  } catch (const H5::Exception& e) {
    throw InputError(path, "", "cannot open as HDF5: " + Describe(e), kExpectedH5);
  }
}

H5Reader::~H5Reader() {
  H5Lock lock(H5Mutex());
  impl_.reset();
}

const std::string& H5Reader::path() const { return impl_->path; }

bool H5Reader::Exists(const std::string& object) const {
  return impl_->Run(object, [&] { return ObjectExists(impl_->file, object); });
}

bool H5Reader::HasAttribute(const std::string& object, const std::string& name) const {
  return impl_->Run(AttributeField(object, name), [&] {
    return ObjectExists(impl_->file, object) &&
           OpenedObject(impl_->file, object).get().attrExists(name);
  });
}

Eigen::VectorXd H5Reader::ReadVector(const std::string& group, const std::string& name) const {
  const std::string object = JoinPath(group, name);
  return impl_->Run(object, [&] {
    std::vector<hsize_t> dims;
    const std::vector<double> data = impl_->ReadNumeric(object, 1, &dims);
    return Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(data.data(), data.size()));
  });
}

Eigen::MatrixXd H5Reader::ReadMatrix(const std::string& group, const std::string& name) const {
  const std::string object = JoinPath(group, name);
  return impl_->Run(object, [&] {
    std::vector<hsize_t> dims;
    const std::vector<double> data = impl_->ReadNumeric(object, 2, &dims);
    using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
    return Eigen::MatrixXd(Eigen::Map<const RowMajor>(
        data.data(), static_cast<Eigen::Index>(dims[0]), static_cast<Eigen::Index>(dims[1])));
  });
}

double H5Reader::ReadScalar(const std::string& group, const std::string& name) const {
  const std::string object = JoinPath(group, name);
  return impl_->Run(object, [&] {
    std::vector<hsize_t> dims;
    const std::vector<double> data = impl_->ReadNumeric(object, 0, &dims);
    if (data.empty()) throw ReadProblem{"is empty (a null dataspace)", "a scalar number"};
    return data.front();
  });
}

std::vector<std::string> H5Reader::ReadStrings(const std::string& group,
                                               const std::string& name) const {
  const std::string object = JoinPath(group, name);
  return impl_->Run(object, [&] {
    const H5::DataSet dataset = impl_->OpenDataSet(object, "a string dataset");
    return ReadStringData(dataset.getId(), false);
  });
}

std::string H5Reader::ReadUnits(const std::string& group, const std::string& name) const {
  return ReadStringAttribute(JoinPath(group, name), "units");
}

std::string H5Reader::ReadStringAttribute(const std::string& object,
                                          const std::string& name) const {
  return impl_->Run(AttributeField(object, name), [&] {
    const H5::Attribute attribute = impl_->OpenAttribute(object, name);
    const std::vector<std::string> values = ReadStringData(attribute.getId(), true);
    if (values.size() != 1) {
      throw ReadProblem{fmt::format("has {} strings", values.size()), "a single string"};
    }
    return values.front();
  });
}

std::vector<std::string> H5Reader::ReadStringArrayAttribute(const std::string& object,
                                                            const std::string& name) const {
  return impl_->Run(AttributeField(object, name), [&] {
    const H5::Attribute attribute = impl_->OpenAttribute(object, name);
    return ReadStringData(attribute.getId(), true);
  });
}

double H5Reader::ReadDoubleAttribute(const std::string& object, const std::string& name) const {
  return impl_->Run(AttributeField(object, name), [&] {
    const H5::Attribute attribute = impl_->OpenAttribute(object, name);
    CheckNumeric(attribute.getTypeClass());
    if (attribute.getSpace().getSimpleExtentNpoints() != 1) {
      throw ReadProblem{"is not a single number", "a scalar number"};
    }
    double value = 0;
    attribute.read(H5::PredType::NATIVE_DOUBLE, &value);
    return value;
  });
}

long long H5Reader::ReadIntAttribute(const std::string& object, const std::string& name) const {
  return impl_->Run(AttributeField(object, name), [&] {
    const H5::Attribute attribute = impl_->OpenAttribute(object, name);
    if (attribute.getTypeClass() != H5T_INTEGER) {
      throw ReadProblem{"is of " + TypeClassName(attribute.getTypeClass()) + " type", "an integer"};
    }
    if (attribute.getSpace().getSimpleExtentNpoints() != 1) {
      throw ReadProblem{"is not a single number", "a scalar integer"};
    }
    long long value = 0;
    attribute.read(H5::PredType::NATIVE_LLONG, &value);
    return value;
  });
}

}  // namespace mbid
