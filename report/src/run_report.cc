#include "mbid/report/run_report.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <sstream>

#include "mbid/report/gnuplot.h"
#include "mbid/updating/profile.h"
#include "mbid/updating/result_io.h"

namespace mbid::report {
namespace {

std::string Path(const std::string& folder, const std::string& name) {
  return (std::filesystem::path(folder) / name).string();
}

const char* kRecordStyle = "points pt 7 ps 0.35 lc rgb '#1f77b4'";

}  // namespace

Figure MakeRecordFigure(const Measurement& measured, const Measurement* exact,
                        const std::string& exact_label, int channel, const ReleaseMark* release) {
  Figure figure;
  const std::string& name = measured.channels[channel];
  figure.title = fmt::format("Test record: {}", name);
  figure.x_label = "time, s";
  figure.y_label = fmt::format("{}, {}", name, measured.units[channel]);
  const Eigen::VectorXd t = measured.CalcTime();
  figure.series.push_back({"record", t, measured.values.col(channel), kRecordStyle});
  if (exact != nullptr) {
    figure.series.push_back(
        {exact_label, t, exact->values.col(channel), "lines lw 1.5 lc rgb '#d62728'"});
  }
  if (release != nullptr) {
    figure.marks.push_back(
        {release->time_s,
         fmt::format("release ({}) at {:.6g} s: t = 0 of the test", release->how, release->time_s),
         "#2ca02c"});
  }
  return figure;
}

std::string DrawRecordFigure(const std::string& folder, const Measurement& measured,
                             const Measurement* exact, const std::string& exact_label, int channel,
                             const ReleaseMark* release) {
  const std::string file = fmt::format("record_{}.png", measured.channels[channel]);
  DrawFigure(MakeRecordFigure(measured, exact, exact_label, channel, release), Path(folder, file));
  return file;
}

std::string DrawSpectrumFigure(const std::string& folder,
                               const identification::ModalResult& result) {
  // No spectrum (an overdamped machine's identification found nothing to show one with).
  if (!result.has_spectrum || result.spectrum.frequency_hz.size() < 2) return "";
  Figure figure;
  figure.title = "Amplitude spectra (step 1), identified frequencies marked";
  figure.x_label = "frequency, Hz";
  figure.y_label = fmt::format("amplitude, {}", result.units.empty() ? "rad" : result.units[0]);
  figure.log_y = true;
  // Up to twice the highest identified frequency (at least 5 Hz), within the spectrum.
  double f_max = 5.0;
  for (const auto& mode : result.modes) f_max = std::max(f_max, 2 * mode.frequency_hz);
  const Eigen::VectorXd& f = result.spectrum.frequency_hz;
  Eigen::Index bins = 0;
  while (bins < f.size() && f[bins] <= f_max) ++bins;
  const char* colors[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd"};
  double floor = std::numeric_limits<double>::infinity(), top = 0;
  for (size_t c = 0; c < result.channels.size(); ++c) {
    // Bin 0 holds the offset; the log axis starts above the smallest positive amplitude.
    Eigen::VectorXd a = result.spectrum.amplitude.col(static_cast<Eigen::Index>(c)).head(bins);
    for (Eigen::Index i = 1; i < bins; ++i) {
      if (a[i] > 0) floor = std::min(floor, a[i]);
      top = std::max(top, a[i]);
    }
    figure.series.push_back({result.channels[c], f.segment(1, bins - 1), a.segment(1, bins - 1),
                             fmt::format("lines lw 1.3 lc rgb '{}'", colors[c % 4])});
  }
  for (size_t k = 0; k < result.modes.size(); ++k) {
    const double fk = result.modes[k].frequency_hz;
    Eigen::VectorXd x(2), y(2);
    x << fk, fk;
    y << std::max(floor, top * 1e-6), top;
    figure.series.push_back(
        {k == 0 ? "identified modes" : "", x, y, "lines dt 2 lw 1 lc rgb '#555555'"});
  }
  DrawFigure(figure, Path(folder, "spectrum.png"));
  return "spectrum.png";
}

std::string DrawReconstructionFigure(const std::string& folder, const Measurement& measured,
                                     const identification::ModalResult& result, int channel) {
  Figure figure;
  const std::string& name = result.channels[channel];
  const int column = measured.FindChannel(name);
  figure.title = fmt::format("{}: record and modal reconstruction (K = {:.4f})", name,
                             result.correlation[channel]);
  figure.x_label = "time, s";
  figure.y_label = fmt::format("{}, {}", name, result.units[channel]);
  const Eigen::VectorXd t_all = measured.CalcTime();
  const int first = static_cast<int>(
      std::lround((result.start_time_s - measured.start_time_s) / measured.sample_interval_s));
  const Eigen::VectorXd t = t_all.segment(first, result.samples);
  figure.series.push_back(
      {"record", t, measured.values.col(column).segment(first, result.samples), kRecordStyle});
  figure.series.push_back({fmt::format("reconstruction ({} modes)", result.modes.size()), t,
                           result.reconstruction.col(channel), "lines lw 1.5 lc rgb '#d62728'"});
  const std::string file = fmt::format("reconstruction_{}.png", name);
  DrawFigure(figure, Path(folder, file));
  return file;
}

std::string DrawStabilizationFigure(const std::string& folder,
                                    const identification::ModalResult& result) {
  Figure figure;
  figure.title = "Stabilization diagram: poles per model order (identified modes dashed)";
  figure.x_label = "frequency, Hz";
  figure.y_label = "model order";
  // The band of the identified modes: up to twice the highest (at least 5 Hz).
  double f_max = 5.0;
  for (const auto& mode : result.modes) f_max = std::max(f_max, 2 * mode.frequency_hz);
  std::vector<double> fs, os, fu, ou;
  for (const auto& order : result.stabilization) {
    for (size_t k = 0; k < order.lambda.size(); ++k) {
      const double f = order.lambda[k].imag() / (2 * M_PI);
      if (f <= 0 || f > f_max) continue;
      (order.stable[k] ? fs : fu).push_back(f);
      (order.stable[k] ? os : ou).push_back(order.order);
    }
  }
  auto to_vector = [](const std::vector<double>& v) {
    return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
  };
  if (!fu.empty()) {
    figure.series.push_back(
        {"pole", to_vector(fu), to_vector(ou), "points pt 6 ps 0.6 lc rgb '#999999'"});
  }
  if (!fs.empty()) {
    figure.series.push_back(
        {"stable pole", to_vector(fs), to_vector(os), "points pt 7 ps 0.6 lc rgb '#1f77b4'"});
  }
  for (size_t k = 0; k < result.modes.size(); ++k) {
    Eigen::VectorXd x(2), y(2);
    x << result.modes[k].frequency_hz, result.modes[k].frequency_hz;
    double lowest = 1e9, highest = 0;
    for (const auto& order : result.stabilization) {
      lowest = std::min<double>(lowest, order.order);
      highest = std::max<double>(highest, order.order);
    }
    y << lowest, highest;
    figure.series.push_back(
        {k == 0 ? "identified modes" : "", x, y, "lines dt 2 lc rgb '#d62728'"});
  }
  if (figure.series.empty()) return "";
  DrawFigure(figure, Path(folder, "stabilization.png"));
  return "stabilization.png";
}

Figure MakeBackboneFigure(const identification::ModalResult& result, int k, bool damping) {
  const identification::IdentifiedMode& mode = result.modes.at(static_cast<size_t>(k));
  const identification::Backbone& backbone = mode.backbone.value();
  // The amplitude is in the unit of the mode's largest channel (backbone.h).
  Eigen::Index largest = 0;
  if (mode.amplitude.size() > 0) mode.amplitude.maxCoeff(&largest);
  const std::string unit = static_cast<size_t>(largest) < result.units.size()
                               ? result.units[static_cast<size_t>(largest)]
                               : std::string("rad");
  Figure figure;
  figure.title = fmt::format("Mode {} ({:.4g} Hz): {} against amplitude (backbone)", k + 1,
                             mode.frequency_hz, damping ? "damping ratio" : "frequency");
  figure.x_label = fmt::format("amplitude, {}", unit);
  figure.y_label = damping ? "damping ratio, 1" : "frequency, Hz";
  figure.pad_x = true;
  figure.key = "top left box opaque";
  const auto add = [&figure, damping](const identification::BackboneCurve& curve,
                                      const std::string& title, const std::string& style) {
    const auto vector = [](const std::vector<double>& v) {
      return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()))
          .eval();
    };
    PlotSeries series{title, vector(curve.amplitude),
                      vector(damping ? curve.damping_ratio : curve.frequency_hz), style};
    series.y_error = vector(damping ? curve.std_damping_ratio : curve.std_frequency_hz);
    figure.series.push_back(series);
  };
  add(backbone, "sliding-window fits (8 periods), +- 1 std",
      "yerrorbars pt 7 ps 0.7 lc rgb '#1f77b4'");
  if (backbone.hilbert) {
    add(*backbone.hilbert, "Hilbert transform (4 periods), +- 1 std",
        "yerrorbars pt 6 ps 0.7 lc rgb '#d62728'");
  }
  return figure;
}

