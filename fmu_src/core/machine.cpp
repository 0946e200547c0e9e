#include "machine.hpp"

#include "leg_kinematics.hpp"

namespace pkm {

Status actuator_positions(const Model& m, const Pose& pose, Vec4& rho) {
  if (!pose.allFinite()) return Status::NonFinite;
  const PlatformConfig pc = platform_config(pose);
  for (int i = 0; i < kLegs; ++i) {
    LegConfig c;
    const Status s = leg_inverse_kinematics(m, i, pc, c);
    if (s != Status::Ok) return s;
    rho[i] = c.rho;
  }
  return Status::Ok;
}

Status stop_indicators(const Model& m, const Pose& pose, double g[kStopIndicators]) {
  Vec4 rho;
  const Status s = actuator_positions(m, pose, rho);
  if (s == Status::Ok) stop_indicators(m.p, rho, g);
  return s;
}

}  // namespace pkm
