#include "pkm4puu/machine/machine.hpp"

#include "pkm4puu/kinematics/leg_kinematics.hpp"

namespace pkm {

// actuator_positions: reduced_dynamics.cpp (the derivative's legs as lanes).

Status stop_indicators(const Model& m, const Pose& pose, double g[kStopIndicators]) {
  Vec4 rho;
  const Status s = actuator_positions(m, pose, rho);
  if (s == Status::Ok) stop_indicators(m.p, rho, g);
  return s;
}

}  // namespace pkm
