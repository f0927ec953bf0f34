#include "mbid/simulation/excitation.h"

#include <cmath>

namespace mbid::simulation {

std::string Excitation::type_name() const {
  switch (type) {
    case Type::kLoadDrop:
      return "load_drop";
    case Type::kInitialDeflection:
      return "initial_deflection";
    case Type::kImpulse:
      return "impulse";
    case Type::kBurst:
      return "burst";
  }
  return "unknown";
}

double Excitation::CalcForcingEndTime() const {
  switch (type) {
    case Type::kImpulse:
      return duration_s;
    case Type::kBurst:
      return cycles / frequency_hz;
    default:
      return 0.0;
  }
}

double Excitation::CalcForcingFactor(double t) const {
  const double end = CalcForcingEndTime();
  if (t < 0 || t >= end) return 0.0;
  if (type == Type::kImpulse) {
    return pulse_shape == PulseShape::kRectangular ? 1.0 : std::sin(M_PI * t / duration_s);
  }
  return std::sin(2 * M_PI * frequency_hz * t);  // burst
}

Eigen::VectorXd CalcInitialCoordinates(const model::MechanicalModel& model,
                                       const Excitation& excitation) {
  const int n = model.coordinate_count();
  Eigen::VectorXd q = Eigen::VectorXd::Zero(n);
  if (excitation.type == Excitation::Type::kLoadDrop) {
    // At rest only the payload's weight matters; after release the machine is unloaded.
    return model.SolveStaticEquilibrium(model.CalcPayloadLoads(excitation.payload_mass_kg));
  }
  if (excitation.type == Excitation::Type::kInitialDeflection) {
    for (int i = 0; i < n; ++i) {
      const auto found = excitation.deflection_rad.find(model.coordinate_names()[i]);
      if (found != excitation.deflection_rad.end()) q[i] = found->second;
    }
  }
  return q;
}

}  // namespace mbid::simulation
