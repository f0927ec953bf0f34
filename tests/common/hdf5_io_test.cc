// HDF5 measurement/result files: exact round trips, h5py compatibility both ways, atomic writing,
// and one test per bad input, each naming the file and the dataset or attribute.
#include "mbid/common/hdf5_io.h"

#include <H5Cpp.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <thread>

#include "test_util.h"

namespace mbid {
namespace {

using testing::CatchInputError;
using ::testing::HasSubstr;
using testing::MakeMeasurement;
using testing::SameBits;
using testing::TempDir;

constexpr int kSamples = 257;  // below the chunking threshold: contiguous datasets

void WriteValid(const std::string& path, const Measurement& m) {
  H5Writer writer(path);
  writer.WriteMeasurement(m);
  writer.Commit();
}

void ExpectSameMeasurement(const Measurement& read, const Measurement& written) {
  EXPECT_EQ(read.channels, written.channels);
  EXPECT_EQ(read.units, written.units);
  EXPECT_EQ(read.source, written.source);
  EXPECT_TRUE(SameBits(read.start_time_s, written.start_time_s));
  EXPECT_TRUE(SameBits(read.sample_interval_s, written.sample_interval_s));
  EXPECT_TRUE(SameBits(read.values, written.values));
}

TEST(Hdf5IoTest, MeasurementRoundTripIsExact) {
  TempDir dir;
  const std::string path = dir.File("m.h5");
  const Measurement written = MakeMeasurement(kSamples);
  WriteValid(path, written);
  ExpectSameMeasurement(ReadMeasurementH5(path), written);
  EXPECT_EQ(dir.Entries(), std::vector<std::string>{"m.h5"});  // no temporary left over
}

TEST(Hdf5IoTest, LongMeasurementRoundTripIsExact) {
  TempDir dir;
  const std::string path = dir.File("m.hdf5");
  // 100001 samples: above the chunk threshold and not a multiple of the chunk size.
  const Measurement written = MakeMeasurement(100001);  // see the comment above
  WriteValid(path, written);
  ExpectSameMeasurement(ReadMeasurement(path), written);
}

TEST(Hdf5IoTest, ScenarioYamlRoundTrip) {
  TempDir dir;
  const std::string path = dir.File("m.h5");
  const std::string yaml = "name: kran\nmodel:\n  type: truck_crane  # Ausleger \xc3\xbc\n";
  {
    H5Writer writer(path);
    writer.WriteMeasurement(MakeMeasurement(kSamples));
    writer.WriteScenarioYaml(yaml);
    writer.Commit();
  }
  EXPECT_EQ(ReadScenarioYaml(path), yaml);
}

TEST(Hdf5IoTest, ScenarioYamlIsEmptyWhenAbsent) {
  TempDir dir;
  const std::string path = dir.File("m.h5");
  WriteValid(path, MakeMeasurement(kSamples));
  EXPECT_EQ(ReadScenarioYaml(path), "");
}

TEST(Hdf5IoTest, ResultDatasetsRoundTrip) {
  TempDir dir;
  const std::string path = dir.File("r.h5");
  Eigen::VectorXd v(4);               // 4: a short result vector
  v << 1.0 / 3.0, -2.5e-300, 0.0, 7;  // a repeating fraction, a tiny value, zero, an integer
  Eigen::MatrixXd m(3, 2);            // 3 x 2: not square, so a transposition would show
  m << 1, 2, 3, 4, 5, 6;              // distinct entries reveal the element order
  const std::vector<std::string> names = {"alpha", "gamma", ""};  // an empty string too
  {
    H5Writer writer(path);
    writer.WriteVector("/truth/modes", "frequency_hz", v, "Hz");
    writer.WriteMatrix("/truth", "M", m, "kg*m^2");
    writer.WriteScalar("/updating", "cost", 0.1, "1");  // 0.1: inexact in binary
    writer.WriteScalar("/updating", "cost", 0.2, "1");  // 0.2: the rewrite replaces it
    writer.WriteStrings("/truth", "coordinates", names);
    writer.WriteStringAttribute("/updating", "termination", "converged");
    writer.WriteDoubleAttribute("/truth/M", "scale", 2.5);  // 2.5: an attribute on a dataset
    writer.Commit();
  }
  H5Reader reader(path);
  EXPECT_TRUE(SameBits(reader.ReadVector("/truth/modes", "frequency_hz"), v));
  EXPECT_EQ(reader.ReadUnits("/truth/modes", "frequency_hz"), "Hz");
  EXPECT_TRUE(SameBits(reader.ReadMatrix("/truth", "M"), m));
  EXPECT_EQ(reader.ReadUnits("/truth", "M"), "kg*m^2");
  EXPECT_EQ(reader.ReadScalar("/updating", "cost"), 0.2);  // the last value written
  EXPECT_EQ(reader.ReadStrings("/truth", "coordinates"), names);
  EXPECT_EQ(reader.ReadStringAttribute("/updating", "termination"), "converged");
  EXPECT_EQ(reader.ReadDoubleAttribute("/truth/M", "scale"), 2.5);  // as written
  EXPECT_EQ(reader.ReadStringAttribute("/", "format"), "mbid");
  EXPECT_EQ(reader.ReadIntAttribute("/", "format_version"), 1);  // the contract's version
  EXPECT_TRUE(reader.Exists("/truth/modes/frequency_hz"));
  EXPECT_FALSE(reader.Exists("/truth/modes/frequency_hz/x"));  // below a dataset
  EXPECT_FALSE(reader.Exists("/validation"));
}

std::string FileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Every kind of object the writer makes, a rewrite and a replaced group among them.
void WriteEveryKind(const std::string& path) {
  H5Writer writer(path);
  writer.WriteMeasurement(MakeMeasurement(kSamples));
  writer.WriteMeasurement(MakeMeasurement(100001), "/long");  // chunked and compressed
  writer.WriteVector("/truth/modes", "frequency_hz", Eigen::Vector2d(1.5, 2.5), "Hz");
  writer.WriteScalar("/updating", "cost", 0.1, "1");
  writer.WriteScalar("/updating", "cost", 0.2, "1");
  writer.WriteStrings("/truth", "coordinates", {"alpha", "gamma"});
  writer.WriteStringAttribute("/updating", "termination", "converged");
  writer.WriteScenarioYaml("name: kran\n");
  writer.Commit();
}

TEST(Hdf5IoTest, SameContentGivesTheSameBytes) {
  // HDF5 stores each object's modification time unless told not to (1 s resolution): two files
  // of the same content written more than a second apart then differ. The campaign's merge
  // copies case files with H5Ocopy and relies on this for the same bytes with any worker count.
  TempDir dir;
  WriteEveryKind(dir.File("first.h5"));
  std::this_thread::sleep_for(std::chrono::milliseconds(1100));  // past the next second
  WriteEveryKind(dir.File("second.h5"));
  const std::string first = FileBytes(dir.File("first.h5"));
  EXPECT_GT(first.size(), 1000u);  // a real file, not two empty reads
  EXPECT_TRUE(first == FileBytes(dir.File("second.h5")));
}

TEST(Hdf5IoTest, ReplacedGroupForgetsItsChildren) {
  // The writer answers "does this path exist" from what it created: a measurement written
  // again over one with other channels removes the old group, and a dataset of the old name can
  // then be written anew (it would fail if the writer still believed it existed).
  TempDir dir;
  const std::string path = dir.File("m.h5");
  Measurement other = MakeMeasurement(kSamples);
  other.channels = {"c", "d"};  // two new names in place of psi, phi, alpha
  other.units = {"rad", "rad"};
  other.values = Eigen::MatrixXd(other.values.leftCols(2));
  {
    H5Writer writer(path);
    writer.WriteMeasurement(MakeMeasurement(kSamples));
    writer.WriteMeasurement(other);
    writer.WriteVector("/measurement", MakeMeasurement(kSamples).channels[0], Eigen::Vector2d(1, 2),
                       "rad");
    writer.Commit();
  }
  H5Reader reader(path);
  const std::string old_name = MakeMeasurement(kSamples).channels[1];
  EXPECT_FALSE(reader.Exists("/measurement/" + old_name));
  EXPECT_TRUE(reader.Exists("/measurement/c"));
  EXPECT_TRUE(SameBits(reader.ReadVector("/measurement", MakeMeasurement(kSamples).channels[0]),
                       Eigen::VectorXd(Eigen::Vector2d(1, 2))));
}

TEST(Hdf5IoTest, MissingResultDatasetNamesIt) {
  TempDir dir;
  const std::string path = dir.File("r.h5");
  WriteValid(path, MakeMeasurement(kSamples));
  const InputError e = CatchInputError([&] { H5Reader(path).ReadVector("/truth", "M"); });
  EXPECT_EQ(e.source(), path);
  EXPECT_EQ(e.field(), "/truth/M");
  EXPECT_EQ(e.problem(), "missing dataset");
}

// h5py (Debian's, for /usr/bin/python3) is the reference reader named in docs/interfaces.
bool HaveH5py() { return std::system("/usr/bin/python3 -c 'import h5py' >/dev/null 2>&1") == 0; }

int RunPython(const TempDir& dir, const std::string& script, const std::string& argument) {
  const std::string script_path = dir.File("check.py");
  testing::WriteText(script_path, script);
  return std::system(("/usr/bin/python3 " + script_path + " " + argument).c_str());
}

TEST(Hdf5IoTest, H5pyReadsTheLayoutOfTheContract) {
  if (!HaveH5py()) GTEST_SKIP() << "h5py is not installed for /usr/bin/python3";
  TempDir dir;
  const std::string path = dir.File("m.h5");
  {
    H5Writer writer(path);
    writer.WriteMeasurement(MakeMeasurement(kSamples));
    writer.WriteScenarioYaml("name: x\n");
    writer.WriteMatrix("/truth", "M", Eigen::MatrixXd::Identity(3, 2), "kg");  // 3 x 2: shape
    writer.Commit();
  }
  const char* script = R"(
import sys, h5py, numpy as np
with h5py.File(sys.argv[1], 'r') as f:
    assert isinstance(f.attrs['format'], str) and f.attrs['format'] == 'mbid', f.attrs['format']
    assert int(f.attrs['format_version']) == 1  # the contract's version
    g = f['measurement']
    channels = list(g.attrs['channels'])
    assert channels == ['psi', 'phi', 'alpha'], channels
    assert all(isinstance(c, str) for c in channels)
    assert isinstance(g.attrs['source'], str) and g.attrs['source'] == 'simulation'
    assert float(g.attrs['sample_interval_s']) == 0.01  # MakeMeasurement's interval
    for name in ['time'] + channels:
        assert g[name].dtype == np.float64 and g[name].shape == (257,), name  # kSamples
        assert isinstance(g[name].attrs['units'], str), name
    assert g['time'].attrs['units'] == 's' and g['alpha'].attrs['units'] == 'm'
    assert g['time'][0] == 0.125  # MakeMeasurement's start time
    assert f['scenario'].attrs['yaml'] == 'name: x\n'
    assert f['truth/M'].shape == (3, 2) and f['truth/M'][0, 0] == 1.0  # the identity written
)";
  EXPECT_EQ(RunPython(dir, script, path), 0);
}

TEST(Hdf5IoTest, ReadsAFileWrittenByH5pyWithFixedLengthStrings) {
  if (!HaveH5py()) GTEST_SKIP() << "h5py is not installed for /usr/bin/python3";
  TempDir dir;
  const std::string path = dir.File("py.h5");
  const char* script = R"(
import sys, h5py, numpy as np
with h5py.File(sys.argv[1], 'w') as f:
    f.attrs['format'] = np.bytes_('mbid')
    f.attrs['format_version'] = np.int64(1)  # the contract's version, as numpy's default int
    g = f.create_group('measurement')
    g.attrs['channels'] = np.array([b'psi', b'phi'])
    g.attrs['sample_interval_s'] = 0.01  # 100 Hz
    g.attrs['source'] = 'import'
    t = 0.5 + 0.01 * np.arange(50)  # 50 samples at 100 Hz from 0.5 s (exact in binary)
    g.create_dataset('time', data=t).attrs['units'] = 's'
    g.create_dataset('psi', data=2 * t).attrs['units'] = np.bytes_('rad')  # 2: exact scaling
    g.create_dataset('phi', data=t.astype(np.float32)).attrs['units'] = 'rad'
)";
  ASSERT_EQ(RunPython(dir, script, path), 0);
  const Measurement m = ReadMeasurementH5(path);
  EXPECT_EQ(m.channels, (std::vector<std::string>{"psi", "phi"}));
  EXPECT_EQ(m.units, (std::vector<std::string>{"rad", "rad"}));
  EXPECT_EQ(m.samples(), 50);            // np.arange(50)
  EXPECT_EQ(m.start_time_s, 0.5);        // t[0]
  EXPECT_EQ(m.sample_interval_s, 0.01);  // the attribute
  EXPECT_EQ(m.values(0, 0), 1.0);        // psi = 2 t at t[0] = 0.5, exact in binary
  EXPECT_EQ(m.values(0, 1), 0.5);        // phi = float32 t at t[0] = 0.5, exact in both widths
}