std::vector<std::string> DrawBackboneFigures(const std::string& folder,
                                             const identification::ModalResult& result) {
  std::vector<std::string> files;
  for (size_t k = 0; k < result.modes.size(); ++k) {
    if (!result.modes[k].backbone || result.modes[k].backbone->frequency_hz.empty()) continue;
    for (const bool damping : {false, true}) {
      const std::string file =
          fmt::format("backbone_{}_{}.png", damping ? "damping" : "frequency", k + 1);
      DrawFigure(MakeBackboneFigure(result, static_cast<int>(k), damping), Path(folder, file));
      files.push_back(file);
    }
  }
  return files;
}

std::string BackboneMarkdown(const identification::ModalResult& result) {
  std::ostringstream out;
  for (size_t k = 0; k < result.modes.size(); ++k) {
    if (!result.modes[k].backbone) continue;
    const identification::Backbone& b = *result.modes[k].backbone;
    out << fmt::format("- Mode {} ({:.4g} Hz): ", k + 1, result.modes[k].frequency_hz);
    if (b.frequency_hz.empty()) {
      out << "too short for a backbone window.\n";
      continue;
    }
    const auto [f_low, f_high] = std::minmax_element(b.frequency_hz.begin(), b.frequency_hz.end());
    const auto [z_low, z_high] =
        std::minmax_element(b.damping_ratio.begin(), b.damping_ratio.end());
    const auto [a_low, a_high] = std::minmax_element(b.amplitude.begin(), b.amplitude.end());
    out << fmt::format(
        "{} window{} from amplitude {:.3g} to {:.3g}: frequency {:.4g} to {:.4g} Hz, damping "
        "ratio {:.3g} to {:.3g}; {} (chi-square per degree of freedom {:.3g})",
        b.frequency_hz.size(), b.frequency_hz.size() == 1 ? "" : "s", *a_high, *a_low, *f_low,
        *f_high, *z_low, *z_high,
        b.amplitude_dependent ? "**depends on amplitude**" : "no drift beyond the noise",
        b.spread_chi_square_per_dof);
    if (b.hilbert) {
      const auto [h_low, h_high] =
          std::minmax_element(b.hilbert->frequency_hz.begin(), b.hilbert->frequency_hz.end());
      out << fmt::format("; Hilbert transform: {} window{}, frequency {:.4g} to {:.4g} Hz",
                         b.hilbert->frequency_hz.size(),
                         b.hilbert->frequency_hz.size() == 1 ? "" : "s", *h_low, *h_high);
    }
    out << ".\n";
  }
  return out.str();
}

