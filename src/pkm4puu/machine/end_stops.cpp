// SPDX-License-Identifier: BSD-2-Clause
#include "pkm4puu/machine/end_stops.hpp"

#include <limits>

#include "pkm4puu/kinematics/actuator_positions.hpp"

namespace pkm {

Status stop_indicators(const Model& m, const Pose& pose, unsigned stops, double z[kStopIndicators]) {
  Vec4 rho;
  const Status s = actuator_positions(m, pose, rho);
  if (s == Status::Ok) stop_indicators(m.p, rho, stops, z);
  return s;
}

}  // namespace pkm
