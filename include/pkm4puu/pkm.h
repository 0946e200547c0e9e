/* SPDX-License-Identifier: BSD-2-Clause */
/**
 * @file pkm.h
 * pkm.h - plain C API of the 4-PUU Schoenflies-motion parallel robot model
 * (docs/model.md). No C++ types; an opaque handle per simulated machine.
 * SI units throughout: m, kg, s, rad, N, N*m.
 *
 * Every function that can fail returns a pkm_status; on anything but PKM_OK
 * the handle's pkm_last_error() says why, and the call has changed nothing:
 * no output written, the handle's state as it was (forward dynamics: at the
 * last point reached, which pkm_last_error names).
 *
 * The parameters are the FMUs', by the same names, ranges and defaults:
 * pkm_set_parameter(m, "payload_mass", 0.25). Structs the library writes
 * start with their size, so that fields can be added at their end:
 * initialise one as `pkm_outputs out = {sizeof(pkm_outputs)};`.
 * The ABI and deprecation policy: docs/c_api.md.
 */
#ifndef PKM4PUU_PKM_H
#define PKM4PUU_PKM_H

#include <stddef.h>

#include "pkm4puu/version.h" /* PKM_VERSION_MAJOR/MINOR/PATCH, PKM_VERSION_STRING */

/** The ABI version: the shared library's SOVERSION (libpkm.so.1). It
 * changes only when a function or a struct changes incompatibly; functions,
 * enumerators and struct fields (at a struct's end) are added within it. */
#define PKM_ABI_VERSION 1

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
  PKM_ERR_INVALID_ARGUMENT = 1,  /**< NULL pointer, bad size, unknown name */
  PKM_ERR_INVALID_PARAMETER = 2, /**< a parameter out of its range, or a set that does not fit together */
  PKM_ERR_NONFINITE = 3,         /**< NaN or Inf in an input */
  PKM_ERR_UNREACHABLE = 4,       /**< pose outside a leg's reach (elbow-down) */
  PKM_ERR_SINGULAR = 5,          /**< leg or parallel singularity (beyond the guards) */
  PKM_ERR_NOT_CONVERGED = 6,     /**< Newton's method failed its stopping rule */
  PKM_ERR_SOLVER = 7,            /**< the integrator gave up */
  PKM_ERR_NOT_INITIALIZED = 8,   /**< forward dynamics before pkm_init_pose */
  PKM_ERR_OUT_OF_MEMORY = 9      /**< an allocation failed */
} pkm_status;

/** Values of the parameter "solver". RK4: fixed step, sub-stepped where
 * friction or a held end stop is stiff; ROSENBROCK: fixed-step ROS2,
 * linearly implicit with the analytic Jacobian (docs/solvers.md). */
enum { PKM_SOLVER_CVODE = 0, PKM_SOLVER_RK4 = 1, PKM_SOLVER_ROSENBROCK = 2 };
/** Values of the parameter "cvode_method". */
enum { PKM_CVODE_ADAMS = 0, PKM_CVODE_BDF = 1 };
/** Values of the parameter "formulation". */
enum {
  PKM_FORM_AUGMENTED = 0,      /**< Eq. 12 */
  PKM_FORM_NULLSPACE_QR = 1,   /**< Eq. 13, B from a QR of C_q */
  PKM_FORM_LEG_PARTITIONED = 2 /**< Eq. 13, B from the leg blocks (default) */
};

/** The plant's inputs u, in this order: F[1..4] actuator forces (N),
 * Fe[1..3] external force on the platform at P (N), Me_z external moment
 * (N*m), tau[1..4] motor torques (N*m, each adds (2 pi/screw_lead) tau_i
 * to F_i): the FMU's inputs. */
enum { PKM_PLANT_INPUTS = 12 };

typedef struct pkm_model pkm_model;

/* ---- The library ---- */

/** The library's version, "MAJOR.MINOR.PATCH": PKM_VERSION_STRING of the
 * header it was built with (a program built against another header can
 * compare the two). */
PKM_API const char* pkm_version(void);
/** The library's PKM_ABI_VERSION (a program that loads it at run time
 * checks it against its header's). */
PKM_API int pkm_abi_version(void);
PKM_API const char* pkm_status_string(pkm_status s);

/* ---- A model ---- */

