// SPDX-License-Identifier: BSD-2-Clause
// Independent reference model of the 4-PUU PKM, written only from
// docs/model.md (not from src/), for checking the main code.
// Kinematics by literal DH products; kinetic energy from body velocities by
// finite differences (no hand-derived mass matrix).
#ifndef PKM4PUU_TESTS_REFERENCE_MODEL_HPP
#define PKM4PUU_TESTS_REFERENCE_MODEL_HPP

#include <array>
#include <cmath>

#include <Eigen/Dense>

namespace ref {

using Q = Eigen::Matrix<double, 16, 1>;  // [rho_i, th1_i, th2_i]x4, x, y, z, phi

constexpr double kPi = 3.14159265358979323846;

// Spec "Geometry defaults (Table II)", "Leg placement", "Bodies (Table III)"; SI units.
struct RefParams {
  double h = 0.06634, l = 0.080, h_prime = 0.075, r_b = 0.09273, r_Q = 0.075;
  std::array<double, 4> beta{0.0, kPi / 2, kPi, 3 * kPi / 2};  // (i-1)*pi/2
  std::array<double, 4> gamma{65 * kPi / 180, -65 * kPi / 180,
                              65 * kPi / 180, -65 * kPi / 180};
  double m_slider = 0.09331;
  double m_rod = 0.06371;
  std::array<double, 3> I_rod{3.83e-6, 49.86e-6, 52.64e-6};  // DH frame 3 axes
  double m_platform = 0.45474;
  double Izz_platform = 2874.21e-6;
  double g = 9.81;
  // Spec "The machine around the mechanism": drives and payload (defaults: none).
  double screw_lead = 0.004;   // m per revolution
  double rotor_inertia = 0.0;  // kg m^2, turns at 2 pi rhod / screw_lead rad/s
  double payload_mass = 0.0;   // kg, rigidly on the platform
  std::array<double, 2> payload_com{0.0, 0.0};  // platform frame, relative to P, at P's height
  double payload_Izz = 0.0;    // kg m^2 about its own centre of mass
};


// Elementary homogeneous transforms.
inline Eigen::Matrix4d rot_z(double t) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T(0, 0) = std::cos(t); T(0, 1) = -std::sin(t);
  T(1, 0) = std::sin(t); T(1, 1) = std::cos(t);
  return T;
}
inline Eigen::Matrix4d rot_x(double t) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T(1, 1) = std::cos(t); T(1, 2) = -std::sin(t);
  T(2, 1) = std::sin(t); T(2, 2) = std::cos(t);
  return T;
}
inline Eigen::Matrix4d trans(double x, double y, double z) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T(0, 3) = x; T(1, 3) = y; T(2, 3) = z;
  return T;
}

// Spec "Leg kinematics": standard DH, T = Rz(theta) * Tz(d) * Tx(a) * Rx(alpha).
inline Eigen::Matrix4d dh(double alpha, double a, double d, double theta) {
  return rot_z(theta) * trans(0, 0, d) * trans(a, 0, 0) * rot_x(alpha);
}

// World transform of DH frame j (0..4) of leg (0..3).
// j = 0: base frame 0_i (spec "Leg placement"): origin B_i, orientation Rz(beta_i).
// j = 1..4: times Table I rows 1..j.
inline Eigen::Matrix4d leg_frame(const RefParams& p, const Q& q, int leg, int j) {
  const double b = p.beta[leg];
  const double rho = q(3 * leg), th1 = q(3 * leg + 1), th2 = q(3 * leg + 2);
  Eigen::Matrix4d T = trans(p.r_b * std::cos(b), p.r_b * std::sin(b), 0) * rot_z(b);
  if (j >= 1) T = T * dh(0, 0, rho + p.h, 0);
  if (j >= 2) T = T * dh(kPi / 2, 0, 0, th1);
  if (j >= 3) T = T * dh(0, p.l, 0, th2);
  if (j >= 4) T = T * dh(-kPi / 2, 0, p.h_prime, -th2);
  return T;
}

// Spec "Bodies": rod (link 3) CoM = midpoint of origins O2 and O3.
inline Eigen::Vector3d rod_com_world(const RefParams& p, const Q& q, int leg) {
  return 0.5 * (leg_frame(p, q, leg, 2).block<3, 1>(0, 3) +
                leg_frame(p, q, leg, 3).block<3, 1>(0, 3));
}

// Rotation of DH frame 3 (rod body axes) in the world frame.
inline Eigen::Matrix3d rod_rotation_world(const RefParams& p, const Q& q, int leg) {
  return leg_frame(p, q, leg, 3).block<3, 3>(0, 0);
}

// Spec "Constraints (Eq. 15)": C_i = O4_i (point Q_i) - (p + Rz(phi) r_Qi).
inline Eigen::Matrix<double, 12, 1> constraints(const RefParams& p, const Q& q) {
  Eigen::Matrix<double, 12, 1> C;
  const Eigen::Vector3d P(q(12), q(13), q(14));
  const Eigen::Matrix3d Rphi = rot_z(q(15)).block<3, 3>(0, 0);
  for (int i = 0; i < 4; ++i) {
    const double a = p.beta[i] + p.gamma[i];
    const Eigen::Vector3d rQ(p.r_Q * std::cos(a), p.r_Q * std::sin(a), 0);
    C.segment<3>(3 * i) = leg_frame(p, q, i, 4).block<3, 1>(0, 3) - (P + Rphi * rQ);
  }
  return C;
}