// ---- writing leaves nothing behind on failure ---------------------------------------------

TEST(Hdf5IoTest, WriterWithoutCommitLeavesNoFile) {
  TempDir dir;
  {
    H5Writer writer(dir.File("m.h5"));
    writer.WriteMeasurement(MakeMeasurement(kSamples));
  }
  EXPECT_TRUE(dir.Entries().empty());
}

TEST(Hdf5IoTest, WriterAbandonedAfterAnExceptionLeavesNoFile) {
  TempDir dir;
  const std::string path = dir.File("m.h5");
  Measurement bad = MakeMeasurement(kSamples);
  bad.values(100, 2) = std::numeric_limits<double>::quiet_NaN();  // sample 100 of alpha
  try {
    H5Writer writer(path);
    writer.WriteScenarioYaml("name: x\n");
    writer.WriteMeasurement(bad);
    writer.Commit();
    ADD_FAILURE() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.source(), path);
    EXPECT_EQ(e.field(), "alpha");
    EXPECT_THAT(e.problem(), HasSubstr("sample 100"));  // the sample set to NaN
  }
  EXPECT_TRUE(dir.Entries().empty());
}

TEST(Hdf5IoTest, WriterIntoMissingDirectoryFailsWithoutFile) {
  TempDir dir;
  const std::string path = dir.File("missing/m.h5");
  const InputError e = CatchInputError([&] { H5Writer writer(path); });
  EXPECT_EQ(e.source(), path);
  EXPECT_TRUE(dir.Entries().empty());
}