std::string ModalTableMarkdown(const identification::ModalResult& result,
                               const std::vector<ReferenceMode>* reference,
                               const std::string& reference_label) {
  std::ostringstream out;
  // The paper's mean amplitude: the envelope A e^{-beta t} averaged over the analysed record.
  const double record_s = (result.samples - 1) * result.sample_interval_s;
  const auto mean_amplitude = [record_s](double amplitude, double decay) {
    const double x = decay * record_s;
    return std::abs(x) < 1e-12 ? amplitude : amplitude * -std::expm1(-x) / x;
  };
  out << "| k | frequency, Hz | beta, 1/s | half-life ln2/beta, s | damping ratio |";
  // Each channel's own unit (an accelerometer's amplitudes are no angles).
  const auto unit = [&result](size_t c) {
    return c < result.units.size() && !result.units[c].empty() ? result.units[c] : "rad";
  };
  for (size_t c = 0; c < result.channels.size(); ++c) {
    out << fmt::format(" A_{}, {} |", result.channels[c], unit(c));
  }
  for (size_t c = 0; c < result.channels.size(); ++c) {
    out << fmt::format(" mean A_{}, {} |", result.channels[c], unit(c));
  }
  if (reference != nullptr) {
    out << fmt::format(" {0}: frequency, Hz | {0}: beta, 1/s |", reference_label);
    if (!reference->empty() && !reference->front().amplitude.empty()) {
      for (size_t c = 0; c < result.channels.size(); ++c) {
        out << fmt::format(" {}: A_{}, {} |", reference_label, result.channels[c], unit(c));
      }
    }
  }
  out << "\n|---|---|---|---|---|";
  for (size_t c = 0; c < 2 * result.channels.size(); ++c) out << "---|";
  if (reference != nullptr) {
    out << "---|---|";
    if (!reference->empty() && !reference->front().amplitude.empty()) {
      for (size_t c = 0; c < result.channels.size(); ++c) out << "---|";
    }
  }
  out << "\n";
  for (size_t k = 0; k < result.modes.size(); ++k) {
    const auto& mode = result.modes[k];
    // A combination tone is no mode of the structure: the table says so where it is read.
    const std::string label =
        mode.combination.empty() ? std::to_string(k + 1)
                                 : fmt::format("{} (combination tone {})", k + 1, mode.combination);
    out << fmt::format("| {} | {:.4f} ± {:.2g} | {:.3f} ± {:.2g} | {:.3f} | {:.3f} |", label,
                       mode.frequency_hz, mode.std_frequency_hz, -mode.decay_rate_per_s,
                       mode.std_decay_rate_per_s, mode.half_life_s, mode.damping_ratio);
    for (Eigen::Index c = 0; c < mode.amplitude.size(); ++c) {
      out << fmt::format(" {:.2e} |", mode.amplitude[c]);
    }
    for (Eigen::Index c = 0; c < mode.amplitude.size(); ++c) {
      out << fmt::format(" {:.2e} |", mean_amplitude(mode.amplitude[c], mode.decay_rate_per_s));
    }
    if (reference != nullptr && !reference->empty()) {
      // The reference mode nearest in frequency.
      const ReferenceMode* nearest = nullptr;
      for (const ReferenceMode& candidate : *reference) {
        if (nearest == nullptr || std::abs(candidate.frequency_hz - mode.frequency_hz) <
                                      std::abs(nearest->frequency_hz - mode.frequency_hz)) {
          nearest = &candidate;
        }
      }
      // A tone has no reference mode: the nearest one is not its counterpart.
      const bool tone = !mode.combination.empty();
      out << (tone ? std::string(" - | - |")
                   : fmt::format(" {:.4f} | {:.3f} |", nearest->frequency_hz,
                                 -nearest->decay_rate_per_s));
      if (!reference->front().amplitude.empty()) {
        for (const std::string& channel : result.channels) {
          const auto found = nearest->amplitude.find(channel);
          out << (tone || found == nearest->amplitude.end()
                      ? std::string(" - |")
                      : fmt::format(" {:.2e} |", found->second));
        }
      }
    }
    out << "\n";
  }
  out << "\nCorrelation of record and reconstruction:";
  for (size_t c = 0; c < result.channels.size(); ++c) {
    out << fmt::format(" K({}) = {:.3f}", result.channels[c],
                       result.correlation[static_cast<Eigen::Index>(c)]);
  }
  out << fmt::format(
      ". Method `{}`, model order {}, effective rank {}; mean amplitudes over the "
      "{:.2f} s analysed.\n",
      result.method, result.model_order, result.effective_rank, record_s);
  return out.str();
}

