#include "damper_window.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "mbid/campaign/campaign_case.h"

namespace mbid::campaign::internal {
namespace {

constexpr int kMaxBisections = 200;  // log2 of any range over any tolerance above 1e-15
constexpr double kInfinity = std::numeric_limits<double>::infinity();

// How far a point is inside the target, relative to it: >= 0 where it meets it, NaN where its
// evaluation failed. "all" is the smaller of the two.
double Margin(const DamperSizingSpec& spec, const std::string& target, const SizingPoint& point) {
  const double ratio = point.min_damping_ratio / spec.min_damping_ratio - 1;
  const double settling = spec.max_settling_time_s / point.settling_time_s - 1;  // never: -1
  if (target == "min_damping_ratio") return ratio;
  if (target == "max_settling_time_s") return settling;
  if (std::isnan(ratio) || std::isnan(settling)) return kNaN;
  return std::min(ratio, settling);
}

// What a point achieves of the target, for the notes.
std::string Achieved(const std::string& target, const SizingPoint& point) {
  std::vector<std::string> parts;
  if (target != "max_settling_time_s") {
    parts.push_back(fmt::format("smallest damping ratio {:.4g}", point.min_damping_ratio));
  }
  if (target != "min_damping_ratio") {
    parts.push_back(std::isinf(point.settling_time_s)
                        ? std::string("not settled within the record")
                        : fmt::format("settling time {:.4g} s", point.settling_time_s));
  }
  return fmt::format("{}", fmt::join(parts, ", "));
}

// Searches the model between sweep points for the dampings the sweep's samples cannot show.
class WindowSearch {
 public:
  WindowSearch(const DamperSizingSpec& spec, const std::string& target,
               const SizingEvaluator& evaluate)
      : spec_(spec), target_(target), evaluate_(evaluate) {}

  int evaluations() const { return evaluations_; }
  const std::string& failure() const { return failure_; }

  SizingPoint At(double damping) { return evaluate_(damping, &evaluations_, &failure_); }
  bool Meets(double damping) { return internal::Meets(spec_, target_, At(damping)); }

  double Middle(double a, double b) const {
    return spec_.log_spacing && a > 0 && b > 0 ? std::sqrt(a * b) : 0.5 * (a + b);
  }

  // The edge between a damping that meets the target and one that does not (either order),
  // to the relative tolerance; returns the admissible end.
  double Bisect(double meets, double fails) {
    for (int i = 0; i < kMaxBisections &&
                    std::abs(fails - meets) > spec_.relative_tolerance * std::max(meets, fails);
         ++i) {
      const double middle = Middle(meets, fails);
      (Meets(middle) ? meets : fails) = middle;
    }
    return meets;
  }

  // Golden-section search for the largest margin between `low` and `high` (on a log axis for log
  // spacing), to 1e-4 of the bracket; it stops at the first damping that meets the target.
  std::pair<double, SizingPoint> Best(double low, double high) {
    const bool log = spec_.log_spacing && low > 0;
    const auto to_x = [&](double d) { return log ? std::log(d) : d; };
    const auto to_d = [&](double x) { return log ? std::exp(x) : x; };
    const double ratio = 0.5 * (std::sqrt(5.0) - 1);
    double a = to_x(low), b = to_x(high);
    double c = b - ratio * (b - a), d = a + ratio * (b - a);
    SizingPoint pc = At(to_d(c)), pd = At(to_d(d));
    const auto margin = [&](const SizingPoint& p) {
      const double m = Margin(spec_, target_, p);
      return std::isnan(m) ? -kInfinity : m;
    };
    const double width = b - a;
    while (b - a > 1e-4 * width && margin(pc) < 0 && margin(pd) < 0) {
      if (margin(pc) >= margin(pd)) {
        b = d, d = c, pd = pc;
        c = b - ratio * (b - a);
        pc = At(to_d(c));
      } else {
        a = c, c = d, pc = pd;
        d = a + ratio * (b - a);
        pd = At(to_d(d));
      }
    }
    return margin(pc) >= margin(pd) ? std::make_pair(to_d(c), pc) : std::make_pair(to_d(d), pd);
  }

