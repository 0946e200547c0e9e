// SPDX-License-Identifier: BSD-2-Clause
// Eq. 13 with the null-space basis taken from the leg blocks (coordinate
// partitioning, platform pose independent), built leg by leg.
//
// Leg i's closure C_i = 0 differentiated once and twice:
//   L_i qd_i = P_i pd,                  L_i = Rz(beta_i) J_i, P_i = [I3, e_z x Rz(phi) r_Qi]
//   L_i qdd_i = P_i pdd - gamma_i,      gamma_i = Rz(beta_i) (J_i qd_i)_q qd_i + Rz(phi) r_Qi phid^2
// so qd_i = A_i pd and qdd_i = A_i pdd + b_i with A_i = L_i^{-1} P_i and
// b_i = -L_i^{-1} gamma_i. Projecting Eq. 1 on B = [A_1; ...; A_4; I4]:
//   (M_p + sum A_i^T M_i A_i) pdd = f_p - G_p + sum A_i^T (f_i - V_i - G_i - M_i b_i)
// and each leg's rows give its multipliers: lambda_i = L_i^{-T} (f_i - M_i qdd_i - V_i - G_i).
#pragma once

#include <array>

#include "pkm4puu/dynamics/leg_lanes.hpp"
#include "pkm4puu/kinematics/leg_kinematics.hpp"

namespace pkm {

class ReducedDynamics {
 public:
  /// Leg i's configuration-dependent terms. Status::Singular at a leg
  /// singularity.
  Status prepare_leg(const Model& m, int leg, const LegConfig& c, const PlatformConfig& pc);
  /// Only what leg_velocity needs (L_i^{-1}, A_i), without the leg's mass
  /// matrix: the legs' rates from the platform's.
  Status prepare_leg_kinematics(const Model& m, int leg, const LegConfig& c, const PlatformConfig& pc);

  /// qd_i = A_i pd (valid after prepare_leg).
  Vec3 leg_velocity(int leg, const Pose& pd) const { return legs_[leg].A * pd; }

  /// Adds leg i's contribution, with its rates qd_leg, the platform's
  /// angular rate phid and the generalised force F on rho_i (actuator,
  /// drive, friction and end stop together).
  void add_leg(const Model& m, int leg, const Vec3& qd_leg, double phid, double F);

  /// Solves the reduced 4x4 system (with the external wrench on the
  /// platform) and recovers the full qdd and lambda.
  Status solve(const Model& m, const Wrench& we, Vec16& qdd, Vec12& lambda);

  /// Only the platform's accelerations (the integrators' hot path).
  Status solve_platform(const Model& m, const Wrench& we, Pose& pdd) const;

  /// The reduced system Mr pdd = rhs with the platform, its payload and the
  /// external wrench included (Mr full and symmetric; valid after add_leg
  /// for every leg).
  void reduced_system(const Model& m, const Wrench& we, Mat4& Mr, Vec4& rhs) const;

  /// The integrators' hot path (state_derivative): the platform's
  /// accelerations pdd without keeping the legs' terms (solve() needs them,
  /// solve_platform does not). The same arithmetic as prepare_leg,
  /// leg_velocity, add_leg and solve_platform, with the zeros and ones of
  /// J_i^{-1}, A_i and M_i written out, computed for the four legs at once
  /// as lanes and summed in leg order: bit for bit the same result. f holds
  /// the applied forces (on rho_i at leg_offset(i)); the passive joint
  /// forces (stops held as `stops`) are added here. rho and rhod (if given)
  /// receive the actuated joints and their rates, untouched on failure. On
  /// failure the status of the first failing leg (Unreachable, Singular),
  /// as leg by leg; InvalidArgument for a copy this build or processor
  /// does not have (lanes::Kernel).
  static Status platform_derivative(const Model& m, const PlatformConfig& pc, const Pose& pd, const Vec16& f,
                                    unsigned stops, Vec4* rho, Vec4* rhod, Pose& pdd,
                                    lanes::Kernel kind = lanes::Kernel::Best);

  /// platform_derivative's solve: pdd from the legs' sums (leg_sums) with
  /// the platform, its payload and the external wrench; the same bits.
  static Status solve_leg_sums(const Model& m, const Wrench& we, const LegSums& sums, const PlatformConfig& pc,
                               double phid, Pose& pdd);
  /// The reduced mass matrix Mr of the same sums (reduced_system's, full).
  static Mat4 reduced_mass(const Model& m, const LegSums& sums, const PlatformConfig& pc);

  struct Leg {
    LegConfig c;
    Vec3 attach;  // Rz(phi) r_Qi
    Mat3 Linv;    // L_i^{-1}
    Mat3 Jinv;    // J_i^{-1} = L_i^{-1} Rz(beta_i)
    Mat34 A;      // L_i^{-1} P_i
    Mat3 M;       // leg mass matrix
    Vec3 b;       // -L_i^{-1} gamma_i
    Vec3 r;       // f_i - V_i - G_i - M_i b_i
  };
  /// Leg i's terms (valid after prepare_leg; b and r after add_leg).
  const Leg& leg(int i) const { return legs_[i]; }
  double cos_phi() const { return cphi_; }
  double sin_phi() const { return sphi_; }

 private:
  std::array<Leg, kLegs> legs_;
  Mat4 Mr_ = Mat4::Zero();
  double cphi_ = 1, sphi_ = 0, phid_ = 0;  // the platform's angle and rate (payload terms)
  Vec4 rhs_ = Vec4::Zero();
};

}  // namespace pkm