// 4th-order central difference of f(q + s*qd) at s = 0 (f returns an Eigen type).
template <class F>
auto ddir(F f, const Q& q, const Q& qd) {
  const double qmax = qd.cwiseAbs().maxCoeff();
  const double s = 1e-3 / (qmax > 1.0 ? qmax : 1.0);  // step in s, scaled by |qd|
  using R = decltype(f(q));
  R r = (f(q - 2 * s * qd) - 8 * f(q - s * qd) + 8 * f(q + s * qd) - f(q + 2 * s * qd)) /
        (12 * s);
  return r;
}

// The payload's centre of mass in the world: P + Rz(phi) c.
inline Eigen::Vector3d payload_com_world(const RefParams& p, const Q& q) {
  const Eigen::Vector3d c(p.payload_com[0], p.payload_com[1], 0.0);
  return Eigen::Vector3d(q(12), q(13), q(14)) + rot_z(q(15)).block<3, 3>(0, 0) * c;
}

// Spec "Bodies (Table III)": T = sum over legs (slider + rod) + platform,
// plus the machine's rotors (1/2 J w^2, w = 2 pi rhod / lead) and payload
// (its centre's velocity by finite differences, 1/2 I_l phid^2).
inline double kinetic_energy(const RefParams& p, const Q& q, const Q& qd) {
  double T = 0;
  const Eigen::Vector3d Irod(p.I_rod[0], p.I_rod[1], p.I_rod[2]);
  for (int i = 0; i < 4; ++i) {
    // Slider (link 1): translates along world z at rate rho_dot.
    T += 0.5 * p.m_slider * qd(3 * i) * qd(3 * i);
    // Rod (link 3): CoM velocity and angular velocity from finite differences.
    const Eigen::Vector3d v = ddir([&](const Q& qq) { return rod_com_world(p, qq, i); }, q, qd);
    const Eigen::Matrix3d R = rod_rotation_world(p, q, i);
    const Eigen::Matrix3d Rdot =
        ddir([&](const Q& qq) { return rod_rotation_world(p, qq, i); }, q, qd);
    const Eigen::Matrix3d W = Rdot * R.transpose();  // omega_hat (world)
    const Eigen::Vector3d w_world(W(2, 1), W(0, 2), W(1, 0));
    const Eigen::Vector3d w_body = R.transpose() * w_world;
    T += 0.5 * p.m_rod * v.squaredNorm() + 0.5 * w_body.dot(Irod.cwiseProduct(w_body));
  }
  // Platform: CoM at P, rotates about z only.
  T += 0.5 * p.m_platform * qd.segment<3>(12).squaredNorm() +
       0.5 * p.Izz_platform * qd(15) * qd(15);
  for (int i = 0; i < 4; ++i) {
    const double w = 2 * kPi * qd(3 * i) / p.screw_lead;
    T += 0.5 * p.rotor_inertia * w * w;
  }
  if (p.payload_mass != 0.0 || p.payload_Izz != 0.0) {
    const Eigen::Vector3d v = ddir([&](const Q& qq) { return payload_com_world(p, qq); }, q, qd);
    T += 0.5 * p.payload_mass * v.squaredNorm() + 0.5 * p.payload_Izz * qd(15) * qd(15);
  }
  return T;
}

// Spec "Bodies" + gravity along -z_G. The slider's height is taken at the
// frame-1 origin (world z = rho + h); constant offsets per body are irrelevant.
inline double potential_energy(const RefParams& p, const Q& q) {
  double V = 0;
  for (int i = 0; i < 4; ++i) {
    V += p.m_slider * p.g * leg_frame(p, q, i, 1)(2, 3);
    V += p.m_rod * p.g * rod_com_world(p, q, i)(2);
  }
  return V + p.m_platform * p.g * q(14) + p.payload_mass * p.g * payload_com_world(p, q)(2);
}

/// Where leg `i`'s rod turns horizontal (theta2 = 0) as the platform moves
/// along +x from home (y = 0, phi = 0; z does not enter): in spec_guards'
/// terms A = l, so (x + d_x(0))^2 + d_y^2 - h'^2 = l^2, d_y being constant
/// along x: x = sqrt(l^2 + h'^2 - d_y^2) - d_x(0).
inline double x_rod_horizontal(int i) {
  const RefParams p;
  const int k = i - 1;
  const double dx0 = p.r_Q * std::cos(p.beta[k] + p.gamma[k]) - p.r_b * std::cos(p.beta[k]);
  const double dy = p.r_Q * std::sin(p.beta[k] + p.gamma[k]) - p.r_b * std::sin(p.beta[k]);
  return std::sqrt(p.l * p.l + p.h_prime * p.h_prime - dy * dy) - dx0;
}

}  // namespace ref

#endif  // PKM4PUU_TESTS_REFERENCE_MODEL_HPP
