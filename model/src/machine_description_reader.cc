// Reads `model: {type: multibody}` (docs/machine-description.md) into a MachineDescription.
#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <stdexcept>

#include "mbid/common/error.h"
#include "mbid/model/expression.h"
#include "mbid/model/machine_description.h"

namespace mbid::model {
namespace {

// A numeric field: a plain YAML number, or an expression of `model.parameters` (quoted or not).
double Number(const YamlReader& node, const ExpressionContext& context) {
  const YAML::Node& yaml = node.node();
  if (!yaml.IsScalar()) node.Fail("is not a number", "a number or an expression of parameters");
  const std::string& text = yaml.Scalar();
  // YAML's own infinities and NaN are numbers to YAML, not to an expression parser.
  std::string lower = text;
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (lower == ".nan" || lower == ".inf" || lower == "+.inf" || lower == "-.inf") {
    node.Fail("'" + text + "' is not finite", "a finite number or an expression of parameters");
  }
  char* end = nullptr;
  std::strtod(text.c_str(), &end);
  const bool plain_number = !text.empty() && end == text.c_str() + text.size() && yaml.Tag() != "!";
  if (plain_number) return node.AsDouble();
  try {
    return context.Evaluate(text);
  } catch (const std::invalid_argument& error) {
    node.Fail(error.what(), "a number or an expression of model.parameters");
  }
}

double Number(const YamlReader& parent, const std::string& key, const ExpressionContext& context) {
  return Number(parent.Child(key), context);
}

double Number(const YamlReader& parent, const std::string& key, const ExpressionContext& context,
              double fallback) {
  return parent.Has(key) ? Number(parent, key, context) : fallback;
}

// Entry i of a list, named `field[i]` in errors.
YamlReader Element(const YamlReader& list, size_t i) {
  return YamlReader(list.node()[i], list.source(), list.field() + "[" + std::to_string(i) + "]");
}

std::vector<double> Numbers(const YamlReader& list, const ExpressionContext& context) {
  if (!list.node().IsSequence()) list.Fail("is not a list", "a list of numbers");
  std::vector<double> values;
  for (size_t i = 0; i < list.node().size(); ++i) {
    values.push_back(Number(Element(list, i), context));
  }
  return values;
}

Eigen::Vector3d Vector3(const YamlReader& list, const ExpressionContext& context) {
  const std::vector<double> v = Numbers(list, context);
  if (v.size() != 3) list.Fail(std::to_string(v.size()) + " entries", "three numbers [x, y, z]");
  return Eigen::Vector3d(v[0], v[1], v[2]);
}

Eigen::Vector3d Vector3(const YamlReader& parent, const std::string& key,
                        const ExpressionContext& context) {
  return Vector3(parent.Child(key), context);
}

Eigen::Vector3d Vector3(const YamlReader& parent, const std::string& key,
                        const ExpressionContext& context, const Eigen::Vector3d& fallback) {
  return parent.Has(key) ? Vector3(parent, key, context) : fallback;
}

Eigen::Matrix3d ReadRotation(const YamlReader& parent, const std::string& key,
                             const ExpressionContext& context) {
  if (!parent.Has(key)) return Eigen::Matrix3d::Identity();
  const YamlReader list = parent.Child(key);
  if (list.node().IsNull()) return Eigen::Matrix3d::Identity();
  if (!list.node().IsSequence())
    list.Fail("is not a list", "a list of turns like [{z: -30}, {y: 16}]");
  std::vector<std::pair<char, double>> turns;
  for (size_t i = 0; i < list.node().size(); ++i) {
    const YamlReader turn = Element(list, i);
    turn.ExpectMap({"x", "y", "z"});
    const std::vector<std::string> keys = turn.Keys();
    if (keys.size() != 1)
      turn.Fail("has " + std::to_string(keys.size()) + " axes", "one turn: {x|y|z: degrees}");
    turns.emplace_back(keys[0][0], Number(turn, keys[0], context));
  }
  return RotationFromTurns(turns);
}

Eigen::Matrix3d Inertia(const YamlReader& body, const ExpressionContext& context) {
  const YamlReader list = body.Child("inertia_kgm2");
  const std::vector<double> v = Numbers(list, context);
  Eigen::Matrix3d I = Eigen::Matrix3d::Zero();
  if (v.size() == 3 || v.size() == 6) {
    I.diagonal() << v[0], v[1], v[2];
  } else {
    list.Fail(std::to_string(v.size()) + " entries",
              "[Ixx, Iyy, Izz] or [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] in kg*m^2");
  }
  if (v.size() == 6) {
    I(0, 1) = I(1, 0) = v[3];
    I(0, 2) = I(2, 0) = v[4];
    I(1, 2) = I(2, 1) = v[5];
  }
  return I;
}

JointDescription ReadJoint(const YamlReader& joint, const ExpressionContext& context) {
  joint.ExpectMap({"type", "coordinates", "axis", "axes", "in_parent_m", "in_parent_rotation_deg",
                   "in_body_m", "in_body_rotation_deg"});
  JointDescription result;
  const std::string type = joint.Choice("type", {"revolute", "prismatic", "universal", "weld"}, "");
  if (type.empty()) joint.FailAt("type", "missing", "revolute, prismatic, universal or weld");
  result.type = type == "revolute"    ? JointType::kRevolute
                : type == "prismatic" ? JointType::kPrismatic
                : type == "universal" ? JointType::kUniversal
                                      : JointType::kWeld;
  if (result.type == JointType::kWeld) {
    if (joint.Has("coordinates") && !joint.StringList("coordinates").empty()) {
      joint.FailAt("coordinates", "coordinates on a weld",
                   "none (a weld has no degree of freedom)");
    }
    for (const char* key : {"axis", "axes"}) {
      if (joint.Has(key)) joint.FailAt(key, "an axis on a weld", "no axis");
    }
  } else {
    result.coordinates = joint.StringList("coordinates");
    // Counted here, before the springs and outputs name them (a universal joint given one
    // coordinate was reported through its second coordinate's spring).
    const size_t dofs = result.type == JointType::kUniversal ? 2 : 1;
    if (result.coordinates.size() != dofs) {
      joint.FailAt("coordinates", std::to_string(result.coordinates.size()) + " coordinates",
                   std::to_string(dofs) + " for this joint type");
    }
    if (result.type == JointType::kUniversal) {
      if (joint.Has("axis"))
        joint.FailAt("axis", "'axis' on a universal joint", "axes: [[..], [..]]");
      const YamlReader axes = joint.Child("axes");
      if (!axes.node().IsSequence() || axes.node().size() != 2) {
        axes.Fail("is not a list of two axes", "axes: [[x, y, z], [x, y, z]]");
      }
      for (size_t i = 0; i < 2; ++i) result.axes.push_back(Vector3(Element(axes, i), context));
    } else {
      if (joint.Has("axes")) joint.FailAt("axes", "'axes' on a one-axis joint", "axis: [x, y, z]");
      result.axes.push_back(Vector3(joint, "axis", context));
    }
  }
  result.in_parent_m = Vector3(joint, "in_parent_m", context, Eigen::Vector3d::Zero());
  result.in_parent_rotation = ReadRotation(joint, "in_parent_rotation_deg", context);
  result.in_body_m = Vector3(joint, "in_body_m", context, Eigen::Vector3d::Zero());
  result.in_body_rotation = ReadRotation(joint, "in_body_rotation_deg", context);
  return result;
}

OutputDescription ReadOutput(const std::string& name, const YamlReader& output,
                             const ExpressionContext& context) {
  OutputDescription result;
  result.name = name;
  const std::string type = output.Choice("type",
                                         {"coordinate", "azimuth", "elevation", "displacement",
                                          "velocity", "acceleration", "angular_velocity"},
                                         "");
  if (type == "coordinate") {
    output.ExpectMap({"type", "coordinate"});
    result.type = OutputType::kCoordinate;
    result.coordinate = output.String("coordinate");
  } else if (type == "azimuth" || type == "elevation") {
    output.ExpectMap({"type", "body", "direction"});
    result.type = type == "azimuth" ? OutputType::kAzimuth : OutputType::kElevation;
    result.body = output.String("body");
    result.direction = Vector3(output, "direction", context);
    result.body_frame = true;
  } else if (type == "angular_velocity") {
    output.ExpectMap({"type", "body", "axis", "frame"});
    result.type = OutputType::kAngularVelocity;
    result.body = output.String("body");
    result.direction = Vector3(output, "axis", context);
    result.body_frame = output.Choice("frame", {"ground", "body"}, "ground") == "body";
  } else if (!type.empty()) {
    output.ExpectMap({"type", "point", "direction", "frame"});
    result.type = type == "displacement" ? OutputType::kDisplacement
                  : type == "velocity"   ? OutputType::kVelocity
                                         : OutputType::kAcceleration;
    result.point = output.String("point");
    result.direction = Vector3(output, "direction", context);
    result.body_frame = output.Choice("frame", {"ground", "body"}, "ground") == "body";
  } else {
    output.FailAt("type", "missing",
                  "coordinate, azimuth, elevation, displacement, velocity, acceleration or "
                  "angular_velocity");
  }
  return result;
}

SpringDescription ReadSpring(const std::string& coordinate, bool translational,
                             const YamlReader& spring, const ExpressionContext& context) {
  const char* stiffness_key = translational ? "stiffness_N_per_m" : "stiffness_Nm_per_rad";
  const char* damping_key = translational ? "damping_Ns_per_m" : "damping_Nms_per_rad";
  spring.ExpectMap({stiffness_key, damping_key});
  SpringDescription result;
  result.coordinate = coordinate;
  result.stiffness = Number(spring, stiffness_key, context);
  if (!(result.stiffness > 0)) {
    spring.FailAt(stiffness_key, "stiffness " + std::to_string(result.stiffness),
                  "a positive stiffness (leave a free coordinate without a spring)");
  }
  result.damping = Number(spring, damping_key, context, 0.0);
  if (result.damping < 0) {
    spring.FailAt(damping_key, "negative damping", "a damping >= 0");
  }
  return result;
}

}  // namespace

MachineDescription ReadMachineDescription(const YamlReader& model) {
  model.ExpectMap({"type", "gravity_mps2", "parameters", "bodies", "springs", "points",
                   "payload_point", "payload_mass_kg", "outputs"});
  ExpressionContext context;
  if (model.Has("parameters")) {
    const YamlReader parameters = model.Child("parameters");
    parameters.ExpectMap(parameters.Keys());  // a map, each key once
    for (const std::string& name : parameters.Keys()) {
      // Earlier parameters may be used in later ones.
      const double value = Number(parameters, name, context);
      try {
        context.Define(name, value);
      } catch (const std::invalid_argument& error) {
        parameters.FailAt(name, error.what(), "a parameter name");
      }
    }
  }

  MachineDescription machine;
  machine.gravity_mps2 = Number(model, "gravity_mps2", context, 9.81);
  const YamlReader bodies = model.Child("bodies");
  bodies.ExpectMap(bodies.Keys());
  for (const std::string& name : bodies.Keys()) {
    const YamlReader body = bodies.Child(name);
    body.ExpectMap({"parent", "joint", "mass_kg", "com_m", "inertia_kgm2"});
    BodyDescription result;
    result.name = name;
    result.parent = body.String("parent");
    // Said here, before the springs and outputs: a missing parent body leaves its coordinates
    // unknown to them, and their error named the symptom (MachineDescription::Validate checks it
    // too, for descriptions made in code).
    if (result.parent != "ground" &&
        std::none_of(machine.bodies.begin(), machine.bodies.end(),
                     [&](const BodyDescription& b) { return b.name == result.parent; })) {
      // Its own parent, or a parent listed later (a loop of bodies is always one of these).
      const std::string problem = result.parent == name
                                      ? "'" + name + "' is its own parent"
                                      : "parent '" + result.parent + "' is not defined above";
      body.FailAt("parent", problem,
                  "ground or a body listed before '" + name + "' (bodies form a tree: no loops)");
    }
    result.joint = ReadJoint(body.Child("joint"), context);
    result.mass_kg = Number(body, "mass_kg", context);
    result.com_m = Vector3(body, "com_m", context, Eigen::Vector3d::Zero());
    result.inertia_kgm2 = Inertia(body, context);
    machine.bodies.push_back(std::move(result));
    // Springs and outputs name coordinates: a bad name or a duplicate must be reported as such
    // first (not as a spring's unknown coordinate offering the bad name as the fix).
    const std::vector<std::string> coordinates = machine.coordinates();
    for (const std::string& coordinate : machine.bodies.back().joint.coordinates) {
      if (!IsIdentifier(coordinate)) {
        body.Child("joint").FailAt("coordinates", "coordinate name '" + coordinate + "'",
                                   "letters, digits and '_', starting with a letter");
      }
    }
    for (size_t i = 0; i < coordinates.size(); ++i) {
      if (std::find(coordinates.begin(), coordinates.begin() + static_cast<long>(i),
                    coordinates[i]) != coordinates.begin() + static_cast<long>(i)) {
        body.Child("joint").FailAt("coordinates", "coordinate '" + coordinates[i] + "' named twice",
                                   "each coordinate name once in the machine");
      }
    }
  }

  if (model.Has("springs")) {
    const YamlReader springs = model.Child("springs");
    springs.ExpectMap(springs.Keys());
    const std::vector<std::string> coordinates = machine.coordinates();
    for (const std::string& coordinate : springs.Keys()) {
      if (std::find(coordinates.begin(), coordinates.end(), coordinate) == coordinates.end()) {
        std::string known;
        for (const std::string& c : coordinates) known += (known.empty() ? "" : ", ") + c;
        springs.FailAt(
            coordinate, "unknown coordinate '" + coordinate + "'",
            known.empty() ? "a coordinate of a joint in bodies (none has one)" : "one of " + known);
      }
      machine.springs.push_back(ReadSpring(coordinate, machine.IsTranslational(coordinate),
                                           springs.Child(coordinate), context));
    }
  }
  if (model.Has("points")) {
    const YamlReader points = model.Child("points");
    points.ExpectMap(points.Keys());
    for (const std::string& name : points.Keys()) {
      const YamlReader point = points.Child(name);
      point.ExpectMap({"body", "at_m"});
      machine.points.push_back({name, point.String("body"), Vector3(point, "at_m", context)});
    }
  }
  machine.payload_point = model.String("payload_point", "");
  machine.attached_payload_kg = Number(model, "payload_mass_kg", context, 0.0);
  const YamlReader outputs = model.Child("outputs");
  outputs.ExpectMap(outputs.Keys());
  for (const std::string& name : outputs.Keys()) {
    machine.outputs.push_back(ReadOutput(name, outputs.Child(name), context));
  }

  try {
    machine.Validate();
  } catch (const InputError& error) {
    // The checks name key paths below `model`; anchor them to this file and section.
    throw InputError(model.source(),
                     model.field().empty() ? error.field() : model.field() + "." + error.field(),
                     error.problem(), error.expected());
  }
  return machine;
}

}  // namespace mbid::model
