#pragma once

// The window of dampings that meet a damper-sizing target (damper_sizing.h): the model evaluated
// at dampings between sweep points, edges bisected, a window narrower than the sweep searched.
#include <map>
#include <string>
#include <vector>

#include "mbid/campaign/campaign.h"
#include "mbid/campaign/damper_sizing.h"
#include "vectors.h"

namespace mbid::campaign::internal {

// A damping's metrics against the targets.
struct SizingPoint {
  double min_damping_ratio = kNaN;
  double settling_time_s = kNaN;
};

bool Meets(const DamperSizingSpec& spec, const std::string& target, const SizingPoint& point);

// Evaluates the model with d_joint = damping: an ad-hoc case of the campaign.
class SizingEvaluator {
 public:
  SizingEvaluator(const Campaign& campaign, const DamperSizingSpec& spec, const std::string& joint);
  // Targets bisect over the same brackets ("all" repeats another target's): each damping is
  // evaluated once.
  SizingPoint operator()(double damping, int* evaluations, std::string* failure) const;

 private:
  Campaign campaign_;
  std::string key_;
  mutable std::map<double, SizingPoint> cache_;
};

struct Window {
  double smallest = kNaN;
  double largest = kNaN;
  std::string note;
};

// The smallest damping that meets `target` and the largest of the window that meets it from
// there (NaN, NaN if none was found), and how they were found. Edges are bisected between
// sweep points; where no sweep point meets the target, the model is searched around the
// sweep's best interior points (a window narrower than the sweep's spacing).
Window FindWindow(const DamperSizingSpec& spec, const std::string& target,
                  const std::vector<double>& damping, const std::vector<SizingPoint>& points,
                  const SizingEvaluator& evaluate, int* evaluations_total);

}  // namespace mbid::campaign::internal
