#include <fmt/format.h>

#include <cmath>
#include <iostream>

#include "mbid/app/commands.h"
#include "mbid/common/error.h"
#include "mbid/common/hdf5_io.h"
#include "mbid/common/json_io.h"
#include "mbid/identification/identify.h"
#include "mbid/records/records.h"
#include "mbid/validation/identification_settings.h"
#include "mbid/validation/release_cut.h"
#include "mbid/validation/scenario.h"

namespace mbid::app {
using validation::DescribeImport;
using validation::ImportReportToJson;
using validation::MergeImportOptions;

int RunIdentifyCommand(const std::string& data_path,
                       const identification::IdentificationOptions& given,
                       const std::string& output_path, const CommonOptions& common) {
  given.Validate("command line");  // before reading a possibly large file
  records::ImportReport import;
  Measurement measurement = records::ImportMeasurement(
      data_path, MergeImportOptions({}, common.import, nullptr), &import);
  if (common.import.end_time_s) {
    validation::EndRecordAt(&measurement, *common.import.end_time_s, data_path, "--end-time-s");
  }
  const std::string scenario = validation::ReadRecordScenario(data_path);
  // A record mbid simulated carries its test: after a forcing (an impulse, a burst) the free
  // decay starts where the forcing ends, as `mbid run` analyses it.
  std::string said;
  const identification::IdentificationOptions options =
      validation::RecordFileOptions(scenario, data_path, given, &said);
  if (!said.empty() && !common.quiet) std::cerr << fmt::format("mbid: {}: {}\n", data_path, said);
  if (!common.quiet) {
    std::cerr << fmt::format("mbid: {}: {}\n", data_path, DescribeImport(import));
    std::cerr << fmt::format("mbid: identifying {} ({} samples x {} channels, {} Hz, {})\n",
                             data_path, measurement.samples(), measurement.channel_count(),
                             1.0 / measurement.sample_interval_s,
                             identification::MethodName(options.method));
  } else {
    for (const std::string& w : import.warnings)
      std::cerr << "mbid: warning: " + data_path + ": " + w + "\n";
  }
  identification::ModalResult result = identification::Identify(measurement, options, data_path);
  validation::AddImportDoubts(import, &result);

  std::unique_ptr<H5Writer> file;
  if (!output_path.empty()) {
    file = std::make_unique<H5Writer>(output_path);
    file->WriteMeasurement(measurement);
    if (!scenario.empty()) file->WriteScenarioYaml(scenario);
    identification::WriteModalResult(*file, result);
  }
  if (!common.json_path.empty()) {
    nlohmann::json summary = identification::ModalResultToJson(result);
    summary["import"] = ImportReportToJson(import);
    WriteJson(summary, common.json_path);
  }
  if (file) file->Commit();  // only when everything else succeeded

  for (const std::string& warning : result.warnings) {
    std::cerr << "mbid: warning: " << warning << "\n";  // also under --quiet
  }
  // Unreliable results are said even with --quiet: dampers get sized on these numbers.
  for (const std::string& reason : result.reasons) {
    std::cerr << "mbid: warning: result unreliable: " << reason << "\n";
  }
  if (common.json_path != "-") {
    std::cout << fmt::format(
        "{} modes ({}, model order {}, effective rank {}{}){}\n", result.modes.size(),
        result.method, result.model_order, result.effective_rank,
        result.decimation > 1 ? fmt::format(", decimation {}", result.decimation) : "",
        result.reliable ? "" : " -- UNRELIABLE, see the warnings");
    std::cout << fmt::format(
        "free decay from {:.6g} s ({}){}\n", result.release_time_s, result.release,
        result.start_time_s > result.release_time_s + 0.5 * result.sample_interval_s
            ? fmt::format(", analysed from {:.6g} s", result.start_time_s)
            : "");
    std::cout << fmt::format("{:>4} {:>13} {:>12} {:>16} {:>12} {:>13}\n", "mode", "frequency_hz",
                             "std_hz", "decay_rate_per_s", "std_per_s", "damping_ratio");
    for (size_t k = 0; k < result.modes.size(); ++k) {
      const identification::IdentifiedMode& mode = result.modes[k];
      std::cout << fmt::format(
          "{:>4} {:>13.6f} {:>12.2e} {:>16.6f} {:>12.2e} {:>13.6f}{}{}\n", k + 1, mode.frequency_hz,
          mode.std_frequency_hz, mode.decay_rate_per_s, mode.std_decay_rate_per_s,
          mode.damping_ratio, mode.significant ? "" : "  (not significant)",
          mode.combination.empty() ? "" : "  (combination tone " + mode.combination + ")");
    }
    for (size_t c = 0; c < static_cast<size_t>(result.drift_per_s.size()); ++c) {
      std::cout << fmt::format("linear drift removed from {}: {:.4g} {}/s\n", result.channels[c],
                               result.drift_per_s[static_cast<Eigen::Index>(c)], result.units[c]);
    }
    for (size_t c = 0; c < result.channels.size(); ++c) {
      std::cout << fmt::format("correlation K({}) in the analysed band = {:.4f}\n",
                               result.channels[c],
                               result.correlation[static_cast<Eigen::Index>(c)]);
    }
  }
  return 0;
}

}  // namespace mbid::app
