// The whole chain on the built-in reference crane through <mbid/mbid.h>: simulate its load-drop
// test, identify the modes, tune the joint parameters to the record, then run the validation
// cycle in memory. Usage: crane_cycle [SCENARIO]
#include <mbid/mbid.h>

#include <cstdio>
#include <string>

int main(int argc, char** argv) {
  try {
    const std::string path = argc > 1 ? argv[1] : mbid::DefaultScenarioPath();
    const mbid::Scenario scenario = mbid::LoadScenario(path);
    std::printf("scenario %s (%s)\n", scenario.name.c_str(), path.c_str());

    const mbid::Measurement record = mbid::Simulate(scenario);
    std::printf("simulated %d samples x %d channels, %g s apart\n", record.samples(),
                record.channel_count(), record.sample_interval_s);

    const mbid::ModalResult modes = mbid::Identify(record);
    for (const auto& mode : modes.modes) {
      std::printf("mode %.4f Hz, decay %.4f 1/s, damping ratio %.4f\n", mode.frequency_hz,
                  mode.decay_rate_per_s, mode.damping_ratio);
    }

    const mbid::UpdateResult tuned = mbid::Update(scenario, {record});
    for (const auto& [name, parameter] : tuned.parameters) {
      std::printf("%s = %.6g +- %.2g %s%s\n", name.c_str(), parameter.value, parameter.std,
                  parameter.units.c_str(), parameter.determined ? "" : " (undetermined)");
    }

    const mbid::ValidationResult cycle = mbid::RunValidationCycle(scenario);
    std::printf("verdict: %s\n", mbid::ToString(cycle.verdict).c_str());
    for (const std::string& reason : cycle.reasons) std::printf("  because %s\n", reason.c_str());
    return cycle.verdict == mbid::Verdict::kFailed ? 1 : 0;
  } catch (const mbid::InputError& error) {
    std::fprintf(stderr, "%s\n", error.what());
    return 2;
  } catch (const mbid::NumericalError& error) {
    std::fprintf(stderr, "%s\n", error.what());
    return 3;
  }
}
