// Route 1's glue: with more identified modes than coordinates, eq. 7 runs on the main ones (the
// paper chose its four "main" modes among all it found).
#include <gtest/gtest.h>

#include "../updating/crane_fixture.h"
#include "mbid/model/linear_model.h"
#include "mbid/updating/settings.h"
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

}  // namespace
}  // namespace mbid::app
