#include "mbid/simulation/excitation.h"

#include "mbid/common/yaml_reader.h"

namespace mbid::simulation {
namespace {

template <typename T>
Excitation ReadAs(const YamlReader& node, const model::MechanicalModel& model) {
  return T::Read(node, model);
}

// The registry follows the variant, so that listing a type there is its one registration line.
template <typename... Types>
std::vector<ExcitationReader> MakeReaders(const std::variant<Types...>* /*list*/) {
  return {ExcitationReader{Types::kTypeName, &ReadAs<Types>}...};
}

}  // namespace

std::string Excitation::type_name() const {
  return std::visit([](const auto& e) -> std::string { return e.kTypeName; }, value);
}

double Excitation::CalcForcingEndTime() const {
  return std::visit([](const auto& e) { return e.CalcForcingEndTime(); }, value);
}

double Excitation::CalcForcingFactor(double t) const {
  const double end = CalcForcingEndTime();
  if (t < 0 || t >= end) return 0.0;
  return std::visit([t](const auto& e) { return e.CalcForcingFactor(t); }, value);
}

const ForceTarget* Excitation::force_target() const {
  return std::visit([](const auto& e) { return e.force_target(); }, value);
}

bool Excitation::start_depends_on_model() const {
  return std::visit([](const auto& e) { return e.kStartDependsOnModel; }, value);
}

Eigen::VectorXd CalcInitialCoordinates(const model::MechanicalModel& model,
                                       const Excitation& excitation) {
  return std::visit([&model](const auto& e) { return e.CalcInitialCoordinates(model); },
                    excitation.value);
}

const std::vector<ExcitationReader>& ExcitationReaders() {
  static const std::vector<ExcitationReader> readers =
      MakeReaders(static_cast<const ExcitationVariant*>(nullptr));
  return readers;
}

std::vector<std::string> ExcitationTypeNames() {
  std::vector<std::string> names;
  for (const ExcitationReader& reader : ExcitationReaders()) names.push_back(reader.type_name);
  return names;
}

}  // namespace mbid::simulation
