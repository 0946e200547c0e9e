// SPDX-License-Identifier: BSD-2-Clause
// The dynamic-parameter regressor: the actuator forces of the inverse
// dynamics (inverse_dynamics.hpp) are linear in the bodies' masses, first
// moments and inertias, the rotor inertia and the friction coefficients
// (for a fixed friction_velocity), so
//   F = Y(q, qd, qdd) pi + F0                                  (R1)
// with pi the parameter vector below (kParams entries) and F0 the part
// that does not depend on pi: the external wrench and, beyond a stop, the
// end stop's force. By virtual power with qd = B pd, B = [A_1; ..; A_4; I4]
// (reduced_dynamics.hpp) and A_rho the rows of the A_i on rho_i:
//   A_rho^T (F + F_passive) = B^T (M qdd + V + G) - we          (R2)
// and M qdd + V + G = D(q, qd, qdd) pi, column by column (regressor.cpp).
#pragma once

#include "pkm4puu/model/model.hpp"

namespace pkm {

/// The parameter vector pi (docs/calibration.md): index, name, unit.
enum RegressorParam : int {
  kPiSlider = 0,      // m_slider, kg
  kPiRod,             // m_rod, kg (centre of mass at l/2: its first moment m_rod l/2)
  kPiRodIx,           // I_rod[1], kg*m^2
  kPiRodIy,           // I_rod[2], kg*m^2
  kPiRodIz,           // I_rod[3], kg*m^2
  kPiPlatform,        // m_platform, kg
  kPiPlatformIzz,     // Izz_platform, kg*m^2
  kPiPayload,         // payload_mass, kg
  kPiPayloadMx,       // payload_mass payload_com[1], kg*m
  kPiPayloadMy,       // payload_mass payload_com[2], kg*m
  kPiPayloadIzzP,     // payload_Izz + payload_mass |payload_com|^2 (about P), kg*m^2
  kPiRotor,           // rotor_inertia, kg*m^2
  kPiViscous,         // friction_viscous, N*s/m
  kPiCoulomb,         // friction_coulomb, N
  kParams
};

struct RegressorParamInfo {
  const char* name;
  const char* unit;
  const char* what;
};
/// Name, unit and meaning of pi's entry j (nullptr name outside 0..kParams-1).
RegressorParamInfo regressor_param_info(int j);

using ParamVector = Eigen::Matrix<double, kParams, 1>;
using Regressor = Eigen::Matrix<double, kLegs, kParams>;

/// pi of a parameter set (the payload as mass, first moments, inertia about P).
ParamVector parameter_vector(const Params& p);

/// Writes pi into p's body, drive and friction parameters (the inverse of
/// parameter_vector): the payload's centre of mass is m_x / m, its inertia
/// about its centre I_P - m |c|^2. InvalidParameter (why in `error`) when
/// that is not a parameter set: a first moment without a payload mass, or
/// the result fails validate().
Status apply_parameter_vector(const ParamVector& pi, Params& p, std::string* error = nullptr);

/// One sample of (R1): Y, F0, and the joints' positions and rates.
struct RegressorSample {
  Regressor Y = Regressor::Zero();
  Vec4 F0 = Vec4::Zero();
  Vec4 rho = Vec4::Zero(), rhod = Vec4::Zero();
  Pose pose = Pose::Zero(), pose_d = Pose::Zero(), pose_dd = Pose::Zero();
  /// Bit i: rho_i < rho_min; bit 4 + i: rho_i > rho_max (stops_passed).
  unsigned beyond_stops = 0;
};

/// (R1) at a platform motion (pose, its rate and acceleration) with the
/// external wrench `we`. Unreachable off the workspace, Singular at a leg
/// singularity, NonFinite for a non-finite input.
Status regressor(const Model& m, const Pose& pose, const Pose& pose_d, const Pose& pose_dd, const Wrench& we,
                 RegressorSample& out);

/// The platform pose at the sliders' positions rho (forward kinematics,
/// Newton on the closed-form legs from the guess in `pose`, elbow-down).
/// Unreachable when a slider position has no pose within reach near the
/// guess, NotConverged after 30 iterations.
Status forward_position(const Model& m, const Vec4& rho, Pose& pose);

/// (R1) from the sliders' positions, rates and accelerations (the drive's
/// measurements) through the forward kinematics, starting from the guess
/// out.pose (the previous sample's pose for a trajectory).
Status joint_regressor(const Model& m, const Vec4& rho, const Vec4& rhod, const Vec4& rhodd, const Wrench& we,
                       RegressorSample& out);

}  // namespace pkm