// ---- one bad input per test --------------------------------------------------------------

// A valid file at `path`, then damaged by `damage` with the plain HDF5 API or the writer.
class Hdf5BadInputTest : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = dir_.File("bad.h5");
    measurement_ = MakeMeasurement(kSamples);
  }
  void WriteWith(const std::function<void(H5Writer&)>& damage) {
    H5Writer writer(path_);
    writer.WriteMeasurement(measurement_);
    damage(writer);
    writer.Commit();
  }
  void DamageWithHdf5(const std::function<void(H5::H5File&)>& damage) {
    WriteValid(path_, measurement_);
    H5::H5File file(path_, H5F_ACC_RDWR);
    damage(file);
  }
  InputError Read() {
    return CatchInputError([this] { ReadMeasurementH5(path_); });
  }
  Eigen::VectorXd Time() const { return measurement_.CalcTime(); }

  TempDir dir_;
  std::string path_;
  Measurement measurement_;
};

TEST_F(Hdf5BadInputTest, NotAnHdf5File) {
  testing::WriteText(path_, "time,psi\n0,1\n");
  const InputError e = Read();
  EXPECT_EQ(e.source(), path_);
  EXPECT_EQ(e.problem(), "not an HDF5 file");
}

TEST_F(Hdf5BadInputTest, MissingFileCannotOpen) {
  const InputError e = CatchInputError([this] { ReadMeasurement(path_); });
  EXPECT_EQ(e.source(), path_);
  EXPECT_THAT(e.problem(), HasSubstr("cannot open"));
}

