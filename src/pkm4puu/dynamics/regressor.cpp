// SPDX-License-Identifier: BSD-2-Clause
#include "pkm4puu/dynamics/regressor.hpp"

#include <cmath>
#include <string>

#include "pkm4puu/dynamics/reduced_dynamics.hpp"
#include "pkm4puu/dynamics/regressor_lanes.hpp"
#include "pkm4puu/machine/end_stops.hpp"
#include "pkm4puu/machine/friction.hpp"

namespace pkm {
namespace {

constexpr RegressorParamInfo kInfo[kParams] = {
    {"m_slider", "kg", "mass of each slider"},
    {"m_rod", "kg", "mass of each rod (centre of mass at l/2)"},
    {"I_rod[1]", "kg.m2", "rod inertia about DH frame 3's x axis"},
    {"I_rod[2]", "kg.m2", "rod inertia about DH frame 3's y axis"},
    {"I_rod[3]", "kg.m2", "rod inertia about DH frame 3's z axis"},
    {"m_platform", "kg", "platform mass"},
    {"Izz_platform", "kg.m2", "platform inertia about z through P"},
    {"payload_mass", "kg", "payload mass"},
    {"payload_mx", "kg.m", "payload first moment, payload_mass * payload_com[1]"},
    {"payload_my", "kg.m", "payload first moment, payload_mass * payload_com[2]"},
    {"payload_Izz_P", "kg.m2", "payload inertia about z through P, payload_Izz + payload_mass |payload_com|^2"},
    {"rotor_inertia", "kg.m2", "rotor inertia of each drive (motor + screw)"},
    {"friction_viscous", "N.s/m", "viscous friction coefficient of each slider"},
    {"friction_coulomb", "N", "Coulomb friction force of each slider (tanh regularised, friction_velocity fixed)"},
};

/// Closed-form legs at pose pc (elbow-down) and their A_i; rho receives the sliders.
Status prepare_legs(const Model& m, const PlatformConfig& pc, ReducedDynamics& rd, Vec4& rho, Mat4& Arho) {
  for (int i = 0; i < kLegs; ++i) {
    LegConfig c;
    Status s = leg_inverse_kinematics(m, i, pc, c);
    if (s != Status::Ok) return s;
    s = rd.prepare_leg_kinematics(m, i, c, pc);
    if (s != Status::Ok) return s;
    rho[i] = c.rho;
    Arho.row(i) = rd.leg(i).A.row(0);  // d rho_i / d pose
  }
  return Status::Ok;
}

/// b_i = -L_i^{-1} gamma_i: qdd_i = A_i pdd + b_i (reduced_dynamics.hpp).
Vec3 leg_bias(const Model& m, const ReducedDynamics& rd, int i, const Vec3& qd, double phid) {
  const ReducedDynamics::Leg& L = rd.leg(i);
  const Vec3 gamma = rotate_to_base(m, i, leg_point_quadratic(m.p, L.c, qd[1], qd[2])) + L.attach * (phid * phid);
  return -(L.Linv * gamma);
}

/// (R2): Y and F0 from the prepared legs, the platform's rate and acceleration.
Status assemble(const Model& m, const ReducedDynamics& rd, const Mat4& Arho, const Pose& pd, const Pose& pdd,
                const Wrench& we, RegressorSample& out) {
  const Params& p = m.p;
  const double g = p.g, l = p.l, k2 = m.drive_ratio * m.drive_ratio;
  Eigen::Matrix<double, 4, kParams> Z = Eigen::Matrix<double, 4, kParams>::Zero();  // B^T D
  for (int i = 0; i < kLegs; ++i) {
    const ReducedDynamics::Leg& L = rd.leg(i);
    const Vec3 qd = L.A * pd;
    const Vec3 qdd = L.A * pdd + leg_bias(m, rd, i, qd, pd[3]);
    const double c2 = L.c.c2, s2 = L.c.s2, sc = s2 * c2;
    const double th1d = qd[1], th2d = qd[2];
    // D_i: the leg's rows of M qdd + V + G per parameter (lagrangian.hpp's M_leg,
    // leg_coriolis, leg_gravity differentiated in each parameter).
    Eigen::Matrix<double, 3, 6> D;
    D.col(0) << qdd[0] + g, 0.0, 0.0;                                                       // m_slider
    D.col(1) << qdd[0] + 0.5 * l * (c2 * qdd[2] - s2 * th2d * th2d) + g,                   // m_rod
        0.25 * l * l * (c2 * c2 * qdd[1] - 2.0 * sc * th1d * th2d),
        0.5 * l * c2 * (qdd[0] + g) + 0.25 * l * l * (qdd[2] + sc * th1d * th1d);
    D.col(2) << 0.0, s2 * s2 * qdd[1] + 2.0 * sc * th1d * th2d, -sc * th1d * th1d;         // I_rod[1]
    D.col(3) << 0.0, c2 * c2 * qdd[1] - 2.0 * sc * th1d * th2d, sc * th1d * th1d;          // I_rod[2]
    D.col(4) << 0.0, 0.0, qdd[2];                                                           // I_rod[3]
    D.col(5) << k2 * qdd[0], 0.0, 0.0;                                                      // rotor_inertia
    const Eigen::Matrix<double, 4, 6> AD = L.A.transpose() * D;
    Z.leftCols<5>() += AD.leftCols<5>();
    Z.col(kPiRotor) += AD.col(5);
    out.rhod[i] = qd[0];
  }
  // The platform with its payload (lagrangian.hpp's M_p and V_p per parameter).
  const double c = rd.cos_phi(), s = rd.sin_phi(), w2 = pd[3] * pd[3];
  const Vec4 translational(pdd[0], pdd[1], pdd[2] + g, 0.0);
  Z.col(kPiPlatform) += translational;
  Z.col(kPiPayload) += translational;
  Z(3, kPiPlatformIzz) += pdd[3];
  Z(3, kPiPayloadIzzP) += pdd[3];
  Z.col(kPiPayloadMx) += Vec4(-s * pdd[3] - c * w2, c * pdd[3] - s * w2, 0.0, -s * pdd[0] + c * pdd[1]);
  Z.col(kPiPayloadMy) += Vec4(-c * pdd[3] + s * w2, -s * pdd[3] - c * w2, 0.0, -c * pdd[0] - s * pdd[1]);

  const Eigen::PartialPivLU<Mat4> lu(Arho.transpose());
  if (!(std::abs(lu.determinant()) > 0.0)) return Status::Singular;
  out.Y = lu.solve(Z);
  out.F0 = -lu.solve(we);
  for (int i = 0; i < kLegs; ++i) {
    // F = ... - F_fric - F_stop with F_fric = -b rhod - F_c tanh(rhod / v_s) (friction.hpp).
    out.Y(i, kPiViscous) = out.rhod[i];
    out.Y(i, kPiCoulomb) = std::tanh(out.rhod[i] / p.friction_velocity);
    out.F0[i] -= stop_force(p, out.rho[i], out.rhod[i]);
  }
  out.pose_d = pd;
  out.pose_dd = pdd;
  out.beyond_stops = stops_passed(p, out.rho);
  return out.Y.allFinite() && out.F0.allFinite() ? Status::Ok : Status::Singular;
}

}  // namespace

RegressorParamInfo regressor_param_info(int j) {
  if (j < 0 || j >= kParams) return {nullptr, nullptr, nullptr};
  return kInfo[j];
}

ParamVector parameter_vector(const Params& p) {
  ParamVector pi;
  const double cx = p.payload_com[0], cy = p.payload_com[1];
  pi << p.m_slider, p.m_rod, p.I_rod[0], p.I_rod[1], p.I_rod[2], p.m_platform, p.Izz_platform, p.payload_mass,
      p.payload_mass * cx, p.payload_mass * cy, p.payload_Izz + p.payload_mass * (cx * cx + cy * cy), p.rotor_inertia,
      p.friction_viscous, p.friction_coulomb;
  return pi;
}

Status apply_parameter_vector(const ParamVector& pi, Params& p, std::string* error) {
  auto fail = [&](const std::string& why) {
    if (error) *error = why;
    return Status::InvalidParameter;
  };
  if (!pi.allFinite()) return fail("the parameter vector has a non-finite entry");
  Params q = p;
  q.m_slider = pi[kPiSlider];
  q.m_rod = pi[kPiRod];
  q.I_rod = {pi[kPiRodIx], pi[kPiRodIy], pi[kPiRodIz]};
  q.m_platform = pi[kPiPlatform];
  q.Izz_platform = pi[kPiPlatformIzz];
  q.payload_mass = pi[kPiPayload];
  if (q.payload_mass > 0.0) {
    q.payload_com = {pi[kPiPayloadMx] / q.payload_mass, pi[kPiPayloadMy] / q.payload_mass};
  } else if (pi[kPiPayloadMx] != 0.0 || pi[kPiPayloadMy] != 0.0) {
    return fail("payload_mx, payload_my need a positive payload_mass");
  } else {
    q.payload_com = {0.0, 0.0};
  }
  const double c2 = q.payload_com[0] * q.payload_com[0] + q.payload_com[1] * q.payload_com[1];
  q.payload_Izz = pi[kPiPayloadIzzP] - q.payload_mass * c2;
  q.rotor_inertia = pi[kPiRotor];
  q.friction_viscous = pi[kPiViscous];
  q.friction_coulomb = pi[kPiCoulomb];
  const std::string why = validate(q);
  if (!why.empty()) return fail(why);
  p = q;
  return Status::Ok;
}

Status regressor(const Model& m, const Pose& pose, const Pose& pose_d, const Pose& pose_dd, const Wrench& we,
                 RegressorSample& out) {
  if (!pose.allFinite() || !pose_d.allFinite() || !pose_dd.allFinite() || !we.allFinite()) return Status::NonFinite;
  // The reduced, leg-partitioned form (regressor_lanes.hpp).
  const Status s = regressor_lanes(m, platform_config(pose), pose_d, pose_dd, we, out);
  if (s == Status::Ok) out.pose = pose;
  return s;
}

Status forward_position(const Model& m, const Vec4& rho, Pose& pose) {
  if (!rho.allFinite() || !pose.allFinite()) return Status::NonFinite;
  ReducedDynamics rd;
  Mat4 Arho;
  Vec4 r;
  Pose x = pose;
  Status s = prepare_legs(m, platform_config(x), rd, r, Arho);
  if (s != Status::Ok) return s;
  double err = (rho - r).lpNorm<Eigen::Infinity>();
  for (int it = 0; it < 30; ++it) {
    if (err <= 1e-14) {  // NewtonOptions' residual_tol
      pose = x;
      return Status::Ok;
    }
    const Eigen::PartialPivLU<Mat4> lu(Arho);
    if (!(std::abs(lu.determinant()) > 0.0)) return Status::Singular;
    const Pose dx = lu.solve(rho - r);  // Newton on rho(pose) = rho
    // Halve the step while it leaves a leg's reach or does not reduce the
    // residual (a far guess); the full step near the solution.
    double t = 1.0;
    for (int k = 0;; ++k) {
      const Pose xt = x + t * dx;
      Vec4 rt = Vec4::Zero();
      Mat4 At = Mat4::Zero();
      ReducedDynamics rdt;
      s = xt.allFinite() ? prepare_legs(m, platform_config(xt), rdt, rt, At) : Status::Unreachable;
      const double et = s == Status::Ok ? (rho - rt).lpNorm<Eigen::Infinity>() : HUGE_VAL;
      if (et < err || (s == Status::Ok && err <= 1e-12)) {
        x = xt;
        r = rt;
        Arho = At;
        err = et;
        break;
      }
      if (k == 30) return s == Status::Ok ? Status::NotConverged : Status::Unreachable;
      t *= 0.5;
    }
  }
  return Status::NotConverged;
}

Status joint_regressor(const Model& m, const Vec4& rho, const Vec4& rhod, const Vec4& rhodd, const Wrench& we,
                       RegressorSample& out) {
  if (!rho.allFinite() || !rhod.allFinite() || !rhodd.allFinite() || !we.allFinite()) return Status::NonFinite;
  Pose pose = out.pose;
  Status s = forward_position(m, rho, pose);
  if (s != Status::Ok) return s;
  ReducedDynamics rd;
  Mat4 Arho;
  s = prepare_legs(m, platform_config(pose), rd, out.rho, Arho);
  if (s != Status::Ok) return s;
  const Eigen::PartialPivLU<Mat4> lu(Arho);
  if (!(std::abs(lu.determinant()) > 0.0)) return Status::Singular;
  // rhod = A_rho pd; rhodd = A_rho pdd + b_rho (the b_i's rho rows).
  const Pose pd = lu.solve(rhod);
  Vec4 b_rho;
  for (int i = 0; i < kLegs; ++i) b_rho[i] = leg_bias(m, rd, i, rd.leg(i).A * pd, pd[3])[0];
  const Pose pdd = lu.solve(rhodd - b_rho);
  out.pose = pose;
  return assemble(m, rd, Arho, pd, pdd, we, out);
}

}  // namespace pkm
