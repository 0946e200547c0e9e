#include "pkm4puu/sim/plant.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "pkm4puu/kinematics/constraints.hpp"
#include "pkm4puu/dynamics/inverse_dynamics.hpp"
#include "pkm4puu/dynamics/lagrangian.hpp"
#include "pkm4puu/integrators/rk4.hpp"
#include "pkm4puu/kinematics/servo_kinematics.hpp"

namespace pkm {
namespace {

void eval_linear(void* user, double t, Vec4& F, Wrench& we) {
  const auto* in = static_cast<const LinearInputs*>(user);
  const double dt = t - in->t0;
  F = in->F0 + in->dF * dt;
  we = in->we0 + in->dwe * dt;
}

void eval_linear_tau(void* user, double t, Vec4& tau) {
  const auto* in = static_cast<const LinearInputs*>(user);
  tau = in->tau0 + in->dtau * (t - in->t0);
}

void read_inputs(const InputSignal& in, double t, Vec4& F, Wrench& we, Vec4& tau) {
  if (in.eval) {
    in.eval(in.user, t, F, we);
  } else {
    F.setZero();
    we.setZero();
  }
  if (in.eval_tau) {
    in.eval_tau(in.user, t, tau);
  } else {
    tau.setZero();
  }
}

// RK4 contact location (Plant::advance_rk4): at most this many located
// events per grid step (beyond, the step goes on without locating: a
// chattering contact), and the bisection's resolution in time.
constexpr int kMaxEventsPerStep = 64;
double event_time_tolerance(double t) { return 1e-12 + 8.0 * std::numeric_limits<double>::epsilon() * std::fabs(t); }
// CVODE: at most this many roots in one advance.
constexpr int kMaxEventsPerAdvance = 100000;

// |theta1| of a leg never comes near this: the closed form gives
// |theta1| < 2 pi, and the legs keep the platform from turning a whole turn.
constexpr double kMaxTheta1 = 8.0 * kPi;

double unwrap_near(double angle, double ref) {
  constexpr double two_pi = 2.0 * kPi;
  return angle + two_pi * std::round((ref - angle) / two_pi);
}

}  // namespace

InputSignal LinearInputs::signal() { return {&eval_linear, this, &eval_linear_tau}; }

std::string validate(const SolverSettings& s) {
  char buf[160];
  // The choices first: the FMUs and the C API pass their integers through
  // unchecked, and this is the one place that words them.
  if (s.solver != Solver::Cvode && s.solver != Solver::Rk4) {
    std::snprintf(buf, sizeof buf, "solver = %d must be 0 (CVODE) or 1 (RK4)", static_cast<int>(s.solver));
    return buf;
  }
  if (s.cvode_method != CvodeMethod::Adams && s.cvode_method != CvodeMethod::BDF) {
    std::snprintf(buf, sizeof buf, "cvode_method = %d must be 0 (Adams) or 1 (BDF)", static_cast<int>(s.cvode_method));
    return buf;
  }
  if (s.formulation != Formulation::Augmented && s.formulation != Formulation::NullSpaceQR &&
      s.formulation != Formulation::LegPartitioned) {
    std::snprintf(buf, sizeof buf, "formulation = %d must be 0 (Eq. 12), 1 (Eq. 13, QR) or 2 (Eq. 13, leg-partitioned)",
                  static_cast<int>(s.formulation));
    return buf;
  }
  if (s.solver == Solver::Cvode && !cvode_available())
    return "solver = 0 (CVODE) is not in this build (a source-code FMU compiled without SUNDIALS): set solver = 1 (RK4)";
  if (!(s.rk4_step > 0.0) || !std::isfinite(s.rk4_step)) {
    std::snprintf(buf, sizeof buf, "rk4_step = %.17g s must be positive and finite", s.rk4_step);
    return buf;
  }
  if (!(s.rk4_step >= kMinRk4Step && s.rk4_step <= kMaxRk4Step)) {
    std::snprintf(buf, sizeof buf, "rk4_step = %.17g s lies outside its range [%g, %g] s", s.rk4_step, kMinRk4Step,
                  kMaxRk4Step);
    return buf;
  }
  if (!(s.rtol > 0.0) || !(s.rtol < 1.0)) {
    std::snprintf(buf, sizeof buf, "rtol = %.17g must lie in (0, 1)", s.rtol);
    return buf;
  }
  if (!(s.atol > 0.0) || !(s.atol <= 1.0)) {
    std::snprintf(buf, sizeof buf, "atol = %.17g must be positive and at most 1", s.atol);
    return buf;
  }
  return validate(s.limits());
}

Plant::Plant(const Model& model) : model_(model) {}

Status Plant::set_solver(const SolverSettings& s, std::string* error) {
  const std::string why = validate(s);
  if (!why.empty()) {
    if (error) *error = why;
    return Status::InvalidArgument;
  }
  settings_ = s;
  cvode_ready_ = false;  // re-created on the next CVODE advance
  return Status::Ok;
}

Status Plant::initialize(double t0, const Pose& pose, const Pose& velocity) {
  error_.clear();
  if (!std::isfinite(t0) || !pose.allFinite() || !velocity.allFinite()) {
    error_ = "the initial time, pose or velocity is not finite";
    return Status::NonFinite;
  }
  Vec8 y;
  y.head<4>() = pose;
  y.tail<4>() = velocity;
  Status s = guard(y, t0);  // reachable elbow-down, within the singularity limits
  if (s != Status::Ok) return s;
  Vec16 q, qd;
  s = closed_form_position(model_, pose, q);
  if (s != Status::Ok) return s;
  s = solve_position(model_, pose, q);  // Eqs. 2-4 (a polish: the closed form is exact)
  if (s != Status::Ok) {
    error_ = "the position problem at the initial pose did not converge";
    return s;
  }
  s = solve_velocity(model_, q, velocity, qd);
  if (s != Status::Ok) return s;
  // The state derivative must exist there (with no inputs): a velocity so
  // large that the Coriolis terms overflow is refused here, not at the first step.
  Vec8 ydot;
  s = state_derivative(model_, settings_.formulation, y, Vec16::Zero(), ydot);
  if (s != Status::Ok || !ydot.allFinite()) {
    error_ = "the state derivative at the initial state is not finite (initial velocity too large?)";
    return Status::NonFinite;
  }
  s = prepare_cvode();
  if (s != Status::Ok) return s;
  y_ = y;
  rho_valid_ = false;
  t_ = t0;
  energy_ = EnergyIntegrals{};
  for (int i = 0; i < kLegs; ++i) theta1_ref_[i] = q[leg_offset(i) + 1];
  theta1_stale_ = false;
  if (cvode_ready_) cvode_.reset(t_, packed());
  initialized_ = true;
  return Status::Ok;
}

Status Plant::prepare_cvode() {
  if (settings_.solver != Solver::Cvode || cvode_ready_) return Status::Ok;
  const Status s = cvode_.init(settings_.cvode_method, settings_.rtol, settings_.atol, &Plant::cvode_rhs, this,
                               kStopIndicators, &Plant::cvode_roots);
  if (s != Status::Ok) {
    error_ = "CVODE could not be set up: " + cvode_.last_error();
    return s == Status::InvalidArgument ? s : Status::SolverFailure;
  }
  cvode_ready_ = true;
  return Status::Ok;
}

Status Plant::restore(double t, const Vec8& y, const Vec4& theta1_ref) {
  if (!std::isfinite(t) || !y.allFinite() || !theta1_ref.allFinite()) {
    error_ = "the time, state or theta1 references are not finite";
    return Status::NonFinite;
  }
  Status s = guard(y, t);
  if (s != Status::Ok) return s;
  Vec16 q, qd;
  s = expand_state(model_, y, q, qd);
  if (s != Status::Ok) return s;
  // theta1 is continuous, never wrapped, but cannot wind: the references
  // are the pose's closed-form angles up to whole turns, within a few turns.
  for (int i = 0; i < kLegs; ++i) {
    const double th1 = q[leg_offset(i) + 1];
    const bool near = std::fabs(unwrap_near(th1, theta1_ref[i]) - theta1_ref[i]) <= 1e-9;
    if (!(std::fabs(theta1_ref[i]) <= kMaxTheta1) || !near) {
      char buf[240];
      std::snprintf(buf, sizeof buf,
                    "the theta1 reference %.17g rad of leg %d is not the pose's theta1 = %.17g rad modulo 2 pi "
                    "(within %g rad)",
                    theta1_ref[i], i + 1, th1, kMaxTheta1);
      error_ = buf;
      return Status::InvalidArgument;
    }
  }
  const Status prepared = prepare_cvode();
  if (prepared != Status::Ok) return prepared;
  t_ = t;
  y_ = y;
  rho_valid_ = false;
  theta1_ref_ = theta1_ref;
  theta1_stale_ = false;
  if (cvode_ready_) cvode_.reset(t_, packed());
  initialized_ = true;
  return Status::Ok;
}

Status Plant::set_state(const Vec8& y) {
  if (!initialized_) return Status::NotInitialized;
  if (!y.allFinite()) return Status::NonFinite;
  GuardReport report;
  GuardLimits none;
  none.max_jacobian_condition = std::numeric_limits<double>::infinity();
  none.min_leg_measure = 0.0;
  const Status s = check_configuration(model_, y.head<4>(), none, &report);
  if (s != Status::Ok) {
    error_ = describe_configuration_failure(model_, y.head<4>(), none, report);
    return s;
  }
  y_ = y;
  rho_valid_ = false;
  theta1_stale_ = true;
  return Status::Ok;
}

Status Plant::derivative_now(const InputSignal& inputs, Vec10& xdot) const {
  if (!initialized_) return Status::NotInitialized;
  Vec10 x;
  x.head<8>() = y_;
  x[8] = energy_.actuator_work;
  x[9] = energy_.dissipated;
  return machine_rates(inputs, t_, x, kStopsFromState, xdot);
}

Status Plant::restore(double t, const Vec8& y, const Vec4& theta1_ref, const EnergyIntegrals& e) {
  if (!std::isfinite(e.actuator_work) || !std::isfinite(e.dissipated)) return Status::NonFinite;
  const EnergyIntegrals keep = energy_;
  energy_ = e;
  const Status s = restore(t, y, theta1_ref);
  if (s != Status::Ok) energy_ = keep;
  return s;
}

Vec10 Plant::packed() const {
  Vec10 x;
  x.head<8>() = y_;
  x[8] = energy_.actuator_work;
  x[9] = energy_.dissipated;
  return x;
}

void Plant::unpack(const Vec10& x) {
  y_ = x.head<8>();
  rho_valid_ = false;
  energy_.actuator_work = x[8];
  energy_.dissipated = x[9];
}

Status Plant::slider_positions(Vec4& rho) const {
  if (!rho_valid_) {
    const Status s = actuator_positions(model_, y_.head<4>(), rho_);
    if (s != Status::Ok) return s;
    rho_valid_ = true;
  }
  rho = rho_;
  return Status::Ok;
}

unsigned Plant::contact_mask(const Vec10& x, Vec4& rho) const {
  if (actuator_positions(model_, x.head<4>(), rho) != Status::Ok) return ~0u;
  return contact_mask_at(x, rho);
}

unsigned Plant::contact_mask_at(const Vec10& x, const Vec4& rho) const {
  unsigned mask = 0;
  for (int i = 0; i < kLegs; ++i) {
    if (rho[i] < model_.p.rho_min) mask |= 1u << i;
    if (rho[i] > model_.p.rho_max) mask |= 1u << (kLegs + i);
  }
  if (mask == 0) return mask;
  // Past a stop: also whether the stop is released (its spring and damper
  // would pull, the force is held at 0), a kink in the force that RK4
  // should not step across either. Needs the joint rates.
  Vec16 q, qd;
  if (expand_state(model_, x.head<8>(), q, qd) != Status::Ok) return ~0u;
  for (int i = 0; i < kLegs; ++i) {
    const StopContact c = stop_contact(model_.p, rho[i], qd[leg_offset(i)]);
    if (c.depth > 0.0 && c.force == 0.0) mask |= 1u << (2 * kLegs + i);
  }
  return mask;
}

double Plant::contact_step() const {
  // The fastest motion a stop can excite in one joint: its spring and
  // damper against the least mass that can sit behind rho_i, the slider
  // with its rotor (the rest of the mechanism only adds mass). A tenth of
  // the inverse rate keeps RK4's error per step near (0.1)^5 / 120 ~ 1e-7
  // of the contact's motion.
  const double mass = model_.p.m_slider + model_.reflected_mass;
  const double rate = std::sqrt(model_.p.stop_stiffness / mass) + model_.p.stop_damping / mass;
  return rate > 0.0 ? 0.1 / rate : std::numeric_limits<double>::infinity();
}

Status Plant::derivative(double t, const Vec10& x, Vec10& xdot) {
  ++rhs_count_;
  // A non-finite trial time or state is the integrator's (a step size
  // computed from absurd accelerations), not the inputs': the step fails,
  // the state is kept.
  if (!std::isfinite(t)) return Status::SolverFailure;
  bool inputs_fault = false;
  const Status s = machine_rates(inputs_, t, x, stops_, xdot, &inputs_fault);
  // With finite inputs a non-finite derivative is the trial state's.
  if (s == Status::NonFinite && !inputs_fault) return Status::SolverFailure;
  return s;
}

namespace {

/// The energy audit's integrands: the power of the actuator forces plus the
/// screws' (Fa) and of the external wrench, and the power dissipated by
/// friction and the end stops `stops`.
void energy_rates(const Params& p, unsigned stops, const Vec4& Fa, const Wrench& we, const Pose& pose_rate,
                  const Vec4& rho, const Vec4& rhod, double& power, double& dissipation) {
  power = Fa.dot(rhod) + we.dot(pose_rate);
  dissipation = 0.0;
  for (int i = 0; i < kLegs; ++i) dissipation += dissipated_power(p, i, stops, rho[i], rhod[i]);
}

}  // namespace

Status Plant::machine_rates(const InputSignal& inputs, double t, const Vec10& x, unsigned stops, Vec10& xdot,
                            bool* inputs_fault) const {
  Vec4 F, tau;
  Wrench we;
  read_inputs(inputs, t, F, we, tau);
  if (!F.allFinite() || !we.allFinite() || !tau.allFinite()) {
    if (inputs_fault) *inputs_fault = true;
    return Status::NonFinite;
  }
  const Vec4 Fa = F + model_.drive_ratio * tau;   // actuator force plus the screw's
  const Vec8 y = x.head<8>();
  Vec8 ydot;
  JointMotion jm;
  const Status s =
      state_derivative(model_, settings_.formulation, y, generalized_forces(Fa, we), ydot, nullptr, &jm, stops);
  if (s != Status::Ok) return s;
  xdot.head<8>() = ydot;
  energy_rates(model_.p, stops, Fa, we, y.tail<4>(), jm.rho, jm.rhod, xdot[8], xdot[9]);
  return Status::Ok;
}

int Plant::cvode_roots(double t, const Vec10& x, double* g, void* self) {
  (void)t;
  const auto* me = static_cast<const Plant*>(self);
  if (stop_indicators(me->model_, x.head<4>(), g) != Status::Ok)
    for (int k = 0; k < kStopIndicators; ++k) g[k] = 1.0;  // off the workspace: the rhs reports it
  return 0;
}

int Plant::cvode_rhs(double t, const Vec10& y, Vec10& ydot, void* self) {
  auto* me = static_cast<Plant*>(self);
  const Status s = me->derivative(t, y, ydot);
  me->rhs_status_ = s;
  // A trial state off the workspace (or not finite) may be CVODE's
  // overshoot: let it retry with a smaller step (recoverable); non-finite
  // inputs abort.
  if (s == Status::Ok) return 0;
  return (s == Status::Unreachable || s == Status::Singular || s == Status::SolverFailure) ? 1 : -1;
}

Status Plant::guard(const Vec8& y, double t) {
  // Called after every step: the message's time is formatted only on failure
  // (a %.17g costs about a tenth of an RK4 step).
  auto at = [t] {
    char buf[64];
    std::snprintf(buf, sizeof buf, "at t = %.17g s: ", t);
    return std::string(buf);
  };
  const double speed = std::max(y.segment<3>(4).cwiseAbs().maxCoeff(), kConditionLength * std::fabs(y[7]));
  if (!(speed <= kMaxSpeed)) {
    char buf[200];
    std::snprintf(buf, sizeof buf,
                  "the platform moves at %.6g m/s (|dx|, |dy|, |dz| or 0.1 m |dphi|), beyond the physical bound "
                  "%g m/s",
                  speed, kMaxSpeed);
    error_ = at() + buf;
    return Status::SolverFailure;
  }
  GuardReport report;
  const Status s = check_configuration(model_, y.head<4>(), settings_.limits(), &report);
  if (s == Status::Ok) return s;
  error_ = at() + describe_configuration_failure(model_, y.head<4>(), settings_.limits(), report);
  return s;
}

double rk4_steps_for(double span, double rk4_step) { return std::ceil(span / rk4_step - 1e-9); }

Status Plant::advance_rk4(double t_end) {
  const double span = t_end - t_;
  const double steps = rk4_steps_for(span, settings_.rk4_step);
  if (!(steps <= kMaxRk4StepsPerAdvance)) {  // also NaN
    char buf[200];
    std::snprintf(buf, sizeof buf,
                  "an interval of %.6g s needs %.3g RK4 steps of rk4_step = %.6g s, more than %.0e: "
                  "use shorter intervals or a larger rk4_step",
                  span, steps, settings_.rk4_step, kMaxRk4StepsPerAdvance);
    error_ = buf;
    return Status::InvalidArgument;
  }
  const long n = std::max(1L, static_cast<long>(steps));
  const double h = span / static_cast<double>(n);
  auto f = [this](double t, const Vec10& x, Vec10& xdot) { return derivative(t, x, xdot); };
  const double t0 = t_;
  const double h_contact = contact_step();
  for (long k = 0; k < n; ++k) {
    const double tk = (k == 0) ? t0 : t0 + static_cast<double>(k) * h;
    const double t_next = (k + 1 == n) ? t_end : t0 + static_cast<double>(k + 1) * h;
    // One grid step, split where a joint reaches or leaves an end stop
    // (the stop force switches on or off there) and, while a joint is past
    // a stop, into substeps of h_contact. A split is located by bisection
    // on re-stepping from the step's start: the shortest step after which
    // the set of joints past their stops has changed.
    Vec10 x = packed();
    double t = tk;
    // rho at x: the previous grid step's end computed it (slider_positions).
    Vec4 rho_x;
    unsigned mask = slider_positions(rho_x) == Status::Ok ? contact_mask_at(x, rho_x) : ~0u;
    bool rho_x_valid = mask != ~0u;
    int events = 0;
    Status s = Status::Ok;
    while (t < t_next && s == Status::Ok) {
      double step = t_next - t;
      bool to_end = true;
      if (mask != 0 && step > h_contact) {
        step = h_contact;
        to_end = false;
      }
      stops_ = mask & 0xFFu;  // held on over the step (and its re-steps)
      Vec10 trial = x;
      s = rk4_step(f, t, step, trial);
      if (s != Status::Ok) break;
      Vec4 rho_trial;
      unsigned trial_mask = contact_mask(trial, rho_trial);
      bool rho_trial_valid = trial_mask != ~0u;
      if (trial_mask == ~0u) trial_mask = mask;  // off the workspace: the guard reports it
      if (trial_mask != mask && events < kMaxEventsPerStep) {
        double lo = 0.0, hi = step;
        const double tol = event_time_tolerance(t);
        while (hi - lo > tol && s == Status::Ok) {
          const double mid = 0.5 * (lo + hi);
          Vec10 xm = x;
          s = rk4_step(f, t, mid, xm);
          Vec4 rho_m;
          const unsigned mm = contact_mask(xm, rho_m);
          if (mm == mask || mm == ~0u) {
            lo = mid;
          } else {
            hi = mid;
            trial = xm;
            trial_mask = mm;
            rho_trial = rho_m;
            rho_trial_valid = true;
          }
        }
        if (s != Status::Ok) break;
        if (hi < step) to_end = false;
        step = hi;
        ++events;
        ++contact_events_;
      }
      x = trial;
      mask = trial_mask;
      rho_x = rho_trial;
      rho_x_valid = rho_trial_valid;
      t = to_end ? t_next : t + step;
    }
    stops_ = kStopsFromState;
    if (s != Status::Ok) {
      char buf[160];
      std::snprintf(buf, sizeof buf, "the RK4 step from t = %.17g s could not be evaluated: %s", t,
                    status_name(s));
      error_ = buf;
      return s;
    }
    s = guard(x.head<8>(), t_next);  // every step ends within the limits, or is undone
    if (s != Status::Ok) return s;
    unpack(x);
    t_ = t_next;
    if (rho_x_valid) {  // what slider_positions would compute at the new state
      rho_ = rho_x;
      rho_valid_ = true;
    }
  }
  return Status::Ok;
}

Status Plant::advance_cvode(double t_end, bool continuous) {
  if (!cvode_ready_) {  // set_solver after initialisation: created here
    const Status s = prepare_cvode();
    if (s != Status::Ok) return s;
    continuous = false;
  }
  if (!continuous || cvode_.needs_reset()) {
    const Status s = cvode_.reset(t_, packed());
    if (s != Status::Ok) return s;
  }
  Vec10 x = packed();
  rhs_status_ = Status::Ok;
  // CVODE stops at every root of the stop indicators (a joint reaching or
  // leaving a stop: the stop force switches there); the history restarts
  // at that point, then integration goes on to t_end.
  // The stops held on between roots: those past at the start, then
  // switched by the direction of each root (not by the side of zero on
  // which the located state happens to fall).
  Vec4 rho;
  stops_ = (slider_positions(rho) == Status::Ok ? contact_mask_at(x, rho) : ~0u) & 0xFFu;
  int events = 0;
  Status s = Status::Ok;
  for (;;) {
    double t_reached = t_end;
    bool root = false;
    int dirs[kStopIndicators] = {};
    s = cvode_.advance(t_end, x, t_reached, root, dirs);
    if (s != Status::Ok) break;
    if (!root) break;
    for (int k = 0; k < kStopIndicators; ++k) {
      if (dirs[k] < 0) stops_ |= 1u << k;   // indicator fell through 0: past the stop
      if (dirs[k] > 0) stops_ &= ~(1u << k);
    }
    ++contact_events_;
    if (++events > kMaxEventsPerAdvance) {
      char buf[160];
      std::snprintf(buf, sizeof buf, "more than %d end-stop events before t = %.17g s (chattering contact)",
                    kMaxEventsPerAdvance, t_end);
      cvode_.reset(t_, packed());
      stops_ = kStopsFromState;
      error_ = buf;
      return Status::SolverFailure;
    }
    if (!(t_reached < t_end)) break;
    s = cvode_.reset(t_reached, x);
    if (s != Status::Ok) break;
  }
  stops_ = kStopsFromState;
  if (s != Status::Ok) {
    error_ = cvode_.last_error();
    cvode_.reset(t_, packed());
    return rhs_status_ != Status::Ok ? rhs_status_ : s;
  }
  s = guard(x.head<8>(), t_end);  // the interval ends within the limits, or is undone
  if (s != Status::Ok) {
    cvode_.reset(t_, packed());
    return s;
  }
  unpack(x);
  t_ = t_end;
  return Status::Ok;
}

Status Plant::advance(double t_end, const InputSignal& inputs, bool continuous) {
  if (!initialized_) return Status::NotInitialized;
  if (!std::isfinite(t_end)) return Status::NonFinite;
  if (!(t_end > t_)) return t_end == t_ ? Status::Ok : Status::InvalidArgument;
  error_.clear();
  inputs_ = inputs;
  const double t_start = t_;
  const Status s = settings_.solver == Solver::Rk4 ? advance_rk4(t_end) : advance_cvode(t_end, continuous);
  inputs_ = InputSignal{};
  if (t_ != t_start) theta1_stale_ = true;
  return s;
}

const Vec4& Plant::theta1_ref() const {
  if (theta1_stale_) update_theta1_ref();
  return theta1_ref_;
}

void Plant::update_theta1_ref() const {
  Vec16 q;
  if (closed_form_position(model_, y_.head<4>(), q) == Status::Ok) refresh_theta1_ref(q);
}

void Plant::refresh_theta1_ref(const Vec16& q) const {
  for (int i = 0; i < kLegs; ++i) theta1_ref_[i] = unwrap_near(q[leg_offset(i) + 1], theta1_ref_[i]);
  theta1_stale_ = false;
}

Status Plant::mechanism(const InputSignal& inputs, MechanismState& out) const {
  if (!initialized_) return Status::NotInitialized;
  Vec4 F, tau;
  Wrench we;
  read_inputs(inputs, t_, F, we, tau);
  Vec8 ydot;
  const Status s = state_derivative(model_, settings_.formulation, y_, generalized_forces(model_, F, tau, we),
                                    ydot, &out);
  if (s != Status::Ok) return s;
  unwrap_theta1(out.q);
  return Status::Ok;
}

void Plant::unwrap_theta1(Vec16& q) const {
  for (int i = 0; i < kLegs; ++i) {
    double& th1 = q[leg_offset(i) + 1];
    th1 = unwrap_near(th1, theta1_ref()[i]);
  }
}

Status Plant::coordinates(Vec16& q, Vec16& qd) const {
  if (!initialized_) return Status::NotInitialized;
  const Status s = expand_state(model_, y_, q, qd);
  if (s != Status::Ok) return s;
  if (theta1_stale_) refresh_theta1_ref(q);  // the closed form update_theta1_ref would evaluate again
  unwrap_theta1(q);
  return Status::Ok;
}

Status Plant::machine_outputs(const InputSignal& inputs, MachineOutputs& out) const {
  if (!initialized_) return Status::NotInitialized;
  Vec16 q, qd;
  Status s = expand_state(model_, y_, q, qd);
  if (s != Status::Ok) return s;
  Vec4 F, tau;
  Wrench we;
  read_inputs(inputs, t_, F, we, tau);
  const Params& p = model_.p;
  for (int i = 0; i < kLegs; ++i) {
    const int o = leg_offset(i);
    out.rho[i] = q[o];
    out.rhod[i] = qd[o];
    out.stop_force[i] = stop_force(p, q[o], qd[o]);
    out.friction_force[i] = friction_force(p, qd[o]);
  }
  s = holding_forces(model_, q, we, out.F_hold);
  if (s != Status::Ok) return s;
  out.kinetic_energy = kinetic_energy(model_, q, qd);
  out.potential_energy = potential_energy(model_, q);
  out.actuator_work = energy_.actuator_work;
  out.dissipated_energy = energy_.dissipated;
  energy_rates(p, kStopsFromState, F + model_.drive_ratio * tau, we, y_.tail<4>(), out.rho, out.rhod,
               out.actuator_power, out.dissipation_rate);
  stop_indicators(p, out.rho, out.stop_indicators);
  return Status::Ok;
}

double Plant::constraint_residual() const {
  Vec16 q, qd;
  if (expand_state(model_, y_, q, qd) != Status::Ok) return std::numeric_limits<double>::quiet_NaN();
  return constraints(model_, q).norm();
}

double Plant::jacobian_condition() const {
  Vec16 q, qd;
  if (expand_state(model_, y_, q, qd) != Status::Ok) return std::numeric_limits<double>::infinity();
  return actuator_jacobian_condition(model_, q);
}

}  // namespace pkm
