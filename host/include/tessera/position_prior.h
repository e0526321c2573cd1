#pragma once

#include <Eigen/Core>

namespace tessera {

// A camera centre held near a known position in bundle adjustment (a GPS prior in the
// model's frame), with its standard deviation per axis in the model's units.
struct PositionPrior {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // world frame
  Eigen::Vector3d sigma = Eigen::Vector3d::Ones();     // > 0 per axis
};

}  // namespace tessera