TEST_F(Hdf5BadInputTest, UnknownExtensionListsTheAcceptedOnes) {
  const std::string path = dir_.File("data.txt");
  testing::WriteText(path, "time,psi\n0,1\n1,2\n");
  const InputError e = CatchInputError([&] { ReadMeasurement(path); });
  EXPECT_EQ(e.source(), path);
  EXPECT_EQ(e.problem(), "unknown file extension '.txt'");
  EXPECT_THAT(e.expected(), HasSubstr(".h5, .hdf5 or .csv"));
}

TEST_F(Hdf5BadInputTest, WrongFormatAttribute) {
  WriteWith([](H5Writer& w) { w.WriteStringAttribute("/", "format", "netcdf"); });
  const InputError e = Read();
  EXPECT_EQ(e.source(), path_);
  EXPECT_EQ(e.field(), "/ attribute 'format'");
  EXPECT_EQ(e.problem(), "is 'netcdf'");
}

TEST_F(Hdf5BadInputTest, MissingFormatAttribute) {
  DamageWithHdf5([](H5::H5File& f) { f.openGroup("/").removeAttr("format"); });
  const InputError e = Read();
  EXPECT_EQ(e.field(), "/ attribute 'format'");
  EXPECT_EQ(e.problem(), "missing");
}

