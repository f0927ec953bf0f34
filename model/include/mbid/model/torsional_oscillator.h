#pragma once

#include "mbid/model/machine_description.h"
#include "mbid/model/multibody_model.h"

namespace mbid::model {

// A disc of moment J on a torsional spring-damper about a fixed vertical axis, without
// gravity: the one-joint model with a closed form (tests, examples). Coordinate and output
// `angle`; a point `rim` 1 m from the axis on the disc's x axis.
struct TorsionalOscillatorParameters {
  double inertia_kgm2 = 1.0;
  double stiffness_Nm_per_rad = 1.0;
  double damping_Nms_per_rad = 0.0;
  void Validate() const;  // InputError unless J, c > 0 and d >= 0, all finite
};

// `type: torsional_oscillator` expands to this description.
MachineDescription DescribeTorsionalOscillator(const TorsionalOscillatorParameters& parameters);

// The oscillator as a model, type() "torsional_oscillator".
MultibodyModel MakeTorsionalOscillator(const TorsionalOscillatorParameters& parameters);

}  // namespace mbid::model
