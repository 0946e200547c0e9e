// SPDX-License-Identifier: BSD-2-Clause
#include "pkm4puu/dynamics/regressor.hpp"

#include <cmath>
#include <string>

#include "pkm4puu/dynamics/regressor_lanes.hpp"

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
  Mat4 Arho;
  Vec4 r;
  Pose x = pose;
  Status s = slider_positions_lanes(m, platform_config(x), r, Arho);
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
      s = xt.allFinite() ? slider_positions_lanes(m, platform_config(xt), rt, At) : Status::Unreachable;
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
  s = joint_regressor_lanes(m, platform_config(pose), rhod, rhodd, we, out);
  if (s == Status::Ok) out.pose = pose;
  return s;
}

}  // namespace pkm
