#include "mbid/model/truck_crane_parameters.h"

#include <cmath>
#include <string>

#include "mbid/common/error.h"

namespace mbid::model {
namespace {

const char* const kSource = "model parameters";

void RequirePositive(double value, const std::string& field, const std::string& unit) {
  if (!(std::isfinite(value) && value > 0)) {
    throw InputError(kSource, field, "value " + std::to_string(value),
                     "a positive finite number in " + unit);
  }
}

void RequireNonNegative(double value, const std::string& field, const std::string& unit) {
  if (!(std::isfinite(value) && value >= 0)) {
    throw InputError(kSource, field, "value " + std::to_string(value),
                     "a non-negative finite number in " + unit);
  }
}

void RequireFinite(const Eigen::Vector3d& v, const std::string& field) {
  if (!v.allFinite()) throw InputError(kSource, field, "non-finite entry", "finite numbers in m");
}

// Principal moments of a rigid body: positive and each at most the sum of the other two.
void RequirePrincipalInertia(const Eigen::Vector3d& I, const std::string& field) {
  for (int i = 0; i < 3; ++i) RequirePositive(I[i], field, "kg*m^2");
  for (int i = 0; i < 3; ++i) {
    if (I[i] > I[(i + 1) % 3] + I[(i + 2) % 3]) {
      throw InputError(kSource, field, "principal moments violate the triangle inequality",
                       "each moment at most the sum of the other two");
    }
  }
}

}  // namespace

void TruckCraneParameters::Validate() const {
  RequirePositive(gravity_mps2, "gravity_mps2", "m/s^2");
  if (!(std::isfinite(boom_elevation_rad) && std::abs(boom_elevation_rad) < M_PI / 2)) {
    throw InputError(kSource, "configuration.boom_elevation_deg", "out of range",
                     "an elevation in (-90, 90) degrees");
  }
  if (!std::isfinite(slew_rad)) {
    throw InputError(kSource, "configuration.slew_deg", "not finite", "a finite angle");
  }
  RequireFinite(p_GOa_m, "base.pitch_pivot_m");
  RequirePositive(base_mass_kg, "base.mass_kg", "kg");
  RequireFinite(p_GBcm_m, "base.com_m");
  RequirePrincipalInertia(base_inertia_kgm2, "base.inertia_kgm2");
  RequireFinite(p_GOs_m, "slewing.bearing_m");
  RequirePositive(slewing_mass_kg, "slewing.mass_kg", "kg");
  RequireFinite(p_OsScm_S_m, "slewing.com_m");
  RequirePrincipalInertia(slewing_inertia_kgm2, "slewing.inertia_kgm2");
  RequireFinite(p_OsF_S_m, "boom.foot_m");
  RequirePositive(boom_mass_kg, "boom.mass_kg", "kg");
  RequirePositive(boom_length_m, "boom.length_m", "m");
  RequirePositive(boom_axial_inertia_kgm2, "boom.axial_inertia_kgm2", "kg*m^2");
  RequireNonNegative(attached_payload_kg, "payload_mass_kg", "kg");
  const char* names[] = {"alpha", "gamma", "eta", "theta"};
  for (int i = 0; i < 4; ++i) {
    const std::string joint = std::string("joints.") + names[i];
    RequirePositive(joints[i].stiffness_Nm_per_rad, joint + ".stiffness_Nm_per_rad", "N*m/rad");
    RequireNonNegative(joints[i].damping_Nms_per_rad, joint + ".damping_Nms_per_rad", "N*m*s/rad");
  }
}

}  // namespace mbid::model
