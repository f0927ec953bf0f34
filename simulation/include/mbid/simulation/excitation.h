#pragma once

#include <Eigen/Core>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "mbid/model/mechanical_model.h"
#include "mbid/simulation/excitations/burst.h"
#include "mbid/simulation/excitations/force_target.h"
#include "mbid/simulation/excitations/impulse.h"
#include "mbid/simulation/excitations/initial_deflection.h"
#include "mbid/simulation/excitations/load_drop.h"

namespace mbid::simulation {

// How a test excites the machine (docs/scenarios.md, `excitation:`): one type per file under
// excitations/. This list is the registry: scenarios read the types named here, and their
// unknown-type error lists them in this order. Adding a type: docs/extending.md.
using ExcitationVariant = std::variant<LoadDrop, InitialDeflection, Impulse, Burst>;

template <typename T, typename Variant>
struct IsExcitationAlternative;
template <typename T, typename... Types>
struct IsExcitationAlternative<T, std::variant<Types...>>
    : std::bool_constant<(std::is_same_v<T, Types> || ...)> {};

struct Excitation {
  Excitation() = default;
  // Implicit, so that `Excitation excitation = LoadDrop{650.0};` reads as it means.
  template <typename T, typename = std::enable_if_t<
                            IsExcitationAlternative<std::decay_t<T>, ExcitationVariant>::value>>
  Excitation(T&& alternative)  // NOLINT(google-explicit-constructor)
      : value(std::forward<T>(alternative)) {}

  ExcitationVariant value = InitialDeflection{};

  std::string type_name() const;
  // When the forcing ends (s); 0 for load_drop and initial_deflection. The record after it is a
  // free decay.
  double CalcForcingEndTime() const;
  // The forcing's time factor in [-1, 1] at time t (0 outside the forcing).
  double CalcForcingFactor(double t) const;
  // Where the forcing acts; nullptr for a free decay.
  const ForceTarget* force_target() const;
  // Whether the start moves with the model's parameters (else dq(0)/dp = 0).
  bool start_depends_on_model() const;

  // The excitation as type T: get throws std::bad_variant_access, get_if returns nullptr if it
  // is another type.
  template <typename T>
  const T& get() const {
    return std::get<T>(value);
  }
  template <typename T>
  T& get() {
    return std::get<T>(value);
  }
  template <typename T>
  const T* get_if() const {
    return std::get_if<T>(&value);
  }
  template <typename T>
  T* get_if() {
    return std::get_if<T>(&value);
  }
};

// The state a test starts from, at rest: q (rad) for the model's coordinates.
Eigen::VectorXd CalcInitialCoordinates(const model::MechanicalModel& model,
                                       const Excitation& excitation);

// The reader of one excitation type, named as in the scenario's `type:`.
struct ExcitationReader {
  const char* type_name;
  Excitation (*read)(const YamlReader& node, const model::MechanicalModel& model);
};
// One reader per alternative of ExcitationVariant, in its order (scenario_sections.h's
// ReadExcitation chooses among them).
const std::vector<ExcitationReader>& ExcitationReaders();
std::vector<std::string> ExcitationTypeNames();

}  // namespace mbid::simulation
