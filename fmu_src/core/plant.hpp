// Forward-dynamics simulation of the mechanism: the state, the solver
// settings and the integrators around state_derivative(). One Plant per
// simulated machine; no global state, so instances are independent.
#pragma once

#include <string>

#include "cvode_integrator.hpp"
#include "minimal_state.hpp"
#include "workspace_guard.hpp"

namespace pkm {

enum class Solver { Cvode = 0, Rk4 = 1 };

struct SolverSettings {
  Solver solver = Solver::Cvode;
  double rk4_step = 1e-3;  // s; an interval is split into whole steps no longer than this
  double rtol = 1e-8;      // CVODE
  double atol = 1e-10;     // CVODE
  CvodeMethod cvode_method = CvodeMethod::Adams;
  Formulation formulation = Formulation::LegPartitioned;
  // Singularity guards (workspace_guard.hpp), checked at the end of every
  // step: a step ending beyond either is undone and reported (Status::Singular).
  double max_jacobian_condition = GuardLimits{}.max_jacobian_condition;
  double min_leg_measure = GuardLimits{}.min_leg_measure;

  GuardLimits limits() const { return {max_jacobian_condition, min_leg_measure}; }
};

/// At most this many RK4 steps in one advance (a longer interval or a
/// smaller rk4_step is refused with Status::InvalidArgument before any
/// work: about 25 s of computing at 2.5 us per step).
constexpr double kMaxRk4StepsPerAdvance = 1e7;

/// Returns "" if the settings are usable, otherwise a message naming the
/// offending setting.
std::string validate(const SolverSettings& s);

/// Inputs over an interval: actuator forces F (N) and the external platform
/// wrench (N, N*m) at time t.
struct InputSignal {
  void (*eval)(void* user, double t, Vec4& F, Wrench& we) = nullptr;
  void* user = nullptr;
};

/// Inputs held constant, or varying linearly: F(t) = F0 + dF (t - t0).
struct LinearInputs {
  double t0 = 0;
  Vec4 F0 = Vec4::Zero(), dF = Vec4::Zero();
  Wrench we0 = Wrench::Zero(), dwe = Wrench::Zero();
  InputSignal signal();
};

class Plant {
 public:
  explicit Plant(const Model& model);

  const Model& model() const { return model_; }

  /// Replaces the solver settings (validated first).
  Status set_solver(const SolverSettings& s, std::string* error = nullptr);
  const SolverSettings& solver() const { return settings_; }

  /// Consistent initial state at time t0 from a pose and a velocity
  /// (position and velocity problems). Status::Unreachable if the pose
  /// cannot be assembled elbow-down, ::Singular if it lies beyond the
  /// singularity limits of the solver settings, ::NonFinite if the state
  /// derivative there is not finite (velocity far too large); last_error()
  /// says which leg and why. On failure nothing changes.
  Status initialize(double t0, const Pose& pose, const Pose& velocity);

  /// Integrates to t_end with the given inputs. `continuous` tells that the
  /// inputs continue smoothly those of the previous call (CVODE keeps its
  /// history); otherwise CVODE restarts at the current time. On failure the
  /// state stays at the last point reached successfully (RK4: the last
  /// whole step; CVODE: the start of the call). Every step's end state is
  /// checked against the singularity limits (check_configuration): a step
  /// ending beyond them is undone and Status::Singular (or ::Unreachable)
  /// returned, with last_error() naming the leg or the condition number.
  Status advance(double t_end, const InputSignal& inputs, bool continuous = false);

  bool initialized() const { return initialized_; }
  double time() const { return t_; }
  /// The integrated state [pose; velocity].
  const Vec8& state() const { return y_; }
  /// Restores a state saved earlier (time, y, theta1 continuity); refused
  /// (nothing changes) if y lies beyond the singularity limits.
  Status restore(double t, const Vec8& y, const Vec4& theta1_ref);

  // ---- Model Exchange: the importer's integrator owns time and state.
  /// Sets the time (the state is kept).
  void set_time(double t) { t_ = t; }
  /// Sets the state [pose; velocity] reached by the importer's integrator:
  /// Status::Unreachable (nothing changes, last_error() says which leg) if a
  /// leg cannot be assembled there, ::NonFinite if y is not finite. The
  /// singularity limits are not checked here: the event indicators
  /// (guard_indicators) locate their crossing.
  Status set_state(const Vec8& y);
  /// dy/dt at the current time and state for the given inputs.
  Status derivative_now(const InputSignal& inputs, Vec8& ydot) const;

  /// q, qd, qdd and lambda at the current time, for the inputs at that time
  /// (evaluated on demand; theta1 continuous in time). Reading changes nothing.
  Status mechanism(const InputSignal& inputs, MechanismState& out) const;
  /// theta1 of each leg at the current time, unwrapped continuously since
  /// initialisation. Brought up to date when read (not in every advance:
  /// that would cost four atan2 per step); continuity holds as long as theta1
  /// moves less than pi between reads, which the workspace guarantees.
  const Vec4& theta1_ref() const;

  /// ||C(q)|| at the current state (m).
  double constraint_residual() const;
  /// Condition number of the actuator Jacobian (MODEL_SPEC), +inf if singular.
  double jacobian_condition() const;

  long rhs_evaluations() const { return rhs_count_; }
  const std::string& last_error() const { return error_; }

 private:
  static int cvode_rhs(double t, const Vec8& y, Vec8& ydot, void* self);
  Status derivative(double t, const Vec8& y, Vec8& ydot);
  Status advance_rk4(double t_end);
  Status advance_cvode(double t_end, bool continuous);
  /// check_configuration of y's pose against the settings' limits; on
  /// failure error_ describes it.
  Status guard(const Vec8& y, double t);
  void update_theta1_ref() const;

  Model model_;
  SolverSettings settings_;
  CvodeIntegrator cvode_;
  bool cvode_ready_ = false;
  InputSignal inputs_;
  bool initialized_ = false;
  double t_ = 0;
  Vec8 y_ = Vec8::Zero();
  mutable Vec4 theta1_ref_ = Vec4::Zero();
  mutable bool theta1_stale_ = false;
  long rhs_count_ = 0;
  Status rhs_status_ = Status::Ok;
  std::string error_;
};

}  // namespace pkm