/** Creates a model of the default machine (docs/model.md), CVODE as its
 * solver. *out is NULL on failure (PKM_ERR_INVALID_ARGUMENT: out is NULL;
 * PKM_ERR_OUT_OF_MEMORY). */
PKM_API pkm_status pkm_create(pkm_model** out);
PKM_API void pkm_destroy(pkm_model* m);
/** Why the handle's last failed call failed ("" if none failed yet). */
PKM_API const char* pkm_last_error(const pkm_model* m);

/* ---- Parameters, by the FMUs' names ---- */

/** Sets the parameter called `name` ("h", "beta[2]", "payload_mass", "solver",
 * "rtol", ... : docs/c_api.md lists them). PKM_ERR_INVALID_ARGUMENT for an
 * unknown name, PKM_ERR_INVALID_PARAMETER for a value outside its range or
 * one that leaves the set inconsistent (rho_max not above rho_min); nothing
 * changes then. A solver setting applies from the next advance. A tunable
 * parameter (is_tunable: the payload) keeps the run: a grasp or a release at
 * the current time, the platform's velocity unchanged, the jump of kinetic
 * and potential energy booked into actuator_work. A change of any other
 * parameter ends the run: forward dynamics answers PKM_ERR_NOT_INITIALIZED
 * until the next pkm_init_pose. */
PKM_API pkm_status pkm_set_parameter(pkm_model* m, const char* name, double value);
/** Sets n parameters as one change: the set is checked as a whole, so
 * rho_min and rho_max can move past each other; all or nothing. */
PKM_API pkm_status pkm_set_parameters(pkm_model* m, size_t n, const char* const names[], const double values[]);
PKM_API pkm_status pkm_get_parameter(const pkm_model* m, const char* name, double* value);

/** What the library knows of a parameter (pkm_parameter_info). */
typedef struct {
  size_t size;             /**< sizeof(pkm_parameter); set by the caller */
  const char* name;        /**< the FMUs' name, e.g. "beta[2]" */
  const char* unit;        /**< the FMUs' unit ("kg.m2"); "" dimensionless */
  const char* description; /**< the FMUs' description */
  double start;            /**< the default */
  double min, max;         /**< the closed range pkm_set_parameter accepts (max may be +Inf) */
  int is_integer;          /**< 1: a whole number (a choice: solver, cvode_method, formulation) */
  int is_solver_setting;   /**< 1: applies from the next advance */
  int is_tunable;          /**< 1: a change keeps the run, here and in the FMUs (variability tunable);
                                with is_solver_setting 0 both: a change ends the run */
  unsigned fmus;           /**< bit 0: PKM4PUU.fmu has it, bit 1: PKM4PUU_Inverse.fmu */
  unsigned value_reference; /**< the FMUs' value reference */
} pkm_parameter;

/** The number of parameters; they are numbered 0..count-1. */
PKM_API size_t pkm_parameter_count(void);
/** Parameter number `index` into *info (info->size set first: the fields
 * that fit are written). PKM_ERR_INVALID_ARGUMENT beyond the count. */
PKM_API pkm_status pkm_parameter_info(size_t index, pkm_parameter* info);

/* ---- Forward dynamics ---- */

/** Consistent initial state at time t0 from pose[4] = (x, y, z, phi) and
 * velocity[4] (NULL: at rest); starts a run. PKM_ERR_UNREACHABLE if a leg
 * cannot reach elbow-down, PKM_ERR_SINGULAR beyond the singularity guards
 * (max_jacobian_condition, min_leg_measure); pkm_last_error says which leg
 * and why. */
PKM_API pkm_status pkm_init_pose(pkm_model* m, double t0, const double pose[4], const double velocity[4]);

/** Forward dynamics from the current time to t_end with the inputs u
 * (PKM_PLANT_INPUTS values; NULL: all zero) held constant. An advance the
 * solver cannot take (CVODE over less than 2^-511 s; RK4 or ROS2 over more
 * than 1e5 grid steps of rk4_step) is refused before any work,
 * PKM_ERR_INVALID_ARGUMENT with the reason, the state unchanged. */
PKM_API pkm_status pkm_advance(pkm_model* m, double t_end, const double u[PKM_PLANT_INPUTS]);

/** Writes the inputs u[PKM_PLANT_INPUTS] at time t (they come in zeroed). */
typedef void (*pkm_input_fn)(void* user, double t, double u[PKM_PLANT_INPUTS]);

