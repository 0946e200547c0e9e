/* SPDX-License-Identifier: BSD-2-Clause */
/**
 * @file pkm.h
 * pkm.h - plain C API of the 4-PUU Schoenflies-motion parallel robot model
 * (docs/model.md). No C++ types; an opaque handle per simulated machine.
 * SI units throughout: m, kg, s, rad, N, N*m.
 *
 * Every function returns a pkm_status; on anything but PKM_OK the handle's
 * pkm_last_error() says why. A failed call leaves the handle's state as it
 * was before the call (forward dynamics: at the last point reached).
 */
#ifndef PKM_H
#define PKM_H

#include <stddef.h>

#include "pkm4puu/version.h" /* PKM_VERSION_MAJOR/MINOR/PATCH, PKM_VERSION_STRING */

#ifdef __cplusplus
extern "C" {
#endif

/* Exported while building the library (PKM_BUILDING_LIBRARY, set on the
 * library target only); imported from the DLL by its users on Windows;
 * nothing for the static library (PKM_STATIC, set for its users). */
#if defined(PKM_STATIC)
#define PKM_API
#elif defined(_WIN32) && defined(PKM_BUILDING_LIBRARY)
#define PKM_API __declspec(dllexport)
#elif defined(_WIN32)
#define PKM_API __declspec(dllimport)
#elif defined(PKM_BUILDING_LIBRARY)
#define PKM_API __attribute__((visibility("default")))
#else
#define PKM_API
#endif

typedef enum {
  PKM_OK = 0,
  PKM_ERR_INVALID_ARGUMENT = 1,  /**< NULL pointer, bad option */
  PKM_ERR_INVALID_PARAMETER = 2, /**< a model parameter out of range */
  PKM_ERR_NONFINITE = 3,         /**< NaN or Inf in an input */
  PKM_ERR_UNREACHABLE = 4,       /**< pose outside a leg's reach (elbow-down) */
  PKM_ERR_SINGULAR = 5,          /**< leg or parallel singularity */
  PKM_ERR_NOT_CONVERGED = 6,     /**< Newton's method failed its stopping rule */
  PKM_ERR_SOLVER = 7,            /**< the integrator gave up */
  PKM_ERR_NOT_INITIALIZED = 8    /**< forward dynamics before pkm_init_pose */
} pkm_status;

/** Table II/III parameters, leg placement and gravity (docs/model.md). */
typedef struct {
  double h, l, h_prime, r_b, r_Q; /**< m */
  double beta[4], gamma[4];       /**< rad */
  double m_slider, m_rod;         /**< kg */
  double I_rod[3];                /**< kg*m^2, DH frame 3 axes */
  double m_platform;              /**< kg */
  double Izz_platform;            /**< kg*m^2 */
  double g;                       /**< m/s^2, along -z */
} pkm_params;

/* RK4: fixed step, sub-stepped where friction or a held end stop is stiff;
 * ROSENBROCK: fixed-step ROS2, linearly implicit with the analytic Jacobian,
 * for stiff machines in real time (docs/solvers.md). */
typedef enum { PKM_SOLVER_CVODE = 0, PKM_SOLVER_RK4 = 1, PKM_SOLVER_ROSENBROCK = 2 } pkm_solver_kind;
typedef enum { PKM_CVODE_ADAMS = 0, PKM_CVODE_BDF = 1 } pkm_cvode_method;
typedef enum {
  PKM_FORM_AUGMENTED = 0,      /**< Eq. 12 */
  PKM_FORM_NULLSPACE_QR = 1,   /**< Eq. 13, B from a QR of C_q */
  PKM_FORM_LEG_PARTITIONED = 2 /**< Eq. 13, B from the leg blocks (default) */
} pkm_formulation;

typedef struct {
  int solver;      /**< pkm_solver_kind, default CVODE */
  double rk4_step; /**< s, default 1e-3 */
  double rtol;     /**< default 1e-8 */
  double atol;     /**< default 1e-10 */
  int cvode_method; /**< pkm_cvode_method, default Adams */
  int formulation;  /**< pkm_formulation, default leg-partitioned */
  /** Singularity guards, checked at the end of every integration step (RK4:
   * every step; CVODE: every pkm_advance*): a step ending beyond either is
   * undone and PKM_ERR_SINGULAR returned (pkm_last_error names the leg or
   * the condition number); the state stays at the last good point. */
  double max_jacobian_condition; /**< actuator Jacobian (phi column / 0.1 m), > 1, default 1e3 */
  double min_leg_measure;        /**< |cos(theta2) sin(theta2)| of every leg, in [0, 0.5), default 1e-2 */
} pkm_solver_settings;

/** Everything the FMU contract lists, at the current time. */
typedef struct {
  double t;                       /**< s */
  double pose[4];                 /**< x, y, z (m), phi (rad) */
  double velocity[4];             /**< dx, dy, dz (m/s), dphi (rad/s) */
  double acceleration[4];         /**< for the inputs at t */
  double rho[4], drho[4];         /**< m, m/s */
  double theta1[4], theta2[4];    /**< rad; theta1 continuous (unwrapped) */
  double q[16], qd[16], qdd[16];  /**< coordinate order of docs/model.md */
  double lambda[12];              /**< Lagrange multipliers of Eq. 1 */
  double constraint_residual;     /**< ||C(q)||, m */
  double jacobian_condition;      /**< actuator Jacobian, phi column / 0.1 m */
} pkm_outputs;

typedef struct {
  double F[4];                    /**< actuator forces, N */
  double lambda[12];
  double q[16], qd[16], qdd[16];
} pkm_inverse_result;

/** Input callback for pkm_advance_fn: forces F[4] (N) and external wrench
 * wrench[4] = (Fx, Fy, Fz in N, Mz in N*m) at time t. */
typedef void (*pkm_input_fn)(void* user, double t, double F[4], double wrench[4]);

typedef struct pkm_model pkm_model;

PKM_API void pkm_default_params(pkm_params* p);
PKM_API void pkm_default_solver_settings(pkm_solver_settings* s);

/** Creates a model. On failure *out is NULL and, if err is not NULL, a
 * message naming the offending parameter is written into err[err_len]. */
PKM_API pkm_status pkm_create(const pkm_params* p, pkm_model** out, char* err, size_t err_len);
PKM_API void pkm_destroy(pkm_model* m);

/** The library's version, "MAJOR.MINOR.PATCH": PKM_VERSION_STRING of the
 * header it was built with (a program built against another header can
 * compare the two). */
PKM_API const char* pkm_version(void);

PKM_API const char* pkm_last_error(const pkm_model* m);
PKM_API const char* pkm_status_string(pkm_status s);

PKM_API pkm_status pkm_set_solver(pkm_model* m, const pkm_solver_settings* s);

/** The fixed-step solvers' checks (docs/solvers.md), kept by pkm_set_solver:
 * work_budget, the inner steps (grid steps, stiff sub-steps, rejected
 * steps, bisection trials) allowed per grid step, summed over one
 * pkm_advance* and at most 1e5 per call, whatever its length ([1, 1e6],
 * default 1000; beyond, PKM_ERR_SOLVER and pkm_last_error says
 * why); energy_tolerance (J, [0, 1e9], 0 = off, the default): an advance
 * whose energy audit residual exceeds it is undone (PKM_ERR_SOLVER).
 * PKM_ERR_INVALID_ARGUMENT (nothing changes) out of range. */
PKM_API pkm_status pkm_set_step_checks(pkm_model* m, double work_budget, double energy_tolerance);
PKM_API pkm_status pkm_get_step_checks(const pkm_model* m, double* work_budget, double* energy_tolerance);

/** Consistent initial state at time t0 from pose[4] and velocity[4]
 * (velocity may be NULL: at rest). PKM_ERR_UNREACHABLE if a leg cannot
 * reach elbow-down, PKM_ERR_SINGULAR beyond the singularity guards of the
 * solver settings; pkm_last_error says which leg and why. */
PKM_API pkm_status pkm_init_pose(pkm_model* m, double t0, const double pose[4],
                                 const double velocity[4]);

/** Inverse dynamics at a platform pose, velocity, acceleration and
 * external wrench (wrench may be NULL: none). Independent of the forward
 * state. */
PKM_API pkm_status pkm_inverse_dynamics(pkm_model* m, const double pose[4], const double velocity[4],
                                        const double acceleration[4], const double wrench[4],
                                        pkm_inverse_result* out);

/** Forward dynamics from the current time to t_end with constant forces F[4]
 * and wrench[4] (either may be NULL: zero). */
PKM_API pkm_status pkm_advance(pkm_model* m, double t_end, const double F[4], const double wrench[4]);

/** The same with inputs evaluated by a callback at the integrator's own
 * times. continuous != 0 says the inputs continue smoothly from the
 * previous call, so CVODE need not restart. */
PKM_API pkm_status pkm_advance_fn(pkm_model* m, double t_end, pkm_input_fn inputs, void* user,
                                  int continuous);

/** Outputs at the current time; F and wrench (may be NULL) are the inputs
 * at that time, needed for the accelerations and multipliers. */
PKM_API pkm_status pkm_get_outputs(pkm_model* m, const double F[4], const double wrench[4],
                                   pkm_outputs* out);

/** Integrated state [x, y, z, phi, dx, dy, dz, dphi] and its time; with the
 * theta1 unwrapping reference. pkm_set_state restores it exactly. */
PKM_API pkm_status pkm_get_state(const pkm_model* m, double* t, double y[8], double theta1_ref[4]);
PKM_API pkm_status pkm_set_state(pkm_model* m, double t, const double y[8], const double theta1_ref[4]);

/** Total mechanical energy T + U (J) at the current state (U with the
 * spec's gravity, up to a constant; with the machine below, T includes the
 * rotors and U the end stops' springs). */
PKM_API pkm_status pkm_energy(pkm_model* m, double* kinetic, double* potential);

/* ---- The machine around the mechanism (docs/model.md): drives, friction,
 * end stops, payload. Separate structs and functions, so the ones above
 * keep their layout and behaviour; a model made by pkm_create has the
 * default machine (pkm_default_machine_params). ---- */
typedef struct {
  double screw_lead;        /**< m per revolution, > 0, default 0.004 */
  double rotor_inertia;     /**< kg*m^2 (motor + screw), >= 0, default 0 */
  double friction_viscous;  /**< N*s/m, >= 0, default 0 */
  double friction_coulomb;  /**< N, >= 0, default 0 */
  double friction_velocity; /**< m/s, > 0, default 1e-3 */
  double rho_min, rho_max;  /**< m, end stops, default 0.0 and 0.15 */
  double stop_stiffness;    /**< N/m, >= 0, default 1e5 */
  double stop_damping;      /**< N*s/m, >= 0, default 100 */
  double payload_mass;      /**< kg, >= 0, default 0 */
  double payload_com[2];    /**< m, platform frame, relative to P, default 0 */
  double payload_Izz;       /**< kg*m^2 about its own centre of mass, default 0 */
} pkm_machine_params;

PKM_API void pkm_default_machine_params(pkm_machine_params* mp);

/** pkm_create with the machine parameters (mp may be NULL: the defaults). */
PKM_API pkm_status pkm_create_machine(const pkm_params* p, const pkm_machine_params* mp, pkm_model** out,
                                      char* err, size_t err_len);

/** Motor torques tau[4] (N*m) at time t, for pkm_advance_fn_drives. */
typedef void (*pkm_torque_fn)(void* user, double t, double tau[4]);

/** pkm_advance with constant motor torques tau[4] besides F and the wrench
 * (any may be NULL: zero); tau_i adds (2 pi / screw_lead) tau_i to F_i. */
PKM_API pkm_status pkm_advance_drives(pkm_model* m, double t_end, const double F[4], const double tau[4],
                                      const double wrench[4]);
/** pkm_advance_fn with a torque callback (may be NULL: zero), same user pointer. */
PKM_API pkm_status pkm_advance_fn_drives(pkm_model* m, double t_end, pkm_input_fn inputs, pkm_torque_fn torques,
                                         void* user, int continuous);

typedef struct {
  double stop_force[4];      /**< N, signed along +z */
  double friction_force[4];  /**< N, signed along +z */
  double F_hold[4];          /**< N: hold the current pose at rest (gravity, payload, wrench) */
  double kinetic_energy;     /**< J, rotors included */
  double potential_energy;   /**< J, gravity plus the stops' springs */
  double actuator_work;      /**< J, running integral since pkm_init_pose */
  double dissipated_energy;  /**< J, running integral since pkm_init_pose */
  double stop_indicators[8]; /**< rho_i - rho_min (i = 1..4), then rho_max - rho_i */
} pkm_machine_outputs;

/** The machine's outputs at the current time for the inputs F, tau, wrench
 * at that time (any may be NULL: zero). */
PKM_API pkm_status pkm_get_machine_outputs(pkm_model* m, const double F[4], const double tau[4],
                                           const double wrench[4], pkm_machine_outputs* out);

typedef struct {
  double F[4];          /**< N, on top of friction (and of a stop's force if beyond one) */
  double tau[4];        /**< N*m, the equivalent motor torques F_i p / (2 pi) */
  double lambda[12];
  unsigned beyond_stops; /**< bit i-1: rho_i < rho_min; bit 3+i: rho_i > rho_max (a warning, not an error) */
} pkm_inverse_machine_result;

/** Inverse dynamics with the machine (rotor inertia, friction, payload). */
PKM_API pkm_status pkm_inverse_dynamics_machine(pkm_model* m, const double pose[4], const double velocity[4],
                                                const double acceleration[4], const double wrench[4],
                                                pkm_inverse_machine_result* out);

/* ---- Analytic derivatives (no finite differences), machine included. ---- */

/** Number of plant inputs u, in this order: F[1..4] (N), Fe[1..3] (N),
 * Me_z (N*m), tau[1..4] (N*m). */
#define PKM_PLANT_INPUTS 12

/** The state derivative ydot = (pd, pdd) at state[8] = (x, y, z, phi, dx, dy,
 * dz, dphi) and inputs[12] (PKM_PLANT_INPUTS order; NULL: zero), with its
 * Jacobians A = dydot/dstate (8x8, row-major) and B = dydot/dinputs (8x12,
 * row-major). Each end stop acts when its joint is past it (at a stop's
 * contact or release instant, the side the force is evaluated on).
 * Independent of the forward state; ydot may be NULL. */
PKM_API pkm_status pkm_forward_derivatives(pkm_model* m, const double state[8], const double inputs[12],
                                           double ydot[8], double A[64], double B[96]);

/** The inverse dynamics' forces F[4] (as pkm_inverse_dynamics_machine gives
 * them) and their Jacobian dF[4x16] (row-major) with respect to
 * (pose[4], velocity[4], acceleration[4], wrench[4]); wrench may be NULL. */
PKM_API pkm_status pkm_inverse_derivatives(pkm_model* m, const double pose[4], const double velocity[4],
                                           const double acceleration[4], const double wrench[4], double F[4],
                                           double dF[64]);

/* ---- Calibration (docs/calibration.md): the actuator forces are linear in
 * the dynamic parameters, F = Y pi + F0, with pi the PKM_REGRESSOR_PARAMS
 * entries named by pkm_regressor_param_name (masses, first moments and
 * inertias of slider, rod, platform and payload, rotor inertia, viscous and
 * Coulomb friction for the model's friction_velocity) and F0 what does not
 * depend on them (the wrench, and an end stop's force beyond it). Y is
 * row-major, 4 x PKM_REGRESSOR_PARAMS per sample. ---- */
#define PKM_REGRESSOR_PARAMS 14

PKM_API int pkm_regressor_param_count(void);
/* Name (the FMU's parameter name where pi's entry is one), unit; NULL
 * outside 0..PKM_REGRESSOR_PARAMS-1. */
PKM_API const char* pkm_regressor_param_name(int j);
PKM_API const char* pkm_regressor_param_unit(int j);

/* The model's own pi (its parameters' values). */
PKM_API pkm_status pkm_regressor_params(pkm_model* m, double pi[PKM_REGRESSOR_PARAMS]);

/* Y (4 x PKM_REGRESSOR_PARAMS, row-major) and F0[4] (may be NULL) at a
 * platform pose, velocity and acceleration with the wrench (may be NULL). */
PKM_API pkm_status pkm_regressor(pkm_model* m, const double pose[4], const double velocity[4],
                                 const double acceleration[4], const double wrench[4], double* Y, double F0[4]);

/* pkm_regressor for n samples (arrays of n x 4, sample-major; Y n x 4 x
 * PKM_REGRESSOR_PARAMS), no wrench; F0, rho and drho (the sliders' positions
 * and rates, n x 4) may be NULL. On failure pkm_last_error names the sample. */
PKM_API pkm_status pkm_regressor_poses(pkm_model* m, size_t n, const double* pose, const double* velocity,
                                       const double* acceleration, double* Y, double* F0, double* rho,
                                       double* drho);

/* The same from the sliders' positions, rates and accelerations (n x 4),
 * through the forward kinematics: each sample starts from the previous
 * sample's pose, the first from guess[4] (NULL: the home pose 0, 0, 0.05 m,
 * 0). pose (n x 4, may be NULL) receives the platform's poses; *done (may be
 * NULL) the number of samples computed, also on failure. */
PKM_API pkm_status pkm_regressor_joints(pkm_model* m, size_t n, const double* rho, const double* drho,
                                        const double* ddrho, const double guess[4], double* Y, double* F0,
                                        double* pose, size_t* done);

#ifdef __cplusplus
}
#endif

#endif /**< PKM_H */