std::string DrawResimulationFigure(const std::string& folder, const Measurement& measured,
                                   const updating::TestFit& fit, int channel) {
  Figure figure;
  const std::string& name = fit.channels[channel];
  const int column = measured.FindChannel(name);
  figure.title = fmt::format("{}: record and re-simulation with the tuned parameters (K = {:.4f})",
                             name, fit.correlation[channel]);
  figure.x_label = "time, s";
  figure.y_label = fmt::format("{}, {}", name, fit.simulated.units[channel]);
  figure.series.push_back(
      {"record", measured.CalcTime(), measured.values.col(column), kRecordStyle});
  // With a fitted baseline the re-simulation carries it (what the record is compared with).
  const char* label = fit.drift.size() > 0    ? "re-simulation (tuned model + offset + drift)"
                      : fit.offset.size() > 0 ? "re-simulation (tuned model + offset)"
                                              : "re-simulation (tuned model)";
  figure.series.push_back({label, fit.simulated.CalcTime(), fit.simulated.values.col(channel),
                           "lines lw 1.5 lc rgb '#2ca02c'"});
  const std::string file = fmt::format("resimulation_{}.png", name);
  DrawFigure(figure, Path(folder, file));
  return file;
}

std::string DrawConvergenceFigure(const std::string& folder, const updating::UpdateResult& result) {
  Figure figure;
  figure.title = "Model updating (Route 2): cost per Ceres iteration";
  figure.x_label = "iteration (all stages in order)";
  figure.y_label = "cost, 1/2 sum of squared weighted residuals";
  figure.log_y = true;
  Eigen::VectorXd x(static_cast<Eigen::Index>(result.history.size()));
  Eigen::VectorXd y(x.size());
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    x[i] = static_cast<double>(i);
    y[i] = std::max(result.history[static_cast<size_t>(i)].cost, 1e-300);
  }
  figure.series.push_back({"cost", x, y, "linespoints pt 7 ps 0.6 lc rgb '#1f77b4'"});
  DrawFigure(figure, Path(folder, "convergence.png"));
  return "convergence.png";
}