/** pkm_advance with the inputs evaluated by a callback at the integrator's
 * own times. continuous != 0 says the inputs continue smoothly from the
 * previous call, so CVODE need not restart. */
PKM_API pkm_status pkm_advance_fn(pkm_model* m, double t_end, pkm_input_fn inputs, void* user, int continuous);

/** Everything the plant FMU's outputs say, at the current time. */
typedef struct {
  size_t size;                   /**< sizeof(pkm_outputs); set by the caller */
  double t;                      /**< s */
  double pose[4];                /**< x, y, z (m), phi (rad) */
  double velocity[4];            /**< dx, dy, dz (m/s), dphi (rad/s) */
  double acceleration[4];        /**< for the inputs at t */
  double rho[4], drho[4];        /**< m, m/s */
  double theta1[4], theta2[4];   /**< rad; theta1 continuous (unwrapped) */
  double q[16], qd[16], qdd[16]; /**< coordinate order of docs/model.md */
  double lambda[12];             /**< Lagrange multipliers of Eq. 1 */
  double constraint_residual;    /**< ||C(q)||, m */
  double jacobian_condition;     /**< actuator Jacobian, phi column / 0.1 m */
  double stop_force[4];          /**< N, signed along +z */
  double friction_force[4];      /**< N, signed along +z */
  double F_hold[4];              /**< N: hold the current pose at rest (gravity, payload, wrench) */
  double kinetic_energy;         /**< J, rotors included */
  double potential_energy;       /**< J, gravity plus the stops' springs */
  double actuator_work;          /**< J, running integral since pkm_init_pose, plus each payload change's work */
  double dissipated_energy;      /**< J, running integral since pkm_init_pose */
  double stop_indicators[8];     /**< rho_i - rho_min (i = 1..4), then rho_max - rho_i */
} pkm_outputs;

/** The outputs at the current time for the inputs u at that time (NULL:
 * zero), which the accelerations, multipliers and forces depend on. */
PKM_API pkm_status pkm_get_outputs(pkm_model* m, const double u[PKM_PLANT_INPUTS], pkm_outputs* out);

/** The state of a run: what pkm_set_state needs to continue it exactly. */
typedef struct {
  size_t size;              /**< sizeof(pkm_state); set by the caller */
  double t;                 /**< s */
  double y[8];              /**< x, y, z, phi, dx, dy, dz, dphi */
  double theta1_ref[4];     /**< theta1's unwrapping reference (rad) */
  double actuator_work;     /**< J, the energy audit's integrals */
  double dissipated_energy; /**< J */
  unsigned stops;           /**< the contact mode: bit i (i = 0..3) leg i+1's lower stop held, bit 4+i its upper,
                                 bit 8+i its stop clamped (pushing no more) */
} pkm_state;

PKM_API pkm_status pkm_get_state(const pkm_model* m, pkm_state* state);
/** Restores a state taken by pkm_get_state (of a model with the same
 * parameters), in this handle or another; a run continues from it bit for
 * bit. The parameters, tunable ones included, are not part of the state. Refused, nothing changed, beyond the guards or the speed limit, with
 * a theta1 reference that is not the pose's, or a contact mode that names no
 * stop. */
PKM_API pkm_status pkm_set_state(pkm_model* m, const pkm_state* state);

/* ---- Inverse dynamics ---- */

typedef struct {
  size_t size;                   /**< sizeof(pkm_inverse_result); set by the caller */
  double F[4];                   /**< N, on top of friction (and of a stop's force if beyond one) */
  double tau[4];                 /**< N*m, the equivalent motor torques F_i p / (2 pi) */
  double lambda[12];             /**< Lagrange multipliers (Eq. 10) */
  double q[16], qd[16], qdd[16]; /**< the legs' motion (coordinate order of docs/model.md) */
  unsigned beyond_stops;         /**< bit i: rho_(i+1) < rho_min; bit 4+i: rho_(i+1) > rho_max (a warning) */
} pkm_inverse_result;

/** Inverse dynamics with the machine (rotor inertia, friction, payload) at a
 * platform pose, velocity, acceleration and external wrench[4] = (Fx, Fy,
 * Fz in N, Mz in N*m; NULL: none). Independent of the forward state.
 * PKM_ERR_SINGULAR beyond the singularity guards (max_jacobian_condition,
 * min_leg_measure), as the inverse FMU. */
