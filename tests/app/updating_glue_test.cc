// Route 1's glue: with more identified modes than coordinates, eq. 7 runs on the main ones (the
// paper chose its four "main" modes among all it found).
#include <gtest/gtest.h>

#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "../common/test_util.h"
#include "../updating/crane_fixture.h"
#include "mbid/identification/release.h"
#include "mbid/model/linear_model.h"
#include "mbid/updating/settings.h"
#include "mbid/validation/record_source.h"
#include "mbid/validation/release_cut.h"
#include "mbid/validation/release_profile.h"
#include "mbid/validation/two_route_update.h"

namespace mbid::app {
using validation::SelectMainModes;
using validation::SolveAlgebraicRoute;

namespace {

identification::IdentifiedMode Mode(std::complex<double> lambda, double psi, double phi) {
  identification::IdentifiedMode mode;
  mode.SetPole(lambda);
  mode.amplitude = Eigen::Vector2d(psi, phi);
  mode.phase_rad = Eigen::Vector2d::Zero();
  return mode;
}

TEST(UpdatingGlueTest, RouteOneRunsOnTheMainModesAndNamesTheOthers) {
  const updating::testing::Crane crane =
      updating::testing::LoadCrane(updating::testing::kReferenceScenario);
  const std::vector<model::Mode> exact = model::CalcModes(crane.model->Linearize());
  ASSERT_EQ(exact.size(), 4u);
  // The exact poles with the free decay's amplitudes of reference-crane.md, and a weak 6 Hz
  // mode the 4-DOF model does not have (a boom bending mode, say) inserted among them.
  identification::ModalResult identified;
  identified.channels = {"psi", "phi"};
  identified.samples = 201;
  identified.sample_interval_s = 0.02;
  identified.noise_std = Eigen::Vector2d(1e-5, 1e-5);
  identified.modes = {Mode(exact[0].lambda, 2.4e-3, 1.4e-5), Mode(exact[1].lambda, 1.5e-4, 8.2e-3),
                      Mode(exact[2].lambda, 5.3e-4, 5.8e-5), Mode(exact[3].lambda, 4.6e-4, 1.4e-3),
                      Mode({-2.0, 2 * M_PI * 6.0}, 2e-5, 2e-5)};
  const std::vector<size_t> main = SelectMainModes(identified, 4);
  EXPECT_EQ(main, (std::vector<size_t>{0, 1, 2, 3}));

  const Measurement record = updating::testing::SimulateExact(crane, 4.0, 50.0);
  const updating::UpdatingSettings settings =
      updating::MakeDefaultUpdatingSettings(*crane.model, crane.simulation.integrator);
  std::string note;
  const auto algebraic =
      SolveAlgebraicRoute(*crane.model, identified, record, crane.excitation, settings, &note);
  ASSERT_NE(algebraic, nullptr) << note;
  EXPECT_NE(note.find("6.000 Hz"), std::string::npos) << note;
  ASSERT_EQ(algebraic->status, updating::CharacteristicResult::Status::kSolved)
      << algebraic->message;
  // Exact poles: the chosen set is the truth to eq. 7's round-off (characteristic_test.cc).
  const auto& chosen = algebraic->solutions[static_cast<size_t>(algebraic->chosen)];
  for (size_t i = 0; i < algebraic->coordinates.size(); ++i) {
    const double c = crane.model->GetParameter("c_" + algebraic->coordinates[i]);
    EXPECT_NEAR(chosen.c[static_cast<Eigen::Index>(i)], c, 1e-6 * c) << i;
  }

  // A combination tone is never a main mode, however strong: the 6 Hz mode made 1000 times
  // stronger displaces the weakest (the third), and as a tone nothing.
  identified.modes[4].amplitude *= 1e3;
  EXPECT_EQ(SelectMainModes(identified, 4), (std::vector<size_t>{0, 1, 3, 4}));
  identified.modes[4].combination = "f2 + f3";
  EXPECT_EQ(SelectMainModes(identified, 4), (std::vector<size_t>{0, 1, 2, 3}));
  // Without the fourth mode the tone leaves 3 modes for 4 coordinates: no Route 1.
  identified.modes.erase(identified.modes.begin() + 3);
  EXPECT_EQ(
      SolveAlgebraicRoute(*crane.model, identified, record, crane.excitation, settings, &note),
      nullptr);
  EXPECT_NE(note.find("3 identified modes (besides combination tones) for 4 coordinates"),
            std::string::npos)
      << note;

  // Fewer modes than coordinates: no Route 1, and the reason.
  identified.modes.resize(3);
  EXPECT_EQ(
      SolveAlgebraicRoute(*crane.model, identified, record, crane.excitation, settings, &note),
      nullptr);
  EXPECT_NE(note.find("3 identified modes for 4 coordinates"), std::string::npos) << note;
}

// The reference crane's exact (noise-free) free decay and default settings, for tests of records
// cut at a release mbid found in them (TestRecord::release_detected), weighted by 1e-5 rad.
struct DetectedReleases {
  updating::testing::Crane crane =
      updating::testing::LoadCrane(updating::testing::kReferenceScenario);
  Measurement exact;
  updating::UpdatingSettings settings =
      updating::MakeDefaultUpdatingSettings(*crane.model, crane.simulation.integrator);
  DetectedReleases(double duration_s, double rate_hz)
      : exact(updating::testing::SimulateExact(crane, duration_s, rate_hz)) {}
  updating::TestRecord Test(const std::string& name, const Measurement& record) const {
    updating::TestRecord test = updating::MakeTestRecord(name, record, crane.excitation, settings);
    test.noise_std = {{"psi", 1e-5}, {"phi", 1e-5}};
    test.release_detected = true;
    return test;
  }
  // The exact record cut `samples` late, and the fit there (at the detected instant).
  struct Late {
    std::vector<updating::TestRecord> records;
    updating::UpdateResult best;
  };
  Late CutLate(double samples) const {
    Late late{{Test("late", validation::MoveRelease(exact, samples * exact.sample_interval_s))},
              {}};
    late.best = updating::UpdateModel(*crane.model, late.records, settings.options);
    return late;
  }
};

// Placing a detected release refits the best (release_profile.h): what the global search or
// Route 1 judged of it must survive. A parameter marked undetermined (here by hand, as the search
// marks those its alternative minima differ in) stays undetermined with its reason; the exact
// record's release is placed where it is (noise-free: within a hundredth of a sample).
TEST(UpdatingGlueTest, APlacedReleaseKeepsWhatTheSearchLeftUndetermined) {
  const DetectedReleases setup(2.0, 100.0);
  const auto& [crane, record, settings] = std::tie(setup.crane, setup.exact, setup.settings);
  const updating::TestRecord test = setup.Test("rec", record);
  updating::UpdateResult best = updating::UpdateModel(*crane.model, {test}, settings.options);
  ASSERT_NE(best.termination, updating::UpdateResult::Termination::kFailure);
  for (updating::ParameterEstimate& p : best.parameters) {
    if (p.name == "c_gamma") {
      p.determined = false;
      p.rival_differs = true;
      p.why_undetermined = "the alternative minima differ in it";
    } else if (p.name == "d_eta") {
      // What the credibility check says of a fit at a misplaced release: the placed fit judges
      // that again from its own residual.
      p.determined = false;
      p.why_undetermined =
          "the fit does not explain the records (a residual above the noise, "
          "not white)";
    }
  }
  best.undetermined = {"c_gamma", "d_eta"};
  // The misplaced fit's own judgment of d_eta goes with it; the search's warning stays.
  best.warnings = {"the records leave undetermined: d_eta (rank 7 of 8)",
                   "non-unique: 1 other minimum(s) fit the records as well as the best"};
  std::vector<updating::TestRecord> records{test};
  const std::vector<std::string> lines =
      validation::PlaceDetectedReleases(*crane.model, &records, settings.options, &best);
  EXPECT_EQ(std::count(best.warnings.begin(), best.warnings.end(), best.warnings.front()), 1);
  EXPECT_EQ(best.warnings.front(),
            "non-unique: 1 other minimum(s) fit the records as well as the best");
  for (const std::string& warning : best.warnings) {
    EXPECT_EQ(warning.find("d_eta (rank 7"), std::string::npos) << warning;
  }
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_NE(lines[0].find("the fit places the release"), std::string::npos) << lines[0];
  EXPECT_NEAR(records[0].record.start_time_s, record.start_time_s, 0.01 * record.sample_interval_s);
  EXPECT_FALSE(best.Find("c_gamma").determined);
  EXPECT_EQ(best.Find("c_gamma").why_undetermined, "the alternative minima differ in it");
  // Judged again from the placed fit's own residual: the misplaced fit's reason is gone (the
  // noise-free record's residual, the integration's error, is not white: not credible).
  EXPECT_EQ(best.Find("d_eta").why_undetermined.find("does not explain"), std::string::npos)
      << best.Find("d_eta").why_undetermined;
  EXPECT_EQ(best.Find("c_alpha").why_undetermined, best.Find("d_eta").why_undetermined);
  EXPECT_NE(std::find(best.undetermined.begin(), best.undetermined.end(), "c_gamma"),
            best.undetermined.end());
  // Moving the release half a sample later leaves out the sample it puts before the release.
  const Measurement later = validation::MoveRelease(record, 0.5 * record.sample_interval_s);
  EXPECT_EQ(later.samples(), record.samples() - 1);
  EXPECT_NEAR(later.start_time_s, record.start_time_s + 0.5 * record.sample_interval_s, 1e-12);
}

// Two records, one cut 0.4 samples late: placing each with the other where it is pulled the
// first (correct) one 0.19 samples off, and further sweeps place each with the other placed.
// Noise-free exact records: both releases back to a fiftieth of a sample.
TEST(UpdatingGlueTest, TwoDetectedReleasesArePlacedTogether) {
  const DetectedReleases setup(2.0, 100.0);
  const auto& [crane, exact, settings] = std::tie(setup.crane, setup.exact, setup.settings);
  const double tau = exact.sample_interval_s;
  std::vector<updating::TestRecord> records;
  for (const Measurement& record : {exact, validation::MoveRelease(exact, 0.4 * tau)}) {
    records.push_back(setup.Test("rec" + std::to_string(records.size()), record));
  }
  updating::UpdateResult best = updating::UpdateModel(*crane.model, records, settings.options);
  ASSERT_NE(best.termination, updating::UpdateResult::Termination::kFailure);
  validation::PlaceDetectedReleases(*crane.model, &records, settings.options, &best);
  // Times from the release of the first sample kept (a release placed later leaves sample 0
  // out): sample 0 of the first record at 0, sample 1 of the second at tau.
  const auto first_time = [](const Measurement& m) {
    return m.start_time_s >= 0.5 * m.sample_interval_s ? m.start_time_s - m.sample_interval_s
                                                       : m.start_time_s;
  };
  EXPECT_NEAR(first_time(records[0].record), 0.0, 0.02 * tau);
  EXPECT_NEAR(first_time(records[1].record), 0.0, 0.02 * tau);
  // Noise-free: each within its own std (0.0024 samples); three sweeps alone left the first 4
  // of its std off, and c_theta 2.3 of its.
  for (size_t k = 0; k < 2; ++k) {
    EXPECT_NEAR(best.tests[k].release_shift_s, k == 0 ? 0.0 : -0.4 * tau,
                best.tests[k].release_shift_std_s)
        << k;
  }
  for (const char* name : {"c_alpha", "c_gamma", "c_eta", "c_theta", "d_alpha", "d_theta"}) {
    const double truth = crane.model->GetParameter(name);
    // Within 2 of the standard deviations 1e-5 rad of noise would give (widened by the
    // releases' uncertainty): the releases' leftover misplacement is no confident error.
    EXPECT_NEAR(best.Find(name).value, truth, 2 * best.Find(name).std) << name;
  }
}

// A release given before the record's first sample: the logger started late. The record is kept
// whole and starts that long after the release, where the test's simulation starts (the reference
// crane's CSV cut 0.5 s after its release, --release-time-s -0.5, updates to the truth within 2
// std in `mbid update`).
TEST(UpdatingGlueTest, AReleaseGivenBeforeTheRecordStartsItThatLongAfter) {
  const updating::testing::Crane crane =
      updating::testing::LoadCrane(updating::testing::kReferenceScenario);
  Measurement record = updating::testing::SimulateExact(crane, 1.0, 50.0);
  record.source = "import";  // a logger's file, not mbid's own
  const Eigen::Index samples = record.values.rows();
  const validation::AppliedRelease applied = validation::CutRecordAtRelease(
      &record, "logger.csv", {false, -0.5, std::nullopt}, crane.excitation);
  EXPECT_EQ(applied.how, "given");
  EXPECT_EQ(applied.release_time_s, -0.5);
  EXPECT_EQ(record.values.rows(), samples);      // nothing cut
  EXPECT_NEAR(record.start_time_s, 0.5, 1e-12);  // 0 - (-0.5)
}

// A test's end given (`end_time_s`, --end-time-s): a second drop a few seconds after the first
// came to rest is not found (its rest is too short), and the fit ran over both drops,
// inconclusive in 272 s; ended before it, a trial's record passes in 8 s. The samples after the
// end go, in the file's time; an end that leaves no test, or one before the given release, is
// refused naming the key.
TEST(UpdatingGlueTest, ATestEndsWhereTheUserSays) {
  const updating::testing::Crane crane =
      updating::testing::LoadCrane(updating::testing::kReferenceScenario);
  Measurement record = updating::testing::SimulateExact(crane, 4.0, 50.0);  // 201 samples
  record.source = "import";
  Measurement ended = record;
  const validation::AppliedRelease applied =
      validation::CutRecordAtRelease(&ended, "logger.csv", {false, 0.0, 3.0}, crane.excitation);
  EXPECT_EQ(ended.values.rows(), 151);  // 0 .. 3 s
  EXPECT_TRUE(ended.values == record.values.topRows(151));
  EXPECT_EQ(applied.end_time_s, 3.0);
  EXPECT_EQ(applied.ToJson().at("end_time_s"), 3.0);
  for (const validation::ReleaseChoice& bad :
       {validation::ReleaseChoice{false, 1.0, 0.5}, validation::ReleaseChoice{false, {}, 0.1}}) {
    Measurement copy = record;
    const InputError e = testing::CatchInputError(
        [&] { validation::CutRecordAtRelease(&copy, "logger.csv", bad, crane.excitation); });
    EXPECT_EQ(e.source(), "logger.csv");
    EXPECT_EQ(e.field(), "end_time_s");
  }
  // An end before the release the record shows (here the crane held 1 s, then released).
  Measurement held = record;
  held.values = Eigen::MatrixXd(50 + record.samples(), record.channel_count());
  held.values.topRows(50) = record.values.row(0).replicate(50, 1);
  held.values.bottomRows(record.samples()) = record.values;
  const InputError early = testing::CatchInputError([&] {
    validation::CutRecordAtRelease(&held, "logger.csv", {false, {}, 0.8}, crane.excitation);
  });
  EXPECT_EQ(early.field(), "end_time_s");
  EXPECT_NE(early.problem().find("(found in the record)"), std::string::npos) << early.problem();
  // The record entry's key, and the command line's over it.
  const YamlReader entry =
      YamlReader::FromString("file: x.csv\nrelease_time_s: 2\nend_time_s: 1.5\n", "s.yaml");
  const InputError before = testing::CatchInputError([&] { validation::ReadReleaseChoice(entry); });
  EXPECT_EQ(before.field(), "end_time_s");
  validation::ImportOverrides overrides;
  overrides.end_time_s = 9.0;
  EXPECT_EQ(validation::OverrideRelease({false, 2.0, 5.0}, overrides).end_time_s, 9.0);
  overrides.release_none = true;
  EXPECT_EQ(validation::OverrideRelease({false, 2.0, 5.0}, overrides).end_time_s, 9.0);
}

// Two columns that would both be `psi` without their unit suffix stay whole (records.md), and
// the scenario's refusal says why and how to read the one meant (a re-audit's `tip_z_mm` beside
// `tip_z_m` read only "neither an output nor a coordinate"); a name that is no unit suffix gets
// no such hint.
TEST(UpdatingGlueTest, TwoColumnsSharingAShortNameAreNamedWhenRefused) {
  const updating::testing::Crane crane =
      updating::testing::LoadCrane(updating::testing::kReferenceScenario);
  Measurement record = updating::testing::SimulateExact(crane, 0.2, 50.0);
  const std::string output = crane.model->output_names().front();
  record.channels.front() = output + "_deg";
  const InputError shared = testing::CatchInputError(
      [&] { validation::RequireModelOutputs(record, "log.csv", *crane.model); });
  EXPECT_NE(shared.problem().find("--channel " + output + "=" + output + "_deg"), std::string::npos)
      << shared.problem();
  record.channels.front() = output + "_left";
  const InputError other = testing::CatchInputError(
      [&] { validation::RequireModelOutputs(record, "log.csv", *crane.model); });
  EXPECT_EQ(other.problem().find("unit suffix"), std::string::npos) << other.problem();
}

// A logger left running through a second test: held, the crane's 14 s decay (at rest from about
// 11 s), a 1 s reload, held, a second drop. The record is cut at the release and before the
// reload, which the applied release names in the file's time (identification's
// NextExcitationTest checks the search itself).
TEST(UpdatingGlueTest, ASecondTestInTheRecordIsCutOff) {
  const updating::testing::Crane crane =
      updating::testing::LoadCrane(updating::testing::kReferenceScenario);
  const Eigen::MatrixXd decay = updating::testing::SimulateExact(crane, 14.0, 100.0).values;
  const Eigen::Index n = decay.rows();
  Eigen::MatrixXd values(100 + n + 200 + n, decay.cols());
  values.topRows(100) = decay.row(0).replicate(100, 1);
  values.middleRows(100, n) = decay;
  for (int j = 0; j < 100; ++j) {  // a raised cosine back to the held level
    const double s = 0.5 * (1 - std::cos(M_PI * j / 100));
    values.row(100 + n + j) = (1 - s) * decay.row(n - 1) + s * decay.row(0);
  }
  values.middleRows(200 + n, 100) = decay.row(0).replicate(100, 1);
  values.bottomRows(n) = decay;
  std::mt19937_64 rng(1);
  std::normal_distribution<double> noise(0.0, 1e-5);  // the paper's sensors
  for (Eigen::Index j = 0; j < values.size(); ++j) values.data()[j] += noise(rng);
  Measurement record;
  record.channels = {"psi", "phi"};
  record.units = {"rad", "rad"};
  record.sample_interval_s = 0.01;
  record.values = values;
  const validation::AppliedRelease applied =
      validation::CutRecordAtRelease(&record, "two-tests.csv", {}, crane.excitation);
  EXPECT_EQ(applied.how, "detected");
  EXPECT_NEAR(applied.release_time_s, 1.0, 0.01);
  ASSERT_TRUE(applied.next_excitation_s.has_value());
  const double reload_s = 0.01 * static_cast<double>(100 + n);  // in the file's time
  EXPECT_GE(*applied.next_excitation_s, reload_s);
  EXPECT_LE(*applied.next_excitation_s, reload_s + 0.06);  // 3 noise std within 4 samples
  // Nothing of the reload is left: the record ends before it, in the cut record's time.
  EXPECT_LT(record.start_time_s + 0.01 * static_cast<double>(record.samples() - 1),
            *applied.next_excitation_s - applied.release_time_s);
  EXPECT_GT(record.samples(), 1300);  // the decay is kept
  EXPECT_NE(applied.next_excitation.find("a second excitation"), std::string::npos);
}

// A record cut 6 samples late (a noisy onset at a high rate is detected so far off): the
// placement follows the parabola past its 2-sample clamp, round after round, back to the
// release. Noise-free exact record: within a fiftieth of a sample.
TEST(UpdatingGlueTest, AReleaseDetectedSixSamplesLateIsPlacedBack) {
  const DetectedReleases setup(1.0, 1000.0);
  const auto& [crane, exact, settings] = std::tie(setup.crane, setup.exact, setup.settings);
  const double tau = exact.sample_interval_s;
  auto [records, best] = setup.CutLate(6);
  ASSERT_NE(best.termination, updating::UpdateResult::Termination::kFailure);
  const std::vector<std::string> lines =
      validation::PlaceDetectedReleases(*crane.model, &records, settings.options, &best);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_NE(lines[0].find("before the detected instant"), std::string::npos) << lines[0];
  // The cut left out samples 0-5; sample 6 is at 6 tau from the true release.
  EXPECT_NEAR(records[0].record.start_time_s, 6 * tau, 0.02 * tau);
  EXPECT_NEAR(best.tests[0].release_shift_s, -6 * tau, 0.02 * tau);
  EXPECT_NEAR(best.tests[0].release_shift_s, -6 * tau, best.tests[0].release_shift_std_s);
}

// A release known sharply: the noise-free crane at 100 Hz, weighted as 1e-5 rad of noise, pins
// it to 0.0024 samples, and a record cut 0.3 samples late must be placed back to that, not to
// what a parabola through half a sample either way says (0.01 samples, 4 of its std, off before).
TEST(UpdatingGlueTest, AReleaseIsPlacedToItsOwnStdWhereTheRecordPinsIt) {
  const DetectedReleases setup(2.0, 100.0);
  const auto& [crane, exact, settings] = std::tie(setup.crane, setup.exact, setup.settings);
  const double tau = exact.sample_interval_s;
  auto [records, best] = setup.CutLate(0.3);
  ASSERT_NE(best.termination, updating::UpdateResult::Termination::kFailure);
  const double detected_cost = best.final_cost;
  validation::PlaceDetectedReleases(*crane.model, &records, settings.options, &best);
  const double std_s = best.tests[0].release_shift_std_s;
  EXPECT_LT(std_s, 0.01 * tau);
  EXPECT_NEAR(best.tests[0].release_shift_s, -0.3 * tau, std_s);
  EXPECT_LT(best.final_cost, detected_cost);
  for (const char* name : {"c_alpha", "c_gamma", "c_eta", "c_theta", "d_alpha", "d_theta"}) {
    const double truth = crane.model->GetParameter(name);
    EXPECT_NEAR(best.Find(name).value, truth, best.Find(name).std) << name;  // noise-free
  }
}

// A release detected early, with rest samples inside the decay (a load drop's release placed by
// two of its four modes came 5.5 samples early): the parabola around it bends the wrong way, and
// the release was kept where detected (no parameter determined). The cost 1, 2, 4 and 8 samples
// either way finds the way back; noise-free, to within the release's std.
TEST(UpdatingGlueTest, AReleaseDetectedEarlyAmongRestSamplesIsPlacedBack) {
  const DetectedReleases setup(1.0, 100.0);
  const auto& [crane, exact, settings] = std::tie(setup.crane, setup.exact, setup.settings);
  const double tau = exact.sample_interval_s;
  constexpr int kRest = 50;  // 0.5 s at rest at the deflection, then the decay
  Measurement logged = exact;
  logged.values.resize(kRest + exact.samples(), exact.channel_count());
  logged.values.bottomRows(exact.samples()) = exact.values;
  for (int j = 0; j < kRest; ++j) logged.values.row(j) = exact.values.row(0);
  logged.start_time_s = 0;
  const double detected = (kRest - 5.5) * tau;  // the truth is kRest * tau
  std::vector<updating::TestRecord> records{
      setup.Test("early", identification::CutAtRelease(logged, detected, "early"))};
  updating::UpdateResult best = updating::UpdateModel(*crane.model, records, settings.options);
  ASSERT_NE(best.termination, updating::UpdateResult::Termination::kFailure);
  const std::vector<std::string> lines =
      validation::PlaceDetectedReleases(*crane.model, &records, settings.options, &best);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_NE(lines[0].find("the fit places the release"), std::string::npos) << lines[0];
  EXPECT_NEAR(best.tests[0].release_shift_s, 5.5 * tau,
              std::max(best.tests[0].release_shift_std_s, 1e-3 * tau));
  // Back at the release, the fit explains the record (noise-free: its residual, the integration's
  // error, is not white, so not credible, but no misfit).
  EXPECT_EQ(best.Find("c_theta").why_undetermined.find("does not explain"), std::string::npos)
      << best.Find("c_theta").why_undetermined;
  EXPECT_LT(best.Find("c_theta").relative_std, 0.3);
}

// The release's uncertainty widens a parameter's std; where the widened spread passes what the
// records determine, the parameter is no longer reported determined (it was, before).
TEST(UpdatingGlueTest, AReleaseUncertaintyThatWidensPastTheLimitLeavesTheParameterUndetermined) {
  updating::UpdateResult best;
  best.std_inflation = 1;
  const auto estimate = [](std::string name, double value, double std) {
    updating::ParameterEstimate p;
    p.name = std::move(name);
    p.value = value;
    p.std = std;
    p.relative_std = std / value;
    p.lower = 0.01 * value;
    p.upper = 100 * value;
    p.determined = true;
    p.log_scale = false;  // an interval of +-2 std
    return p;
  };
  best.parameters = {estimate("c_wide", 1000, 200), estimate("c_kept", 1000, 50),
                     estimate("d_untouched", 10, 2.5)};
  updating::UpdateOptions options;  // undetermined_relative_std 0.3
  // c_wide: sqrt(200^2 + 250^2) = 320, relative 0.32 > 0.3; c_kept: sqrt(50^2 + 100^2) = 112.
  validation::WidenForReleases({{"c_wide", 250.0 * 250.0}, {"c_kept", 100.0 * 100.0}}, options,
                               &best);
  const updating::ParameterEstimate& wide = best.Find("c_wide");
  EXPECT_NEAR(wide.std, 320.156, 1e-3);
  EXPECT_FALSE(wide.determined);
  EXPECT_NE(wide.why_undetermined.find("relative std 0.32"), std::string::npos)
      << wide.why_undetermined;
  EXPECT_NE(wide.why_undetermined.find("release"), std::string::npos) << wide.why_undetermined;
  EXPECT_EQ(best.undetermined, std::vector<std::string>{"c_wide"});
  const updating::ParameterEstimate& kept = best.Find("c_kept");
  EXPECT_NEAR(kept.std, 111.803, 1e-3);
  EXPECT_TRUE(kept.determined);
  EXPECT_NEAR(kept.interval_upper, 1000 + 2 * 111.803, 1e-2);  // the interval from the widened std
  EXPECT_EQ(best.Find("d_untouched").std, 2.5);
}

}  // namespace
}  // namespace mbid::app
