// SPDX-License-Identifier: BSD-2-Clause
// Model parameters (docs/model.md: Tables II and III, leg placement, gravity),
// in SI units. Defaults are the spec's values, converted once here.
#pragma once

#include <array>
#include <string>

namespace pkm {

constexpr double kPi = 3.14159265358979323846;
constexpr double deg(double d) { return d * kPi / 180.0; }

struct Params {
  // Geometry (Table II), m.
  double h = 0.06634;
  double l = 0.080;
  double h_prime = 0.075;
  double r_b = 0.09273;
  double r_Q = 0.075;
  // Leg placement (spec "Leg placement"), rad.
  std::array<double, 4> beta{0.0, kPi / 2, kPi, 3 * kPi / 2};
  std::array<double, 4> gamma{deg(65), deg(-65), deg(65), deg(-65)};
  // Bodies (Table III): kg and kg*m^2.
  double m_slider = 0.09331;
  double m_rod = 0.06371;
  std::array<double, 3> I_rod{3.83e-6, 49.86e-6, 52.64e-6};  // DH frame 3 axes
  double m_platform = 0.45474;
  double Izz_platform = 2874.21e-6;
  // Gravity along -z_G, m/s^2. Zero is allowed (the comparison test).
  double g = 9.81;

  // The machine around the mechanism (docs/model.md "The machine around the
  // mechanism"). Every default leaves the paper's ideal mechanism unchanged.
  // Drives: a motor on a ball screw per actuator.
  double screw_lead = 0.004;       // m per revolution, > 0
  double rotor_inertia = 0.0;      // kg*m^2 (motor + screw), >= 0
  // Joint friction in each prismatic joint:
  //   F_fric = -friction_viscous rhod - friction_coulomb tanh(rhod / friction_velocity).
  double friction_viscous = 0.0;   // N*s/m, >= 0
  double friction_coulomb = 0.0;   // N, >= 0
  double friction_velocity = 1e-3; // m/s, > 0
  // End stops: each slider travels in [rho_min, rho_max]; past a limit by
  // depth delta > 0 a compliant stop pushes back with k delta + d delta_dot,
  // never pulling.
  double rho_min = 0.0;            // m
  double rho_max = 0.15;           // m, > rho_min
  double stop_stiffness = 1e5;     // N/m, >= 0
  double stop_damping = 100.0;     // N*s/m, >= 0
  // Payload rigidly fixed to the platform: mass, centre of mass in the
  // platform frame relative to P (at P's height), inertia about its own
  // centre of mass.
  double payload_mass = 0.0;                 // kg, >= 0
  std::array<double, 2> payload_com{0.0, 0.0};  // m
  double payload_Izz = 0.0;                  // kg*m^2, >= 0
};

/// Physical ranges of the parameters, which the parameter table
/// (parameter_table.hpp) gives each parameter of Params. A machine
/// of this kind spans decimetres; these bounds leave room for any real one
/// and refuse what only overflows (g = 1e300 made the first step's size NaN).
constexpr double kMaxLength = 10.0;     // m: lengths, |rho_min|, |rho_max|, |payload_com|, screw_lead
constexpr double kMaxMass = 1e4;        // kg
constexpr double kMaxInertia = 1e4;     // kg*m^2
constexpr double kMaxGravity = 1e3;     // m/s^2, |g| (100 times the earth's)
constexpr double kMaxAngle = 10.0 * kPi; // rad, |beta_i|, |gamma_i|
constexpr double kMaxForce = 1e6;       // N: friction_coulomb
constexpr double kMaxDamping = 1e6;     // N*s/m: friction_viscous, stop_damping
constexpr double kMaxStiffness = 1e9;   // N/m: stop_stiffness
constexpr double kMaxSlipSpeed = 10.0;  // m/s: friction_velocity
// The smallest values of the parameters that must be positive. A min in a
// modelDescription is inclusive, so "positive" is declared as these floors,
// far below any real machine's and far above where the dynamics' arithmetic
// over- or underflows: a micrometre (lengths, screw lead), a milligram
// (masses), a milligram at a millimetre (inertias: 1e-6 kg x (1e-3 m)^2),
// a nanometre per second (the Coulomb friction's regularising speed).
constexpr double kMinLength = 1e-6;     // m
constexpr double kMinMass = 1e-6;       // kg
constexpr double kMinInertia = 1e-12;   // kg*m^2
constexpr double kMinSlipSpeed = 1e-9;  // m/s

/// Checks every parameter against its row of the parameter table, then
/// what no row says alone (rho_max above rho_min, the rod's principal
/// moments). Returns an empty string when they are valid, otherwise a
/// message that names the offending parameter and its value.
std::string validate(const Params& p);

}  // namespace pkm