TEST_F(Hdf5BadInputTest, NewerFormatVersion) {
  DamageWithHdf5([](H5::H5File& f) {
    const int version = 2;  // one newer than the contract's
    f.openGroup("/").openAttribute("format_version").write(H5::PredType::NATIVE_INT, &version);
  });
  const InputError e = Read();
  EXPECT_EQ(e.field(), "/ attribute 'format_version'");
  EXPECT_THAT(e.problem(), HasSubstr("newer"));
}

TEST_F(Hdf5BadInputTest, MissingMeasurementGroup) {
  DamageWithHdf5([](H5::H5File& f) { f.unlink("/measurement"); });
  const InputError e = Read();
  EXPECT_EQ(e.source(), path_);
  EXPECT_EQ(e.field(), "/measurement");
  EXPECT_EQ(e.problem(), "missing group");
}

TEST_F(Hdf5BadInputTest, MissingChannelDataset) {
  DamageWithHdf5([](H5::H5File& f) { f.unlink("/measurement/phi"); });
  const InputError e = Read();
  EXPECT_EQ(e.source(), path_);
  EXPECT_EQ(e.field(), "/measurement/phi");
  EXPECT_THAT(e.problem(), HasSubstr("missing dataset for channel 'phi'"));
}

TEST_F(Hdf5BadInputTest, MissingUnitsAttribute) {
  DamageWithHdf5([](H5::H5File& f) { f.openDataSet("/measurement/psi").removeAttr("units"); });
  const InputError e = Read();
  EXPECT_EQ(e.field(), "/measurement/psi attribute 'units'");
  EXPECT_EQ(e.problem(), "missing");
}

TEST_F(Hdf5BadInputTest, MissingChannelsAttribute) {
  DamageWithHdf5([](H5::H5File& f) { f.openGroup("/measurement").removeAttr("channels"); });
  const InputError e = Read();
  EXPECT_EQ(e.field(), "/measurement attribute 'channels'");
  EXPECT_EQ(e.problem(), "missing");
}