 private:
  const DamperSizingSpec& spec_;
  const std::string& target_;
  const SizingEvaluator& evaluate_;
  int evaluations_ = 0;
  std::string failure_;
};

}  // namespace

SizingEvaluator::SizingEvaluator(const Campaign& campaign, const DamperSizingSpec& spec,
                                 const std::string& joint)
    : campaign_(campaign) {
  campaign_.cases.clear();
  key_ = spec.DampingKey(joint);
  // The damping ratio alone needs no simulation.
  if (!spec.has_settling_target()) campaign_.steps = {false, false, false};
}

SizingPoint SizingEvaluator::operator()(double damping, int* evaluations,
                                        std::string* failure) const {
  ++*evaluations;
  const auto cached = cache_.find(damping);
  if (cached != cache_.end()) return cached->second;
  const CampaignCase one_case = MakeAdHocCase(
      campaign_, {{key_, NumberNode(damping), "damper_sizing.range_Nms_per_rad"}}, "sizing");
  const CaseOutcome outcome = ComputeCase(campaign_, one_case);
  SizingPoint point;
  if (!outcome.ok()) {
    *failure = outcome.reason;
    return point;
  }
  point.min_damping_ratio =
      *std::min_element(outcome.exact_damping_ratios.begin(), outcome.exact_damping_ratios.end());
  point.settling_time_s = outcome.settling_time_s;
  cache_.emplace(damping, point);
  return point;
}

bool Meets(const DamperSizingSpec& spec, const std::string& target, const SizingPoint& point) {
  const bool ratio = point.min_damping_ratio >= spec.min_damping_ratio;
  const bool settling = point.settling_time_s <= spec.max_settling_time_s;
  if (target == "min_damping_ratio") return ratio;
  if (target == "max_settling_time_s") return settling;
  return ratio && settling;
}

Window FindWindow(const DamperSizingSpec& spec, const std::string& target,
                  const std::vector<double>& damping, const std::vector<SizingPoint>& points,
                  const SizingEvaluator& evaluate, int* evaluations_total) {
  Window window;
  WindowSearch search(spec, target, evaluate);
  const size_t n = points.size();
  std::vector<std::string> notes;
  size_t first = 0;
  while (first < n && !Meets(spec, target, points[first])) ++first;
  size_t after = n;  // the first sweep point after the window that fails
  if (first == n) {
    // Local maxima of the sampled margin (the range's ends too), best first: the model between
    // their neighbours may meet the target where no sample does.
    std::vector<size_t> peaks;
    for (size_t i = 0; i < n; ++i) {
      const double m = Margin(spec, target, points[i]);
      const double before = i > 0 ? Margin(spec, target, points[i - 1]) : -kInfinity;
      const double after_peak = i + 1 < n ? Margin(spec, target, points[i + 1]) : -kInfinity;
      if (n > 1 && m >= before && m >= after_peak && (m > before || m > after_peak)) {
        peaks.push_back(i);
      }
    }
    std::sort(peaks.begin(), peaks.end(), [&](size_t i, size_t j) {
      return Margin(spec, target, points[i]) > Margin(spec, target, points[j]);
    });
    std::pair<double, SizingPoint> best{kNaN, SizingPoint()};
    for (size_t k = 0; k < std::min<size_t>(peaks.size(), 3); ++k) {
      const size_t i = peaks[k];
      const size_t low = i > 0 ? i - 1 : i, high = i + 1 < n ? i + 1 : i;
      const auto found = search.Best(damping[low], damping[high]);
      if (std::isnan(best.first) ||
          Margin(spec, target, found.second) > Margin(spec, target, best.second)) {
        best = found;
      }
      if (Meets(spec, target, found.second)) {
        window.smallest = search.Bisect(found.first, damping[low]);
        window.largest = search.Bisect(found.first, damping[high]);
        notes.push_back(fmt::format(
            "met only between {:.6g} and {:.6g} N*m*s/rad, where no sweep point is: found by a "
            "search of the model around the sweep's best point ({:.6g} N*m*s/rad: {}) and "
            "bisection",
            window.smallest, window.largest, damping[i], Achieved(target, points[i])));
        break;
      }
    }
    if (std::isnan(window.smallest)) {
      size_t best_point = 0;
      for (size_t i = 1; i < n; ++i) {
        if (Margin(spec, target, points[i]) > Margin(spec, target, points[best_point])) {
          best_point = i;
        }
      }
      std::string note = fmt::format("not met by any damping from {:.6g} to {:.6g} N*m*s/rad",
                                     damping.empty() ? kNaN : damping.front(),
                                     damping.empty() ? kNaN : damping.back());
      if (target == "max_settling_time_s" && n > 0 &&
          !(Margin(spec, target, points[best_point]) > -1) &&
          !(Margin(spec, target, best.second) > -1)) {
        note += ": the outputs settled within the record at no damping tried";
      } else if (!std::isnan(best.first) &&
                 !(Margin(spec, target, points[best_point]) > Margin(spec, target, best.second))) {
        note += fmt::format(
            ": the best found is {} at {:.6g} N*m*s/rad (a search of the model "
            "around the sweep's best points)",
            Achieved(target, best.second), best.first);
      } else if (n > 0) {
        note += fmt::format(": the sweep's best is {} at {:.6g} N*m*s/rad{}",
                            Achieved(target, points[best_point]), damping[best_point],
                            best_point == 0       ? ", the range's smallest (smaller not tried)"
                            : best_point == n - 1 ? ", the range's largest (larger not tried)"
                                                  : "");
      }
      notes.push_back(note);
    }
  } else {
    if (first == 0) {
      window.smallest = damping[0];
      notes.push_back("met at the smallest damping of the range; smaller not tried");
    } else {
      const int before = search.evaluations();
      window.smallest = search.Bisect(damping[first], damping[first - 1]);
      notes.push_back(fmt::format(
          "from {:.6g}: bisection between {:.6g} and {:.6g} N*m*s/rad "
          "({} steps)",
          window.smallest, damping[first - 1], damping[first], search.evaluations() - before));
    }
    after = first + 1;
    while (after < n && Meets(spec, target, points[after])) ++after;
    if (after == n) {
      window.largest = damping[n - 1];
      notes.push_back("met up to the range's largest damping; larger not tried");
    } else {
      const int before = search.evaluations();
      window.largest = search.Bisect(damping[after - 1], damping[after]);
      notes.push_back(fmt::format(
          "up to {:.6g}: larger dampers fail it again ({}; bisection between {:.6g} and {:.6g} "
          "N*m*s/rad, {} steps)",
          window.largest, Achieved(target, points[after]), damping[after - 1], damping[after],
          search.evaluations() - before));
    }
  }
  for (size_t i = after; i < n; ++i) {
    if (Meets(spec, target, points[i])) {
      notes.push_back(
          fmt::format("met again from the sweep point {:.6g} N*m*s/rad: more than "
                      "one window",
                      damping[i]));
      break;
    }
  }
  if (!search.failure().empty()) notes.push_back("some evaluations failed: " + search.failure());
  *evaluations_total += search.evaluations();
  window.note = fmt::format("{}", fmt::join(notes, "; "));
  return window;
}

}  // namespace mbid::campaign::internal
