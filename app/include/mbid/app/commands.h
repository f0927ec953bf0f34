#pragma once

#include <optional>
#include <string>
#include <vector>

#include "mbid/identification/options.h"
#include "mbid/validation/record_import.h"

namespace mbid::app {

// Options every command shares.
struct CommonOptions {
  // No progress on standard error: --quiet, or standard error is no terminal (the contract)
  // and --progress is not given.
  bool quiet = false;
  std::string json_path;  // "" = none, "-" = standard output
  // Replace existing output files; `run`: an output folder an earlier run wrote.
  bool overwrite = false;
  validation::ImportOverrides import;  // --channel, --unit, --fill-gaps for measured files
  bool profile = false;  // --profile: profile-likelihood intervals (updating.profile.enabled)
};

// `mbid modes SCENARIO [--json FILE]`: the linearized model and its exact modes.
int RunModesCommand(const std::string& scenario_path, const CommonOptions& common);

// `mbid simulate SCENARIO -o FILE.h5 [--json FILE] [--export FILE]...`: a synthetic
// measurement from the model; each `--export` also writes the measured record for other tools,
// by extension: .uff/.unv (UFF58 ASCII), .uffb (UFF58b binary), .mat (MATLAB v5), .csv (time
// and channels, units in a comment: mbid's own CSV layout).
int RunSimulateCommand(const std::string& scenario_path, const std::string& output_path,
                       const CommonOptions& common,
                       const std::vector<std::string>& export_paths = {});

// `mbid campaign CAMPAIGN.yaml -o DIR [--workers N] [--resume]`: runs a campaign of virtual
// tests (or a design study) into DIR (docs/campaigns.md); under `mpirun -n K` the cases are
// spread over the ranks. `workers` = 0 chooses one per hardware thread (one per rank under
// MPI). Returns the exit code.
int RunCampaignCommand(const std::string& campaign_path, const std::string& output_dir, int workers,
                       bool resume, const CommonOptions& common);

// `mbid identify DATA [options] [-o FILE.h5] [--json FILE]`: the modes of a free-decay record.
int RunIdentifyCommand(const std::string& data_path,
                       const identification::IdentificationOptions& options,
                       const std::string& output_path, const CommonOptions& common);

// `mbid update SCENARIO DATA [DATA...] [-o FILE.h5] [--json FILE]`: tunes the scenario's joint
// parameters to the records (Route 1 start, Route 2 fit); the exit code follows the fit's
// termination (3 unless converged).
int RunUpdateCommand(const std::string& scenario_path, const std::vector<std::string>& data_paths,
                     const std::string& output_path, const CommonOptions& common);

// `mbid plan SCENARIO [DATA...] --candidates FILE.yaml [--json FILE]`: ranks candidate tests
// by the information they add to the recorded ones (docs/planning.md), best first.
int RunPlanCommand(const std::string& scenario_path, const std::vector<std::string>& data_paths,
                   const std::string& candidates_path, const CommonOptions& common);

// `mbid structure SCENARIO DATA [DATA...] [--max-rigid K] [-o FILE.h5] [--json FILE]`: ranks
// the candidate structures (the model, the model with up to `max_rigid` compliant coordinates
// made rigid, the scenario's `structure.alternatives`) by BIC of their Route 2 fits
// (docs/structure.md); `threads` fits side by side (0: one per core). -o also writes the report
// beside the file (FILE.md, FILE-criteria.png). Unset `max_rigid`: 1, or 0 where the machine
// has one compliant coordinate only.
int RunStructureCommand(const std::string& scenario_path,
                        const std::vector<std::string>& data_paths, std::optional<int> max_rigid,
                        int threads, const std::string& output_path, const CommonOptions& common);

}  // namespace mbid::app