TEST_F(Hdf5BadInputTest, TimeInMilliseconds) {
  WriteWith([this](H5Writer& w) {
    w.WriteVector("/measurement", "time", Time() * 1e3, "ms");  // 1e3: seconds to milliseconds
  });
  const InputError e = Read();
  EXPECT_EQ(e.field(), "/measurement/time attribute 'units'");
  EXPECT_EQ(e.problem(), "is 'ms'");
}

TEST_F(Hdf5BadInputTest, ChannelLengthMismatch) {
  WriteWith([](H5Writer& w) {
    w.WriteVector("/measurement", "phi", Eigen::VectorXd::Zero(kSamples - 1), "rad");  // 1 short
  });
  const InputError e = Read();
  EXPECT_EQ(e.field(), "/measurement/phi");
  EXPECT_EQ(e.problem(), "has 256 samples");  // kSamples - 1
}

TEST_F(Hdf5BadInputTest, NonUniformTime) {
  WriteWith([this](H5Writer& w) {
    Eigen::VectorXd t = Time();
    t[100] += 0.3 * measurement_.sample_interval_s;  // sample 100 moved by 30% of a step
    w.WriteVector("/measurement", "time", t, "s");
  });
  const InputError e = Read();
  EXPECT_EQ(e.source(), path_);
  EXPECT_EQ(e.field(), "/measurement/time");
  EXPECT_THAT(e.problem(), HasSubstr("non-uniform time"));
  // Either step touching the moved sample 100 may be reported.
  EXPECT_THAT(e.problem(), ::testing::AnyOf(HasSubstr("from sample 99 to 100"),
                                            HasSubstr("from sample 100 to 101")));
}

// Times stored in single precision (or as epoch seconds in double) are uniform to their last
// bit only: 1000.125 + j 0.01 s as floats deviates by up to 3e-5 s, 0.3 % of a step, and was
// refused as "non-uniform time". The stated interval stands where the fit agrees with it.
TEST_F(Hdf5BadInputTest, SinglePrecisionTimesAreUniformToTheirResolution) {
  WriteWith([this](H5Writer& w) {
    Eigen::VectorXd t = Time().array() + 1000.0;
    for (Eigen::Index j = 0; j < t.size(); ++j) t[j] = static_cast<float>(t[j]);
    w.WriteVector("/measurement", "time", t, "s");
  });
  const Measurement m = ReadMeasurementH5(path_);
  EXPECT_EQ(m.sample_interval_s, 0.01);         // the attribute
  EXPECT_NEAR(m.start_time_s, 1000.125, 1e-4);  // a float's resolution at 1000 s: 6e-5
}

TEST_F(Hdf5BadInputTest, DecreasingTime) {
  WriteWith([this](H5Writer& w) {
    Eigen::VectorXd t = Time();
    std::swap(t[10], t[11]);  // samples 10 and 11 out of order
    w.WriteVector("/measurement", "time", t, "s");
  });
  const InputError e = Read();
  EXPECT_EQ(e.field(), "/measurement/time");
  EXPECT_THAT(e.problem(), HasSubstr("time decreases"));
  EXPECT_THAT(e.problem(), HasSubstr("(sample 11)"));  // the later of the swapped pair
}

TEST_F(Hdf5BadInputTest, NaNInAChannel) {
  WriteWith([this](H5Writer& w) {
    Eigen::VectorXd psi = measurement_.values.col(0);
    psi[42] = std::numeric_limits<double>::quiet_NaN();  // sample 42: any inside the record
    w.WriteVector("/measurement", "psi", psi, "rad");
  });
  const InputError e = Read();
  EXPECT_EQ(e.field(), "/measurement/psi");
  EXPECT_THAT(e.problem(), HasSubstr("sample 42"));  // the sample set to NaN
  EXPECT_THAT(e.problem(), HasSubstr("NaN"));
}

