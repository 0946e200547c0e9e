// SPDX-License-Identifier: BSD-2-Clause
// Inverse dynamics (Eqs. 10-11) in reduced, leg-partitioned form. With
// qd_i = A_i pd and qdd_i = A_i pdd + b_i
// (reduced_dynamics.hpp), projecting Eq. 1 on B = [A_1; ...; A_4; I4]
// removes lambda and leaves four equations for the four forces:
//   J_rho^T F = sum_i A_i^T tau_i + M_p pdd + V_p + G_p - we,
//   tau_i = M_i qdd_i + V_i + G_i - F_passive,i e_0,
// J_rho's row i being A_i's first row (d rho_i/dp). Each leg's position is
// its closed-form inverse kinematics (elbow-down): no iteration. Leg i's
// rows of Eq. 1 then give its multipliers, lambda_i = L_i^{-T} (F_i e_0 -
// tau_i) (Eq. 10 leg by leg), computed only when asked.
#pragma once

#include "pkm4puu/base/lanes.hpp"
#include "pkm4puu/model/model.hpp"

namespace pkm {

struct InverseDynamicsResult;
struct InverseActuators;

/// The reduced inverse dynamics of the machine (rotor, payload, friction
/// and, beyond a stop, the stop's force, as actuator_forces) for the
/// platform motion (pose, pd, pdd) under the external wrench `we`, into
/// `full` (q, qd, qdd, lambda, F, tau, beyond_stops) if given, else into
/// `act`. Status::Unreachable if a leg is out of reach, ::Singular at a leg
/// or parallel singularity, ::NonFinite for a non-finite argument,
/// The Best copy (lanes::Kernel); the overload with `kind` runs the copy
/// asked for, ::InvalidArgument for one this build, processor or kernel does
/// not have (it has no one-leg Scalar copy).
Status reduced_inverse(const Model& m, const Pose& pose, const Pose& pd, const Pose& pdd, const Wrench& we,
                       InverseDynamicsResult* full, InverseActuators* act);
Status reduced_inverse(const Model& m, const Pose& pose, const Pose& pd, const Pose& pdd, const Wrench& we,
                       InverseDynamicsResult* full, InverseActuators* act, lanes::Kernel kind);

}  // namespace pkm
