// The mbid command: parses flags, calls the libraries, maps failures to the exit codes of
// docs/interfaces.md (2 invalid input, 3 numerical failure, 1 anything else).
#include <glog/logging.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cmath>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "mbid/app/commands.h"
#include "mbid/app/exit_code.h"
#include "mbid/app/run_cycle.h"
#include "mbid/app/version.h"
#include "mbid/common/atomic_file.h"
#include "mbid/common/error.h"
#include "mbid/common/interrupt_cleanup.h"
#include "mbid/identification/options.h"
#include "mbid/records/records.h"
#include "mbid/validation/scenario.h"

namespace {

// Flags for the measured files of identify, update and run (docs/records.md).
struct ImportFlags {
  std::vector<std::string> channels;
  std::vector<std::string> units;
  std::string fill_gaps;
  std::string time_unit;
  std::optional<double> sample_rate_hz;
  std::string release;
  std::optional<double> release_time_s;
  std::optional<double> end_time_s;
};

void AddImportFlags(CLI::App* command, ImportFlags* flags) {
  command
      ->add_option("--channel", flags->channels,
                   "Record channel from a file column: NAME=COLUMN (column name or number among "
                   "the data columns); repeatable")
      ->allow_extra_args(false);
  command
      ->add_option("--unit", flags->units,
                   "Unit of a file column (or record channel): COLUMN=UNIT, e.g. Zeit=ms; "
                   "repeatable")
      ->allow_extra_args(false);
  command
      ->add_option("--fill-gaps", flags->fill_gaps,
                   "Empty or NaN cells: linear (interpolate and report) or none (refuse)")
      ->check(CLI::IsMember({"linear", "none"}));
  command->add_option("--time-unit", flags->time_unit,
                      "Unit of the file's time column, over what the file says, e.g. ms");
  command->add_option("--sample-rate-hz", flags->sample_rate_hz,
                      "For files without a time column: samples at j / rate, Hz");
  CLI::Option* release =
      command
          ->add_option("--release", flags->release,
                       "none: the record is the free decay (default: find where it starts)")
          ->check(CLI::IsMember({"none", "detect"}));
  command
      ->add_option("--release-time-s", flags->release_time_s,
                   "The free decay starts at this time of the record, s")
      ->excludes(release);
  command->add_option("--end-time-s", flags->end_time_s,
                      "The test ends at this time of the record, s (what follows is another "
                      "test's)");
}

mbid::validation::ImportOverrides MakeOverrides(const ImportFlags& flags) {
  mbid::validation::ImportOverrides overrides;
  overrides.channel_columns = mbid::validation::ParseAssignments(flags.channels, "--channel");
  for (const auto& [column, unit] : mbid::validation::ParseAssignments(flags.units, "--unit")) {
    overrides.units[column] = unit;
  }
  if (!flags.fill_gaps.empty()) {
    overrides.fill_gaps =
        mbid::validation::ParseGapFill(flags.fill_gaps, "command line", "--fill-gaps");
  }
  overrides.time_unit = flags.time_unit;
  if (flags.sample_rate_hz &&
      !(std::isfinite(*flags.sample_rate_hz) && *flags.sample_rate_hz > 0)) {
    throw mbid::InputError("command line", "--sample-rate-hz",
                           std::to_string(*flags.sample_rate_hz), "a finite sample rate > 0 Hz");
  }
  overrides.sample_rate_hz = flags.sample_rate_hz;
  overrides.release_none = flags.release == "none";
  for (const auto& [flag, time] : {std::pair{"--release-time-s", flags.release_time_s},
                                   std::pair{"--end-time-s", flags.end_time_s}}) {
    if (time && !std::isfinite(*time)) {
      throw mbid::InputError("command line", flag, std::to_string(*time), "a finite time in s");
    }
  }
  overrides.release_time_s = flags.release_time_s;
  overrides.end_time_s = flags.end_time_s;
  return overrides;
}

int Main(int argc, char** argv) {
  CLI::App app{
      "mbid: simulate machine structures, identify their vibration modes from "
      "free-decay records, and tune joint stiffness and damping to match.",
      "mbid"};
  app.set_version_flag("--version", std::string("mbid ") + mbid::app::kVersion);
  app.require_subcommand(1);
  app.fallthrough();
  mbid::app::CommonOptions common;
  ImportFlags import_flags;
  app.add_flag("-q,--quiet", common.quiet, "No progress on standard error");
  bool progress = false;
  app.add_flag("--progress", progress,
               "Progress on standard error also where it is no terminal (a log file)");
  app.add_flag("--overwrite", common.overwrite, "Replace output files that exist");

  std::string scenario_path;
  CLI::App* modes = app.add_subcommand(
      "modes", "Linearized model (M, D, C, H) at the unloaded rest and its exact modes");
  modes->add_option("SCENARIO", scenario_path, "Scenario YAML file")->required();
  modes->add_option("--json", common.json_path, "Write the JSON summary to FILE ('-' = stdout)");

  std::string output_path;
  CLI::App* simulate = app.add_subcommand(
      "simulate", "Simulate the scenario's test and write a measurement file (HDF5)");
  simulate->add_option("SCENARIO", scenario_path, "Scenario YAML file")->required();
  simulate->add_option("-o,--output", output_path, "Measurement file to write (.h5)")->required();
  simulate->add_option("--json", common.json_path, "Write the JSON summary to FILE ('-' = stdout)");
  std::vector<std::string> export_paths;
  simulate->add_option("--export", export_paths,
                       "Also write the measured record as FILE (repeatable): .uff/.unv UFF58 "
                       "ASCII, .uffb UFF58 binary, .mat MATLAB v5, .csv time and channels");

  std::string output_dir;
  CLI::App* run = app.add_subcommand(
      "run", "The validation cycle on a scenario, with its report (default: the reference crane)");
  run->add_option("SCENARIO", scenario_path, "Scenario YAML file")
      ->default_str("scenarios/reference-crane.yaml");
  run->add_option("-o,--output", output_dir, "Results folder (default results/<scenario name>)");
  run->add_flag("--overwrite", common.overwrite,
                "Replace the results folder if an earlier mbid run wrote it (never other folders)");
  AddImportFlags(run, &import_flags);
  run->add_flag("--profile", common.profile,
                "Profile-likelihood intervals of the tuned parameters (updating.profile)");

  std::string campaign_path;
  int campaign_workers = 0;
  bool campaign_resume = false;
  CLI::App* campaign = app.add_subcommand(
      "campaign", "Run a campaign of virtual tests or a design study (threads; MPI under mpirun)");
  campaign->add_option("CAMPAIGN", campaign_path, "Campaign YAML file")->required();
  campaign->add_option("-o,--output", output_dir, "Results folder")->required();
  campaign
      ->add_option("--workers,--threads", campaign_workers,
                   "Worker threads (default: one per core)")
      ->check(CLI::Range(1, 1 << 20));
  campaign->add_flag("--resume", campaign_resume, "Finish a campaign this folder holds");

  std::string data_path;
  mbid::identification::IdentificationOptions identify_options;
  std::string identify_method = "hankel-nls";
  std::string identify_offset = "fit";
  CLI::App* identify = app.add_subcommand(
      "identify", "Identify the modes of a free-decay record (HDF5, CSV or logger export)");
  identify->add_option("DATA", data_path, "Measurement file (.h5, .csv, .txt, .mat, .uff, .lvm)")
      ->required();
  AddImportFlags(identify, &import_flags);
  identify->add_option("-o,--output", output_path, "Write /measurement and /identification (.h5)");
  identify->add_option("--json", common.json_path, "Write the JSON summary to FILE ('-' = stdout)");
  identify
      ->add_option("--method", identify_method, "hankel-nls (default) or prony-svd (the paper's)")
      ->check(CLI::IsMember(mbid::identification::MethodNames()));
  identify->add_option("--order", identify_options.prony.order, "prony-svd: order p of eq. 3")
      ->capture_default_str();
  identify->add_option("--channels", identify_options.channels, "Channels to analyse (default all)")
      ->delimiter(',');
  identify->add_option("--window-start-s", identify_options.window_start_s,
                       "Analyse from this time, s");
  identify->add_option("--window-end-s", identify_options.window_end_s,
                       "Analyse up to this time, s");
  identify->add_option("--offset", identify_offset, "Constant offset: none, mean or fit (default)")
      ->check(CLI::IsMember({"none", "mean", "fit"}));
  identify->add_option("--decimate", identify_options.decimation, "Decimation factor for the poles")
      ->capture_default_str();
  identify->add_option("--min-frequency-hz", identify_options.min_frequency_hz,
                       "Step 5: lowest frequency, Hz");
  identify->add_option("--max-frequency-hz", identify_options.max_frequency_hz,
                       "Step 5: highest frequency, Hz (0 = Nyquist)");
  identify
      ->add_option("--max-damping-ratio", identify_options.max_damping_ratio,
                   "Step 5: largest damping ratio")
      ->capture_default_str();
  identify->add_option("--max-modes", identify_options.max_modes, "At most this many modes")
      ->capture_default_str();
  identify
      ->add_option("--extra-orders", identify_options.hankel.extra_orders,
                   "hankel-nls: also restart from this many orders above the signal order "
                   "(low-SNR records)")
      ->capture_default_str();

  std::string identify_backbone = "clusters";
  identify
      ->add_option("--backbone", identify_backbone,
                   "Backbones (frequency and damping against amplitude): clusters (default: "
                   "modes drifting with amplitude), always (every mode) or never")
      ->check(CLI::IsMember({"clusters", "always", "never"}));
  identify->add_flag("--remove-drift", identify_options.remove_drift,
                     "Fit and subtract a linear drift per channel with the modes");
  identify->add_flag("--keep-clipped{false}", identify_options.skip_clipped,
                     "Analyse a record clipped at its start from the release, not from after "
                     "its last clipped sample");

  std::vector<std::string> update_data;
  CLI::App* update = app.add_subcommand(
      "update", "Tune the joints' stiffness and damping to measurements (Route 1, then Ceres)");
  update->add_option("SCENARIO", scenario_path, "Scenario YAML file")->required();
  update
      ->add_option("DATA", update_data,
                   "Measurement files (.h5, .csv, .txt, .mat, .uff, .lvm), one per test")
      ->required();
  AddImportFlags(update, &import_flags);
  update->add_option("-o,--output", output_path, "Write /measurement, /scenario, /updating (.h5)");
  update->add_option("--json", common.json_path, "Write the JSON summary to FILE ('-' = stdout)");
  update->add_flag("--profile", common.profile,
                   "Profile-likelihood intervals of the tuned parameters (updating.profile)");

  std::vector<std::string> plan_data;
  std::string plan_candidates;
  CLI::App* plan = app.add_subcommand(
      "plan", "Rank candidate next tests by the information they add (D-optimal design)");
  plan->add_option("SCENARIO", scenario_path, "Scenario YAML file")->required();
  plan->add_option("DATA", plan_data,
                   "Recorded tests (.h5, .csv, .txt, .mat, .uff, .lvm), one per test; none: "
                   "plan from the scenario's values");
  plan->add_option("--candidates", plan_candidates, "Candidate tests (YAML, docs/planning.md)")
      ->required();
  AddImportFlags(plan, &import_flags);
  plan->add_option("--json", common.json_path, "Write the JSON summary to FILE ('-' = stdout)");

  std::vector<std::string> structure_data;
  std::optional<int> structure_max_rigid;
  int structure_threads = 0;
  CLI::App* structure = app.add_subcommand(
      "structure", "Rank structures (which joints really move) by BIC of their Route 2 fits");
  structure->add_option("SCENARIO", scenario_path, "Scenario YAML file")->required();
  structure
      ->add_option("DATA", structure_data,
                   "Measurement files (.h5, .csv, .txt, .mat, .uff, .lvm), one per test")
      ->required();
  AddImportFlags(structure, &import_flags);
  structure->add_option(
      "--max-rigid", structure_max_rigid,
      "Candidates with up to K compliant coordinates made rigid (default 1; 0 for "
      "a machine of one compliant coordinate)");
  structure->add_option("--threads", structure_threads,
                        "Fits side by side (default: one per core)");
  structure->add_option("-o,--output", output_path,
                        "Write /measurement, /scenario, /structure (.h5) and the report beside it");
  structure->add_option("--json", common.json_path,
                        "Write the JSON summary to FILE ('-' = stdout)");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    if (error.get_exit_code() == 0) return app.exit(error);  // --help, --version
    std::cerr << "mbid: error: command line: " << mbid::OneLine(error.what())
              << "; expected see mbid --help\n";
    return static_cast<int>(mbid::app::ExitCode::kInvalidInput);
  }
  // Progress goes to a terminal only: a script or log sees warnings and errors alone.
  if (!progress && ::isatty(STDERR_FILENO) == 0) common.quiet = true;
  common.import = MakeOverrides(import_flags);
  // No output may replace an input or another output. Only one command's lists are filled.
  std::vector<mbid::NamedFile> inputs{{"SCENARIO", scenario_path}, {"DATA", data_path}};
  for (const auto* data : {&update_data, &plan_data, &structure_data}) {
    for (const std::string& path : *data) inputs.push_back({"DATA", path});
  }
  inputs.push_back({"--candidates", plan_candidates});
  std::vector<mbid::NamedFile> outputs{{"-o", output_path}, {"--json", common.json_path}};
  for (const std::string& path : export_paths) outputs.push_back({"--export", path});
  mbid::CheckOutputsAreNew(inputs, outputs);
  mbid::CheckOutputsReplaceable(outputs, common.overwrite);  // before the work, not after
  mbid::records::CheckHdf5OutputName(output_path);
  if (run->parsed()) {
    if (scenario_path.empty()) scenario_path = mbid::validation::DefaultScenarioPath();
    return mbid::app::RunValidationCycle(scenario_path, output_dir, common);
  }
  if (campaign->parsed()) {
    return mbid::app::RunCampaignCommand(campaign_path, output_dir, campaign_workers,
                                         campaign_resume, common);
  }
  // -o, --json and --export appear together when the command succeeds, or none of them.
  mbid::OutputSet outputs_together;
  const int code = [&] {
    if (identify->parsed()) {
      mbid::identification::ParseMethod(identify_method, &identify_options.method);
      mbid::identification::ParseBackboneMode(identify_backbone, &identify_options.backbone);
      if (common.import.release_none) {
        identify_options.release = mbid::identification::ReleaseMode::kNone;
      } else if (common.import.release_time_s) {
        identify_options.release = mbid::identification::ReleaseMode::kGiven;
        identify_options.release_time_s = *common.import.release_time_s;
      }
      identify_options.offset =
          identify_offset == "none"   ? mbid::identification::OffsetRemoval::kNone
          : identify_offset == "mean" ? mbid::identification::OffsetRemoval::kMean
                                      : mbid::identification::OffsetRemoval::kFit;
      return mbid::app::RunIdentifyCommand(data_path, identify_options, output_path, common);
    }
    if (update->parsed()) {
      return mbid::app::RunUpdateCommand(scenario_path, update_data, output_path, common);
    }
    if (plan->parsed()) {
      return mbid::app::RunPlanCommand(scenario_path, plan_data, plan_candidates, common);
    }
    if (structure->parsed()) {
      return mbid::app::RunStructureCommand(scenario_path, structure_data, structure_max_rigid,
                                            structure_threads, output_path, common);
    }
    if (modes->parsed()) return mbid::app::RunModesCommand(scenario_path, common);
    if (simulate->parsed()) {
      return mbid::app::RunSimulateCommand(scenario_path, output_path, common, export_paths);
    }
    return static_cast<int>(mbid::app::ExitCode::kOther);
  }();
  if (code == 0) outputs_together.Commit();
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  // First, before any thread exists: SIGINT/SIGTERM then remove unfinished outputs.
  mbid::InstallInterruptCleanup();
  // Ceres logs a fit stopped by a failed simulation (an "E..." line, after glog's own warning
  // about its set-up); mbid reports what failed itself, in its own words.
  FLAGS_minloglevel = google::GLOG_FATAL;
  google::InitGoogleLogging("mbid");
  try {
    return Main(argc, argv);
  } catch (const mbid::InputError& error) {
    std::cerr << "mbid: error: " << error.what() << "\n";
    return static_cast<int>(mbid::app::ExitCode::kInvalidInput);
  } catch (const mbid::NumericalError& error) {
    std::cerr << "mbid: numerical failure: " << error.what() << "\n";
    return static_cast<int>(mbid::app::ExitCode::kNumericalFailure);
  } catch (const std::exception& error) {
    std::cerr << "mbid: failure: " << mbid::OneLine(error.what()) << "\n";
    return static_cast<int>(mbid::app::ExitCode::kOther);
  }
}