TEST_F(Hdf5BadInputTest, InfinityInTime) {
  WriteWith([this](H5Writer& w) {
    Eigen::VectorXd t = Time();
    t[5] = std::numeric_limits<double>::infinity();  // sample 5: any inside the record
    w.WriteVector("/measurement", "time", t, "s");
  });
  const InputError e = Read();
  EXPECT_EQ(e.field(), "/measurement/time");
  EXPECT_THAT(e.problem(), HasSubstr("+Inf"));
}

TEST_F(Hdf5BadInputTest, FewerThanTwoSamples) {
  WriteWith([](H5Writer& w) {
    w.WriteVector("/measurement", "time", Eigen::VectorXd::Zero(1), "s");  // a single sample
  });
  const InputError e = Read();
  EXPECT_EQ(e.field(), "/measurement/time");
  EXPECT_EQ(e.problem(), "has 1 samples");  // the single sample written
}

TEST_F(Hdf5BadInputTest, IntervalAttributeDisagreesWithTime) {
  WriteWith([](H5Writer& w) {
    w.WriteDoubleAttribute("/measurement", "sample_interval_s", 0.02);  // twice the true step
  });
  const InputError e = Read();
  EXPECT_EQ(e.field(), "/measurement attribute 'sample_interval_s'");
  EXPECT_THAT(e.problem(), HasSubstr("has a step of"));
}

TEST_F(Hdf5BadInputTest, ChannelDatasetOfStrings) {
  WriteWith([](H5Writer& w) { w.WriteStrings("/measurement", "phi", {"a", "b"}); });
  const InputError e = Read();
  EXPECT_EQ(e.field(), "/measurement/phi");
  EXPECT_EQ(e.problem(), "is of string type");
}

// Dimensions of 2^40 samples in a file of a few KB (chunked, nothing written): refused before
// anything that size is allocated (it was std::bad_alloc, exit 1).
TEST_F(Hdf5BadInputTest, AbsurdDimensionsAreRefusedBeforeAllocating) {
  DamageWithHdf5([](H5::H5File& f) {
    f.unlink("/measurement/time");
    const hsize_t dims[1] = {hsize_t{1} << 40};
    const hsize_t chunk[1] = {1024};
    H5::DSetCreatPropList properties;
    properties.setChunk(1, chunk);
    f.createDataSet("/measurement/time", H5::PredType::NATIVE_DOUBLE, H5::DataSpace(1, dims),
                    properties);
  });
  const InputError e = Read();
  EXPECT_EQ(e.field(), "/measurement/time");
  EXPECT_THAT(e.problem(), HasSubstr("has dimensions beyond 100000000 elements"));
}

// A channel name that is not UTF-8 is refused where it is read, naming the attribute (it used
// to pass and fail only when the JSON summary was written).
TEST_F(Hdf5BadInputTest, ChannelNameThatIsNotUtf8) {
  DamageWithHdf5([](H5::H5File& f) {
    H5::Group group = f.openGroup("/measurement");
    group.removeAttr("channels");
    const H5::StrType type(H5::PredType::C_S1, 8);
    const hsize_t dims[1] = {2};
    H5::Attribute attribute = group.createAttribute("channels", type, H5::DataSpace(1, dims));
    const char names[16] = {'p', 's', 'i', 0, 0, 0, 0, 0, 'p', 'h', '\xE9', 0, 0, 0, 0, 0};
    attribute.write(type, names);
  });
  const InputError e = Read();
  EXPECT_EQ(e.field(), "/measurement attribute 'channels'");
  EXPECT_EQ(e.problem(), "string 2 is not UTF-8 (byte 0xE9 at byte 3)");
}