PKM_API pkm_status pkm_inverse_dynamics(pkm_model* m, const double pose[4], const double velocity[4],
                                        const double acceleration[4], const double wrench[4],
                                        pkm_inverse_result* out);

/* ---- Analytic derivatives (no finite differences), machine included ---- */

/** The state derivative ydot = (pd, pdd) at state[8] = (x, y, z, phi, dx, dy,
 * dz, dphi) and inputs u (NULL: zero), with its Jacobians A = dydot/dstate
 * (8x8, row-major) and B = dydot/du (8 x PKM_PLANT_INPUTS, row-major). Each
 * end stop acts when its joint is past it (at a stop's contact or release
 * instant, the side the force is evaluated on). Independent of the forward
 * state; ydot may be NULL. */
PKM_API pkm_status pkm_forward_derivatives(pkm_model* m, const double state[8], const double u[PKM_PLANT_INPUTS],
                                           double ydot[8], double A[64], double B[8 * PKM_PLANT_INPUTS]);

/** The inverse dynamics' forces F[4] (as pkm_inverse_dynamics gives them)
 * and their Jacobian dF[4x16] (row-major) with respect to (pose[4],
 * velocity[4], acceleration[4], wrench[4]); wrench may be NULL. */
PKM_API pkm_status pkm_inverse_derivatives(pkm_model* m, const double pose[4], const double velocity[4],
                                           const double acceleration[4], const double wrench[4], double F[4],
                                           double dF[64]);

/* ---- Calibration (docs/calibration.md): the actuator forces are linear in
 * the dynamic parameters, F = Y pi + F0, with pi the PKM_REGRESSOR_PARAMS
 * entries named by pkm_regressor_param_name (masses, first moments and
 * inertias of slider, rod, platform and payload, rotor inertia, viscous and
 * Coulomb friction for the model's friction_velocity) and F0 what does not
 * depend on them (the wrench, and an end stop's force beyond it). Y is
 * row-major, 4 x PKM_REGRESSOR_PARAMS per sample. Poses beyond the
 * singularity guards are refused as by pkm_inverse_dynamics. ---- */
enum { PKM_REGRESSOR_PARAMS = 14 };

/** Name (the FMUs' parameter name where pi's entry is one), unit; NULL
 * outside 0..PKM_REGRESSOR_PARAMS-1. */
PKM_API const char* pkm_regressor_param_name(int j);
PKM_API const char* pkm_regressor_param_unit(int j);

/** The model's own pi (its parameters' values). */
PKM_API pkm_status pkm_regressor_params(pkm_model* m, double pi[PKM_REGRESSOR_PARAMS]);

/** Y (4 x PKM_REGRESSOR_PARAMS, row-major) and F0[4] (may be NULL) at a
 * platform pose, velocity and acceleration with the wrench (may be NULL). */
PKM_API pkm_status pkm_regressor(pkm_model* m, const double pose[4], const double velocity[4],
                                 const double acceleration[4], const double wrench[4], double* Y, double F0[4]);

/** pkm_regressor for n samples (arrays of n x 4, sample-major; Y n x 4 x
 * PKM_REGRESSOR_PARAMS), no wrench; F0, rho and drho (the sliders' positions
 * and rates, n x 4) may be NULL. *done (may be NULL) receives the number of
 * samples written, 0..n-1 on failure, where pkm_last_error names the sample. */
PKM_API pkm_status pkm_regressor_poses(pkm_model* m, size_t n, const double* pose, const double* velocity,
                                       const double* acceleration, double* Y, double* F0, double* rho,
                                       double* drho, size_t* done);

/** The same from the sliders' positions, rates and accelerations (n x 4),
 * through the forward kinematics: each sample starts from the previous
 * sample's pose, the first from guess[4] (NULL: the home pose 0, 0, 0.05 m,
 * 0). pose (n x 4, may be NULL) receives the platform's poses; *done as for
 * pkm_regressor_poses. */
PKM_API pkm_status pkm_regressor_joints(pkm_model* m, size_t n, const double* rho, const double* drho,
                                        const double* ddrho, const double guess[4], double* Y, double* F0,
                                        double* pose, size_t* done);

#ifdef __cplusplus
}
#endif

#endif /* PKM4PUU_PKM_H */
