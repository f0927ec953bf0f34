// The sensor outputs of a state: positions from the described kinematics, rates from Simbody.
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "mbid/common/error.h"
#include "mbid/model/multibody_model.h"
#include "multibody_model_impl.h"

namespace mbid::model {

Eigen::VectorXd MultibodyModel::CalcOutputs(const SimTK::State& state, int max_order) const {
  const Impl& m = *impl_;
  const SimTK::Vector& q_simtk = state.getQ();
  Eigen::VectorXd q(q_simtk.size());
  for (int i = 0; i < q_simtk.size(); ++i) q[i] = q_simtk[i];
  // Positions from the description's kinematics; rates from Simbody, realized as far as needed.
  const int highest_order = std::min(m.highest_output_order, max_order);
  const std::vector<Impl::Pose> poses = m.CalcPoses(q, m.pose_count);
  if (highest_order > 0) {
    m.system.realize(state,
                     highest_order == 1 ? SimTK::Stage::Velocity : SimTK::Stage::Acceleration);
  }
  Eigen::VectorXd y(static_cast<Eigen::Index>(m.outputs.size()));
  for (size_t i = 0; i < m.outputs.size(); ++i) {
    const Impl::Output& output = m.outputs[i];
    if (m.output_orders[i] > highest_order) {
      y[static_cast<Eigen::Index>(i)] = std::numeric_limits<double>::quiet_NaN();
      continue;
    }
    double value = 0;
    switch (output.type) {
      case OutputType::kCoordinate:
        value = output.coordinate >= 0 ? q[output.coordinate] : 0.0;
        break;
      case OutputType::kAzimuth:
      case OutputType::kElevation: {
        const Eigen::Vector3d u = poses[static_cast<size_t>(output.body)].R * output.direction;
        value = output.type == OutputType::kAzimuth
                    ? WrapToPi(std::atan2(u[1], u[0]) - output.rest_angle_rad)
                    : std::atan2(u[2], std::hypot(u[0], u[1])) - output.rest_angle_rad;
        break;
      }
      case OutputType::kDisplacement: {
        const Impl::Pose& pose = poses[static_cast<size_t>(output.body)];
        const Eigen::Vector3d p = pose.p + pose.R * ToEigen3(output.station);
        const Eigen::Vector3d d =
            output.body_frame ? Eigen::Vector3d(pose.R * output.direction) : output.direction;
        value = (p - output.rest_position).dot(d);
        break;
      }
      default: {
        const MobilizedBody& body = m.mobods[static_cast<size_t>(output.body)];
        const Eigen::Vector3d d =
            output.body_frame ? Eigen::Vector3d(ToEigen33(body.getBodyRotation(state).asMat33()) *
                                                output.direction)
                              : output.direction;
        const Vec3 v = output.type == OutputType::kVelocity
                           ? body.findStationVelocityInGround(state, output.station)
                       : output.type == OutputType::kAcceleration
                           ? body.findStationAccelerationInGround(state, output.station)
                           : body.getBodyAngularVelocity(state);
        value = ToEigen3(v).dot(d);
      }
    }
    y[static_cast<Eigen::Index>(i)] = value;
  }
  return y;
}

}  // namespace mbid::model