// The issue's cases, found by fuzz_hdf5: a variable-length string attribute whose global-heap
// read in libhdf5 1.10.8 (H5Aread -> H5T__conv_vlen -> H5HG_read) crashes with SIGSEGV, or
// loops for ever, on mbid's own read path. The read is tried in a child process first; the file
// ends in an InputError (exit 2), after the child's time limit for the loop.
InputError ReadHostile(const std::string& name) {
  TempDir dir;
  const std::string path = dir.File("hostile.h5");
  std::filesystem::copy_file(std::string(MBID_SOURCE_DIR) + "/tests/data/records/hostile/" + name,
                             path);
  const InputError e = CatchInputError([&] { ReadMeasurementH5(path); });
  EXPECT_EQ(e.source(), path);
  return e;
}

// What the child probe reports for this file: its crash (SIGSEGV inside libhdf5); under
// AddressSanitizer the wild read is caught first, in an intercepted libc call, and the child
// ends with ASan's report (exit status 1). Either way the file is refused, named.
#if defined(__SANITIZE_ADDRESS__)
const char* const kLibhdf5Crash = "the HDF5 library failed reading the file (status 1)";
#else
const char* const kLibhdf5Crash = "the HDF5 library crashed reading the file (signal 11";
#endif

TEST(Hdf5IoTest, AFileThatCrashesLibhdf5IsAnInputError) {
  EXPECT_THAT(ReadHostile("vlen_string_global_heap_crash.h5").problem(), HasSubstr(kLibhdf5Crash));
}

// With the child's time limit at 0.5 s (MBID_CHILD_PROBE_LIMIT_S) instead of the default 5 s,
// which a test need not wait for.
TEST(Hdf5IoTest, AFileThatHangsLibhdf5IsAnInputError) {
  ::setenv("MBID_CHILD_PROBE_LIMIT_S", "0.5", 1);
  const InputError e = ReadHostile("vlen_string_global_heap_loop.h5");
  ::unsetenv("MBID_CHILD_PROBE_LIMIT_S");
  EXPECT_THAT(e.problem(), HasSubstr("the HDF5 library did not finish reading the file in 0.5 s"));
}

// H5Reader used directly (not through ReadMeasurementH5) surveys the whole file in the child.
TEST(Hdf5IoTest, H5ReaderSurveysTheWholeFileFirst) {
  TempDir dir;
  const std::string path = dir.File("hostile.h5");
  std::filesystem::copy_file(
      std::string(MBID_SOURCE_DIR) + "/tests/data/records/hostile/vlen_string_global_heap_crash.h5",
      path);
  const InputError e = CatchInputError([&] { H5Reader reader(path); });
  EXPECT_THAT(e.problem(), HasSubstr(kLibhdf5Crash));
}

// A full disk, made by a file-size limit (writes fail with EFBIG as they would with ENOSPC). HDF5
// 1.10.8 crashed (SIGSEGV) when the writer closed the file a second time after the failed close.
// In a child process: the limit and the HDF5 state after the failure must not reach other tests.
TEST(Hdf5IoTest, AFullDiskIsAnErrorNotACrashAndLeavesNothing) {
  TempDir dir;
  const std::string path = dir.File("big.h5");
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    std::signal(SIGXFSZ, SIG_IGN);  // as mbid does: the write fails instead of killing
    // 64 KiB: the superblock and the root group fit, the 800 kB vector below does not.
    const rlimit limit{64 * 1024, 64 * 1024};
    ::setrlimit(RLIMIT_FSIZE, &limit);
    int code = 3;  // no exception: the limit did not bite
    try {
      H5Writer writer(path);
      // 100000 random doubles: 800 kB that compression cannot bring under the limit.
      writer.WriteVector("/big", "x", Eigen::VectorXd::Random(100000), "1");
      writer.Commit();
    } catch (const std::runtime_error&) {
      code = 0;
    }
    std::exit(code);  // std::exit, not _exit: HDF5's own clean-up at exit runs too
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status)) << "killed by signal " << WTERMSIG(status);
  EXPECT_EQ(WEXITSTATUS(status), 0);
  EXPECT_TRUE(dir.Entries().empty());  // the temporary is removed
}

}  // namespace
}  // namespace mbid