std::string TunedParametersMarkdown(const updating::UpdateResult& result,
                                    const model::MechanicalModel& model,
                                    const std::string& model_label) {
  std::ostringstream out;
  out << fmt::format(
      "Termination `{}` after {} iterations; cost {:.4g} -> {:.4g}; Jacobian "
      "from {}.\n\n",
      result.termination_name(), result.iterations, result.initial_cost, result.final_cost,
      result.jacobian);
  // "start": where the best minimum's own fit began (a Route-1 set, the scenario, a design point).
  out << fmt::format("| parameter | tuned | std | start of its fit | {} | difference |\n",
                     model_label);
  out << "|---|---|---|---|---|---|\n";
  for (const updating::ParameterEstimate& p : result.parameters) {
    double true_value = std::numeric_limits<double>::quiet_NaN();
    for (const model::Parameter& q : model.parameters()) {
      if (q.name == p.name) true_value = q.value;
    }
    out << fmt::format("| {} ({}) | {:.4g}{} | {} | {:.4g} | {} | {} |\n", p.name, p.units, p.value,
                       p.at_bound ? " (at bound)" : "",
                       // An undetermined parameter's std is no result either: said in its cell.
                       !std::isfinite(p.std) ? "undetermined"
                       : p.determined ? fmt::format("{:.2g} ({:.2g}%)", p.std, 100 * p.relative_std)
                                      : fmt::format("undetermined (std {:.2g})", p.std),
                       p.initial,
                       std::isfinite(true_value) ? fmt::format("{:.4g}", true_value) : "-",
                       std::isfinite(true_value)
                           ? fmt::format("{:+.3g}%", 100 * (p.value - true_value) / true_value)
                           : "");
  }
  const std::vector<std::string> profiles = updating::DescribeProfiles(result);
  if (!profiles.empty()) {
    out << "\nProfile-likelihood intervals (each parameter held, the others re-fitted):\n\n";
    for (const std::string& line : profiles) out << "- " << line << "\n";
  }
  if (!result.undetermined.empty()) {
    out << "\n**The record leaves these parameters undetermined:** "
        << fmt::format("{}", fmt::join(result.undetermined, ", "))
        << " (their values above are not results).\n";
  }
  for (const updating::TestFit& fit : result.tests) {
    const std::vector<std::string> lines = updating::DescribeBaseline(fit);
    if (lines.empty()) continue;
    out << "\nFitted baseline of the record (added to the re-simulation below): "
        << fmt::format("{}", fmt::join(lines, "; ")) << ".\n";
  }
  for (const std::string& warning : result.warnings) out << "\n> " << warning << "\n";
  return out.str();
}

