#include "mbid/identification/modal_result.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <set>
#include <string>

#include "mbid/common/hdf5_io.h"
#include "mbid/identification/identify.h"
#include "signals.h"

namespace mbid::identification {
namespace {

// The paper's record without noise: every field is filled and known.
ModalResult PaperResult() {
  const testing::SignalSpec spec = testing::PaperSignal();
  return Identify(testing::MakeRecord(spec, testing::Synthesize(spec)), IdentificationOptions());
}

std::set<std::string> Keys(const nlohmann::json& object) {
  std::set<std::string> keys;
  for (const auto& item : object.items()) keys.insert(item.key());
  return keys;
}

TEST(ModalResultTest, DerivedQuantitiesFollowTheNotation) {
  // The paper's mode 1: beta = -6.77 1/s at 1.155 Hz; Table 1 gives ln2/|beta| = 0.102 s and
  // interfaces.md's example damping ratio 0.68, undamped 1.58 Hz, log decrement 5.86.
  IdentifiedMode mode;
  mode.SetPole({-6.77, 2 * M_PI * 1.155});
  EXPECT_DOUBLE_EQ(mode.decay_rate_per_s, 6.77);
  EXPECT_DOUBLE_EQ(mode.frequency_hz, 1.155);
  EXPECT_NEAR(mode.half_life_s, 0.102, 0.0005);          // Table 1, 3 digits
  EXPECT_NEAR(mode.damping_ratio, 0.68, 0.005);          // interfaces.md, 2 digits
  EXPECT_NEAR(mode.undamped_frequency_hz, 1.58, 0.005);  // interfaces.md, 3 digits
  EXPECT_NEAR(mode.log_decrement, 5.86, 0.005);          // 2 pi 6.77 / (2 pi 1.155)
  mode.SetPole({0.0, 1.0});                              // not decaying: no half life
  EXPECT_TRUE(std::isinf(mode.half_life_s));
}

TEST(ModalResultTest, JsonHasTheFieldsOfTheContract) {
  const ModalResult result = PaperResult();
  const nlohmann::json json = ModalResultToJson(result);
  // docs/interfaces.md, `identify`: these fields, and optional extras only.
  for (const char* key : {"channels", "sample_interval_s", "samples", "method", "model_order",
                          "effective_rank", "modes", "correlation"}) {
    EXPECT_TRUE(json.contains(key)) << key;
  }
  EXPECT_EQ(json["channels"], nlohmann::json({"psi", "phi"}));
  EXPECT_EQ(json["sample_interval_s"], 0.01);
  EXPECT_EQ(json["samples"], 1000);
  EXPECT_EQ(json["method"], "hankel-nls");
  EXPECT_TRUE(json["model_order"].is_number_integer());
  EXPECT_TRUE(json["effective_rank"].is_number_integer());
  EXPECT_EQ(Keys(json["correlation"]), (std::set<std::string>{"psi", "phi"}));
  ASSERT_EQ(json["modes"].size(), 4u);
  double previous = 0;
  for (const auto& mode : json["modes"]) {
    for (const char* key : {"frequency_hz", "decay_rate_per_s", "damping_ratio",
                            "undamped_frequency_hz", "log_decrement", "half_life_s"}) {
      EXPECT_TRUE(mode[key].is_number()) << key;
    }
    EXPECT_EQ(Keys(mode["amplitude"]), (std::set<std::string>{"psi", "phi"}));
    EXPECT_EQ(Keys(mode["phase_rad"]), (std::set<std::string>{"psi", "phi"}));
    EXPECT_GT(mode["frequency_hz"].get<double>(), previous);  // ascending frequency
    previous = mode["frequency_hz"].get<double>();
  }
  // Table 1's first mode, amplitude 0.0112 rad in psi (noiseless: the synthesized value).
  EXPECT_NEAR(json["modes"][0]["amplitude"]["psi"].get<double>(), 0.0112, 1e-9);
  EXPECT_NEAR(json["modes"][0]["decay_rate_per_s"].get<double>(), 6.77, 1e-8);
}

TEST(ModalResultTest, NonFiniteNumbersBecomeNull) {
  ModalResult result = PaperResult();
  result.modes[0].std_frequency_hz = std::numeric_limits<double>::quiet_NaN();
  result.modes[0].half_life_s = std::numeric_limits<double>::infinity();
  const nlohmann::json json = ModalResultToJson(result);
  EXPECT_TRUE(json["modes"][0]["std_frequency_hz"].is_null());
  EXPECT_TRUE(json["modes"][0]["half_life_s"].is_null());
}

TEST(ModalResultTest, Hdf5GroupMirrorsTheJson) {
  const ModalResult result = PaperResult();
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("mbid_identification_" + std::to_string(::getpid()) + ".h5"))
                               .string();
  {
    H5Writer writer(path);
    WriteModalResult(writer, result);
    writer.Commit();
  }
  H5Reader reader(path);
  EXPECT_EQ(reader.ReadStringAttribute("/identification", "method"), "hankel-nls");
  EXPECT_EQ(reader.ReadStrings("/identification", "channels"),
            (std::vector<std::string>{"psi", "phi"}));
  EXPECT_EQ(reader.ReadScalar("/identification", "samples"), 1000);
  EXPECT_EQ(reader.ReadUnits("/identification", "sample_interval_s"), "s");
  const Eigen::VectorXd frequency = reader.ReadVector("/identification/modes", "frequency_hz");
  ASSERT_EQ(frequency.size(), 4);
  EXPECT_EQ(frequency(2), result.modes[2].frequency_hz);  // exact: float64 round trip
  EXPECT_EQ(reader.ReadUnits("/identification/modes", "frequency_hz"), "Hz");
  EXPECT_EQ(reader.ReadUnits("/identification/modes", "decay_rate_per_s"), "1/s");
  const Eigen::VectorXd psi = reader.ReadVector("/identification/modes/amplitude", "psi");
  EXPECT_EQ(psi(0), result.modes[0].amplitude(0));
  EXPECT_EQ(reader.ReadUnits("/identification/modes/amplitude", "psi"), "rad");
  EXPECT_EQ(reader.ReadUnits("/identification/modes/phase_rad", "phi"), "rad");
  EXPECT_EQ(reader.ReadScalar("/identification/correlation", "phi"), result.correlation(1));
  EXPECT_EQ(reader.ReadVector("/identification/reconstruction", "psi").size(), 1000);
  EXPECT_TRUE(reader.Exists("/identification/spectrum/frequency_hz"));
  EXPECT_TRUE(reader.Exists("/identification/stabilization/order"));
  EXPECT_TRUE(reader.Exists("/identification/eq2_coefficients"));
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace mbid::identification