std::vector<std::pair<std::string, double>> CalcRelativeSpread(
    const std::vector<const updating::UpdateResult*>& results) {
  std::vector<std::pair<std::string, double>> spread;
  if (results.empty()) return spread;
  for (const updating::ParameterEstimate& p : results.front()->parameters) {
    if (!p.test.empty()) continue;  // a nuisance parameter of one test
    // Determined values only: an undetermined one is where its fit happened to stop (a test
    // that does not excite the joint keeps its start), and its spread says nothing of the joint.
    double lowest = INFINITY, highest = -INFINITY;
    int count = 0;
    for (const updating::UpdateResult* result : results) {
      for (const updating::ParameterEstimate& q : result->parameters) {
        if (q.name == p.name && q.test.empty() && q.determined) {
          lowest = std::min(lowest, q.value);
          highest = std::max(highest, q.value);
          ++count;
        }
      }
    }
    spread.emplace_back(p.name, count >= 2 ? (highest - lowest) / highest : NAN);
  }
  return spread;
}

std::string TestsTableMarkdown(const std::vector<std::string>& test_names,
                               const std::vector<const updating::UpdateResult*>& results) {
  const auto spread = CalcRelativeSpread(results);
  std::ostringstream out;
  out << "| test |";
  for (const auto& [name, value] : spread) out << " " << name << " |";
  out << "\n|---|";
  for (size_t i = 0; i < spread.size(); ++i) out << "---|";
  out << "\n";
  for (size_t t = 0; t < results.size(); ++t) {
    out << "| " << test_names[t] << " |";
    for (const auto& [name, value] : spread) {
      for (const updating::ParameterEstimate& q : results[t]->parameters) {
        if (q.name == name && q.test.empty()) {
          out << fmt::format(" {:.3g}{} |", q.value, q.determined ? "" : " (undetermined)");
        }
      }
    }
    out << "\n";
  }
  out << "| relative spread, % |";
  for (const auto& [name, value] : spread) {
    out << (std::isfinite(value) ? fmt::format(" {:.0f} |", 100 * value) : std::string(" - |"));
  }
  out << "\n\nThe spread is over the determined values (\"-\": fewer than two tests determine the "
         "parameter).\n";
  return out.str();
}

std::string AlgebraicSetsMarkdown(const updating::CharacteristicResult& result) {
  std::ostringstream out;
  out << fmt::format("Route 1 (eq. 7) from the identified poles: `{}`, {} of {} starts converged",
                     result.status_name(), result.converged_starts, result.starts);
  if (result.ambiguous) out << "; **ambiguous** (rival sets fit the initial state about as well)";
  out << ".\n\n| set | admissible | mismatch of the initial state |";
  for (const std::string& q : result.coordinates) out << " c_" << q << " |";
  for (const std::string& q : result.coordinates) out << " d_" << q << " |";
  out << "\n|---|---|---|";
  for (size_t i = 0; i < 2 * result.coordinates.size(); ++i) out << "---|";
  out << "\n";
  for (size_t k = 0; k < result.solutions.size(); ++k) {
    const updating::CharacteristicSolution& set = result.solutions[k];
    out << fmt::format("| {}{} | {} | {} |", k + 1,
                       static_cast<int>(k) == result.chosen ? " (chosen)" : "",
                       set.admissible ? "yes" : set.reason,
                       set.admissible ? fmt::format("{:.3g}", set.mismatch) : "");
    for (Eigen::Index i = 0; i < set.c.size(); ++i) out << fmt::format(" {:.3g} |", set.c[i]);
    for (Eigen::Index i = 0; i < set.d.size(); ++i) out << fmt::format(" {:.3g} |", set.d[i]);
    out << "\n";
  }
  return out.str();
}

}  // namespace mbid::report
