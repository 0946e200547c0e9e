// PKM4PUU.fmu: forward dynamics of the 4-PUU robot (the plant), over
// pkm::Plant. Variables, names and units: MODEL_SPEC "FMU interface contract".
//
// Immutable: the table below and the ModelDefinition (shared by every
// instance); pkm::Model, built once per instance at the end of
// initialisation and owned by the instance's pkm::Plant.
// Per instance (PlantData): parameter values, inputs and their first
// derivatives, the output cache and the Plant (integrated state).
//
// Time stepping: every fmi2DoStep integrates with inputs
// u(t) = u + du (t - t_step_start) (du from fmi2SetRealInputDerivatives,
// reset to 0 whenever u is set). After a step the inputs hold their
// extrapolated values u + du h, the inputs at the new time. CVODE continues
// its history across the communication point (Plant::advance with
// continuous = true: no restart) when the inputs did not jump there
// (inputs_continue): every input at the step start equals its value at the
// end of the previous step within kInputJump (relative: rounding) -- inputs
// held constant, or a ramp whose values and slopes the master sets each
// step (a change of slope is a kink, which CVODE's error test resolves).
// A value that differs is a jump, and CVODE restarts at the step start:
// integrating across a jump from the old history costs accuracy (pkm_tick_bench:
// 1e-6 m after 1 s with midpoint-held forces, or with value and slope sampled
// from a curved signal, whose lines miss each other by u'' h^2 / 2, against
// 6e-9 m restarted).
// FMU states: CVODE's history is not part of a saved state. The next step
// after a GetFMUState restarts, as the first step after a SetFMUState does
// (PlantData::state_saved), so a restored run continues bit for bit like
// the original one (RK4 keeps no history: nothing changes for it).
//
// Outputs are computed lazily by group (the state's copies, the legs, the
// dynamics, the machine, the health measures: kGroup* below), each on the
// first get that reads it after anything changed, so that a controller
// reading the pose and the sliders does not pay for the multipliers. The
// accelerations, hence lambda, depend on the inputs at the current time.
//
// Model Exchange: the continuous states are the pose and its velocity (the
// outputs x..dphi) and the energy audit's two running integrals
// (actuator_work, dissipated_energy); the importer's integrator sets them and
// the time, the legs are reconstructed from the pose (closed form), so the
// states never leave the constraint manifold. The event indicators are the
// singularity guards (pkm::guard_indicators), whose crossing terminates the
// simulation with a logged reason as a discarded step does in
// Co-Simulation, and the end stops (rho_i - rho_min, rho_max - rho_i), whose
// crossings are events logged under logEvents.
#include <cmath>
#include <cstring>
#include <iterator>
#include <memory>

#include "pkm4puu/kinematics/constraints.hpp"
#include "pkm4puu/dynamics/reduced_dynamics_derivatives.hpp"
#include "pkm4puu/machine/passive_force.hpp"
#include "pkm4puu/kinematics/actuator_positions.hpp"
#include "models/common/mechanism_parameters.hpp"
#include "models/models.hpp"
#include "pkm4puu/sim/plant.hpp"
#include "pkm4puu/kinematics/workspace_guard.hpp"

namespace pkm_fmi {
namespace {

constexpr pkm::SolverSettings kDefaultSolver{};
constexpr int kStates = 10;  // pose, velocity, actuator_work, dissipated_energy
constexpr int kIndicators = pkm::kGuardIndicators + pkm::kStopIndicators;
constexpr int kInputs = 12;  // F[1..4], Fe[1..3], Me_z, tau[1..4]
// MODEL_SPEC "A check anyone can derive": each actuator's share of the
// weight at the default initial pose, the start value of F[1..4] (so that a
// plant nothing drives stays where it is).
constexpr double kHoldingForce = 2.655616050;
// An input jumps at a communication point when it differs from its value at
// the end of the previous step by more than this, relative to 1 + |value|
// (in N, N*m): far above the rounding of a master that evaluates a ramp
// a + b t where the FMU extrapolated u + b h (a few 1e-16), far below any
// jump that matters (a jump of 1e-12 N moves the platform by ~1e-16 m in a
// millisecond).
constexpr double kInputJump = 1e-12;

// The output groups (Variable::group): a get computes only the groups it
// reads, each once until the state, time or inputs change.
enum : std::uint8_t {
  kGroupState = 1u << 0,     // pose, velocity, energy integrals, der(pose): copies of the state
  kGroupJoints = 1u << 1,    // drho, theta1, theta2: the legs in closed form
  kGroupDynamics = 1u << 2,  // accelerations and multipliers: the full forward dynamics
  kGroupMachine = 1u << 3,   // end stops, holding forces, energies and their rates
  kGroupHealth = 1u << 4,    // loop-closure residual, Jacobian condition, guard indicators
  kGroupSliders = 1u << 5,   // rho: the closed form without angles (what a joint-space controller reads)
};

struct PlantData final : MechanismData {
  // Parameters beyond the mechanism's: initial state and solver settings.
  double pose0[4] = {0.0, 0.0, 0.05, 0.0};
  double vel0[4] = {0.0, 0.0, 0.0, 0.0};
  std::int32_t solver = static_cast<std::int32_t>(kDefaultSolver.solver);
  double rk4_step = kDefaultSolver.rk4_step;
  double rtol = kDefaultSolver.rtol;
  double atol = kDefaultSolver.atol;
  std::int32_t cvode_method = static_cast<std::int32_t>(kDefaultSolver.cvode_method);
  std::int32_t formulation = static_cast<std::int32_t>(kDefaultSolver.formulation);
  // Inputs u = [F1..F4, Fe1..Fe3, Me_z, tau1..tau4] at the current time, and du/dt.
  double u[kInputs] = {kHoldingForce, kHoldingForce, kHoldingForce, kHoldingForce};
  double du[kInputs] = {};
  // Outputs (computed by update_outputs).
  double pose[4] = {}, vel[4] = {};
  double rho[4] = {}, drho[4] = {}, theta1[4] = {}, theta2[4] = {};
  double lambda[12] = {};
  double residual = 0.0, condition = 0.0;
  double F_hold[4] = {}, stop_force[4] = {};
  double kinetic = 0.0, potential = 0.0;
  double energy[2] = {};  // actuator_work, dissipated_energy (states)
  double dy[kStates] = {};  // der(x) .. der(dphi), der(actuator_work), der(dissipated_energy)
  double z[kIndicators] = {};  // the event indicators: guards, then end stops
  // Model Exchange: the stops passed at the last event (end_stops.hpp's
  // contact mode), to log contacts and releases.
  unsigned logged_stops = 0;
  // Co-Simulation: end-stop events located so far (logged per step).
  long contact_events = 0;
  // Co-Simulation: the inputs at the end of the last step and whether CVODE
  // may continue from there (no restart, failure or saved state since).
  double u_end[kInputs] = {};
  bool may_continue = false;
  // The simulated machine (nullptr before initialisation).
  std::unique_ptr<pkm::Plant> plant;

  void reset() override {
    plant.reset();
    may_continue = false;
  }
  void state_saved() override { may_continue = false; }
  /// Whether every input continues its value at the end of the last step (kInputJump).
  bool inputs_continue() const;
  Status exit_initialization(Context& ctx) override;
  Status do_step(Context& ctx, double t, double h, double& t_reached) override;
  Status check_step(Context& ctx, double h) const override;
  Status update_outputs(Context& ctx, unsigned groups) override;
  void save(StateWriter& w) const override;
  bool load(StateReader& r, Context& ctx) override;

  void set_time(double t) override {
    if (plant) plant->set_time(t);
  }
  Status get_states(Context& ctx, double x[]) override;
  Status set_states(Context& ctx, const double x[]) override;
  Status get_derivatives(Context& ctx, double dx[]) override;
  Status get_event_indicators(Context& ctx, double z[]) override;
  Status event_update(Context& ctx, bool& terminate) override;
  Status partial_derivatives(Context& ctx, const Variable* const unknowns[], std::size_t nu,
                             const Variable* const knowns[], std::size_t nk, double J[]) override;

  /// The absolute time of the plant (its own time is the time since startTime), for messages.
  double absolute_time(const Context& ctx) const { return ctx.start_time + plant->time(); }
  /// The model and solver settings of the current parameters (Error, logged, if unusable).
  Status configuration(Context& ctx, const char* function, pkm::Model& model, pkm::SolverSettings& s) const;
  /// A Plant for the current parameters (not yet initialised).
  Status make_plant(Context& ctx, const char* function, std::unique_ptr<pkm::Plant>& out) const;
  /// Whether the plant exists and was built from these parameters and settings.
  bool built_from(const pkm::Model& model, const pkm::SolverSettings& s) const;
  /// make_plant, then the consistent initial state from x0..phi0, dx0..dphi0.
  Status build(Context& ctx, const char* function);
  /// The plant, built from the current parameters in initialisation mode.
  Status ready(Context& ctx, const char* function);
  pkm::LinearInputs inputs(double t0) const;
  /// The stops passed now (end_stops.hpp's contact mode; bit k: indicator k < 0).
  unsigned stops_passed_now() const;
  /// Logs (logEvents) each stop passed or left since the last call.
  void log_stop_changes(Context& ctx, unsigned now, const char* where);
};

Status PlantData::make_plant(Context& ctx, const char* function, std::unique_ptr<pkm::Plant>& out) const {
  pkm::Model model;
  pkm::SolverSettings s;
  const Status st = configuration(ctx, function, model, s);
  if (st != Status::OK) return st;
  auto plant_new = std::make_unique<pkm::Plant>(model);
  std::string why;
  if (plant_new->set_solver(s, &why) != pkm::Status::Ok) {
    ctx.log.error("%s: parameter %s", function, why.c_str());
    return Status::Error;
  }
  out = std::move(plant_new);
  return Status::OK;
}

bool PlantData::built_from(const pkm::Model& model, const pkm::SolverSettings& s) const {
  static_assert(sizeof(pkm::Params) % sizeof(double) == 0, "Params holds doubles only: no padding to compare");
  return plant && std::memcmp(&plant->model().p, &model.p, sizeof(pkm::Params)) == 0 && plant->solver() == s;
}

Status PlantData::configuration(Context& ctx, const char* function, pkm::Model& model,
                                pkm::SolverSettings& s) const {
  std::string why;
  if (pkm::make_model(params, model, &why) != pkm::Status::Ok) {
    ctx.log.error("%s: %s", function, why.c_str());
    return Status::Error;
  }
  s = pkm::SolverSettings{};
  s.solver = static_cast<pkm::Solver>(solver);
  s.rk4_step = rk4_step;
  s.rtol = rtol;
  s.atol = atol;
  s.cvode_method = static_cast<pkm::CvodeMethod>(cvode_method);
  s.formulation = static_cast<pkm::Formulation>(formulation);
  s.max_jacobian_condition = limits.max_jacobian_condition;
  s.min_leg_measure = limits.min_leg_measure;
  const std::string invalid = pkm::validate(s);
  if (!invalid.empty()) {
    ctx.log.error("%s: parameter %s", function, invalid.c_str());
    return Status::Error;
  }
  return Status::OK;
}

Status PlantData::build(Context& ctx, const char* function) {
  std::unique_ptr<pkm::Plant> p;
  const Status st = make_plant(ctx, function, p);
  if (st != Status::OK) return st;
  const pkm::Pose pose_0(pose0[0], pose0[1], pose0[2], pose0[3]);
  const pkm::Pose vel_0(vel0[0], vel0[1], vel0[2], vel0[3]);
  const pkm::Status s = p->initialize(0.0, pose_0, vel_0);  // model time: since ctx.start_time
  if (s != pkm::Status::Ok) {
    const char* what = s == pkm::Status::Unreachable ? "cannot be assembled elbow-down"
                       : s == pkm::Status::Singular  ? "lies beyond the singularity limits"
                       : s == pkm::Status::SolverFailure ? "cannot be integrated (the solver could not be set up)"
                                                     : "cannot be used";
    ctx.log.error("%s: the initial state x0 = %.9g m, y0 = %.9g m, z0 = %.9g m, phi0 = %.9g rad (velocity dx0 = %g, "
                  "dy0 = %g, dz0 = %g m/s, dphi0 = %g rad/s) %s: %s: %s",
                  function, pose0[0], pose0[1], pose0[2], pose0[3], vel0[0], vel0[1], vel0[2], vel0[3], what,
                  pkm::status_name(s), p->last_error().c_str());
    return Status::Error;
  }
  plant = std::move(p);
  contact_events = plant->contact_events();
  logged_stops = stops_passed_now();
  may_continue = false;
  return Status::OK;
}

unsigned PlantData::stops_passed_now() const {
  pkm::Vec4 rho;
  if (plant->actuator_positions(rho) != pkm::Status::Ok) return 0;
  return pkm::stops_passed(plant->model().p, rho);
}

void PlantData::log_stop_changes(Context& ctx, unsigned now, const char* where) {
  const unsigned changed = now ^ logged_stops;
  for (int k = 0; k < pkm::kStopIndicators; ++k) {
    if (!(changed & (1u << k))) continue;
    const bool lower = k < 4;
    ctx.log.event("%s at t = %.17g: slider %d %s its %s end stop (%s = %.9g m)", where, absolute_time(ctx), k % 4 + 1,
                  (now & (1u << k)) ? "passes" : "leaves", lower ? "lower" : "upper", lower ? "rho_min" : "rho_max",
                  lower ? plant->model().p.rho_min : plant->model().p.rho_max);
  }
  logged_stops = now;
}

pkm::LinearInputs PlantData::inputs(double t0) const {
  pkm::LinearInputs in;
  in.t0 = t0;
  in.F0 = pkm::Vec4(u[0], u[1], u[2], u[3]);
  in.dF = pkm::Vec4(du[0], du[1], du[2], du[3]);
  in.we0 = pkm::Wrench(u[4], u[5], u[6], u[7]);
  in.dwe = pkm::Wrench(du[4], du[5], du[6], du[7]);
  in.tau0 = pkm::Vec4(u[8], u[9], u[10], u[11]);
  in.dtau = pkm::Vec4(du[8], du[9], du[10], du[11]);
  return in;
}

Status PlantData::exit_initialization(Context& ctx) { return build(ctx, "ExitInitializationMode"); }

Status PlantData::ready(Context& ctx, const char* function) {
  if (ctx.initialization_mode) {
    // Initial values for the parameters set so far.
    const Status st = build(ctx, function);
    if (st != Status::OK) return st;
  }
  if (!plant || !plant->initialized()) {
    ctx.log.error("%s: no state (initialisation did not succeed)", function);
    return Status::Error;
  }
  return Status::OK;
}

Status PlantData::do_step(Context& ctx, double t, double h, double& t_reached) {
  if (!plant || !plant->initialized()) {
    ctx.log.error("DoStep: no state (initialisation did not succeed)");
    return Status::Error;
  }
  const double t_start = plant->time();
  const double t_end = t + h;
  t_reached = t_start;
  pkm::LinearInputs in = inputs(t_start);
  const double span = t_end - t_start;
  if (!(in.F0 + in.dF * span).allFinite() || !(in.we0 + in.dwe * span).allFinite() ||
      !(in.tau0 + in.dtau * span).allFinite()) {
    ctx.log.error("DoStep: the inputs extrapolated with their derivatives to t = %.17g are not finite", t_end);
    return Status::Error;
  }
  const bool continuous = may_continue && inputs_continue();
  const pkm::Status s = plant->advance(t_end, in.signal(), continuous);
  t_reached = plant->time();
  // The inputs now refer to the time reached.
  if (t_reached != t_start)
    for (int k = 0; k < kInputs; ++k)
      if (du[k] != 0.0) u[k] += du[k] * (t_reached - t_start);
  may_continue = s == pkm::Status::Ok;
  std::memcpy(u_end, u, sizeof u_end);
  if (plant->contact_events() != contact_events) {
    contact_events = plant->contact_events();
    // Also with logEvents off: the record of the stops passed stays current.
    log_stop_changes(ctx, stops_passed_now(), "DoStep");
  }
  switch (s) {
    case pkm::Status::Ok:
      return Status::OK;
    case pkm::Status::SolverFailure:
    case pkm::Status::Unreachable:
    case pkm::Status::Singular:
    case pkm::Status::NotConverged:
      // The plant kept its last good state (RK4: last whole step; CVODE: the
      // step start), within the singularity limits. The layer sets
      // terminated: a master stops at the last successful time instead of
      // retrying the same step.
      ctx.log.discard("DoStep: integration from t = %.17g to %.17g failed (%s%s%s, times since startTime); the "
                      "state is kept at t = %.17g (the last successful time), terminated = true",
                      ctx.start_time + t_start, ctx.start_time + t_end, pkm::status_name(s),
                      plant->last_error().empty() ? "" : ": ", plant->last_error().c_str(), ctx.start_time + t_reached);
      return Status::Discard;
    default:
      ctx.log.error("DoStep: integration from t = %.17g to %.17g failed: %s%s%s", ctx.start_time + t_start,
                    ctx.start_time + t_end,
                    pkm::status_name(s), plant->last_error().empty() ? "" : ": ", plant->last_error().c_str());
      return Status::Error;
  }
}

bool PlantData::inputs_continue() const {
  for (int k = 0; k < kInputs; ++k)
    if (!(std::abs(u[k] - u_end[k]) <= kInputJump * (1.0 + std::abs(u_end[k])))) return false;
  return true;
}

Status PlantData::check_step(Context& ctx, double h) const {
  if (!plant || plant->solver().solver != pkm::Solver::Rk4) return Status::OK;
  const double step = plant->solver().rk4_step;
  const double steps = pkm::rk4_steps_for(h, step);
  if (steps <= pkm::kMaxRk4StepsPerAdvance) return Status::OK;
  ctx.log.error("DoStep: a communication step of %.6g s needs %.3g RK4 steps of rk4_step = %.6g s, more than the "
                "work budget of %.0e per step: use shorter communication steps or a larger rk4_step; the call has "
                "no effect",
                h, steps, step, pkm::kMaxRk4StepsPerAdvance);
  return Status::Error;
}

Status PlantData::update_outputs(Context& ctx, unsigned groups) {
  const Status st = ready(ctx, "get");
  if (st != Status::OK) return st;
  const double t = absolute_time(ctx);  // for the messages; the model's own time is plant->time()
  bool finite = true;
  auto all_finite = [&finite](const double* v, int n) {
    for (int i = 0; i < n; ++i) finite = finite && std::isfinite(v[i]);
  };
  auto cannot_assemble = [&ctx, t](pkm::Status s) {
    ctx.log.error("get: the legs cannot be assembled at t = %.17g: %s", t, pkm::status_name(s));
    return Status::Error;
  };
  if (groups & kGroupState) {  // copies of the state
    const pkm::Vec8& y = plant->state();
    for (int i = 0; i < 4; ++i) {
      pose[i] = y[i];
      vel[i] = dy[i] = y[4 + i];
    }
    energy[0] = plant->energy_integrals().actuator_work;
    energy[1] = plant->energy_integrals().dissipated;
  }
  if (groups & kGroupJoints) {
    pkm::Vec16 q, qd;
    const pkm::Status s = plant->coordinates(q, qd);
    if (s != pkm::Status::Ok) {
      return cannot_assemble(s);
    }
    for (int i = 0; i < 4; ++i) {
      const int o = pkm::leg_offset(i);
      drho[i] = qd[o];
      theta1[i] = q[o + 1];
      theta2[i] = q[o + 2];
    }
    for (const double* block : {drho, theta1, theta2}) all_finite(block, 4);
  }
  if (groups & kGroupSliders) {
    pkm::Vec4 r;
    const pkm::Status s = plant->actuator_positions(r);
    if (s != pkm::Status::Ok) {
      return cannot_assemble(s);
    }
    for (int i = 0; i < 4; ++i) rho[i] = r[i];
    all_finite(rho, 4);
  }
  if (groups & kGroupDynamics) {  // Eqs. 12-13 and the multipliers
    pkm::MechanismState ms;
    const pkm::Status s = plant->mechanism(inputs(plant->time()).signal(), ms);
    if (s != pkm::Status::Ok) {
      ctx.log.error("get: the mechanism cannot be evaluated at t = %.17g: %s", t, pkm::status_name(s));
      return Status::Error;
    }
    for (int i = 0; i < 4; ++i) dy[4 + i] = ms.qdd[12 + i];
    for (int k = 0; k < 12; ++k) lambda[k] = ms.lambda[k];
    all_finite(dy + 4, 4);
    all_finite(lambda, 12);
  }
  if (groups & kGroupMachine) {
    pkm::MachineOutputs mo;
    const pkm::Status s = plant->machine_outputs(inputs(plant->time()).signal(), mo);
    if (s != pkm::Status::Ok) {
      ctx.log.error("get: the machine's outputs cannot be evaluated at t = %.17g: %s", t, pkm::status_name(s));
      return Status::Error;
    }
    for (int i = 0; i < 4; ++i) {
      F_hold[i] = mo.F_hold[i];
      stop_force[i] = mo.stop_force[i];
    }
    kinetic = mo.kinetic_energy;
    potential = mo.potential_energy;
    dy[8] = mo.actuator_power;
    dy[9] = mo.dissipation_rate;
    for (int k = 0; k < pkm::kStopIndicators; ++k) z[pkm::kGuardIndicators + k] = mo.stop_indicators[k];
    for (const double* block : {F_hold, stop_force}) all_finite(block, 4);
    for (double v : {kinetic, potential, dy[8], dy[9]}) finite = finite && std::isfinite(v);
  }
  if (groups & kGroupHealth) {  // one SVD for the condition number and its guard indicator
    pkm::Vec16 q, qd;
    pkm::Status s = plant->coordinates(q, qd);
    if (s == pkm::Status::Ok)
      s = pkm::guard_indicators(plant->model(), plant->state().head<4>(), plant->solver().limits(), z, &condition);
    if (s != pkm::Status::Ok) {
      return cannot_assemble(s);
    }
    residual = pkm::constraints(plant->model(), q).norm();
    finite = finite && std::isfinite(residual) && !std::isnan(condition);  // +inf at a singularity, never NaN
  }
  if (!finite) {
    ctx.log.error("get: non-finite outputs at t = %.17g (singular configuration?)", t);
    return Status::Error;
  }
  return Status::OK;
}

// ---------------------------------------------------------------- Model Exchange

Status PlantData::get_states(Context& ctx, double x[]) {
  const Status st = ready(ctx, "GetContinuousStates");
  if (st != Status::OK) return st;
  for (int k = 0; k < 8; ++k) x[k] = plant->state()[k];
  x[8] = plant->energy_integrals().actuator_work;
  x[9] = plant->energy_integrals().dissipated;
  return Status::OK;
}

Status PlantData::set_states(Context& ctx, const double x[]) {
  const Status st = ready(ctx, "SetContinuousStates");
  if (st != Status::OK) return st;
  const pkm::Vec8 y = Eigen::Map<const pkm::Vec8>(x);
  if (!std::isfinite(x[8]) || !std::isfinite(x[9])) {
    ctx.log.error("SetContinuousStates: actuator_work = %g J or dissipated_energy = %g J is not finite; the states "
                  "are unchanged", x[8], x[9]);
    return Status::Error;
  }
  const pkm::Status s = plant->set_state(y);
  if (s == pkm::Status::Ok) plant->set_energy_integrals({x[8], x[9]});
  if (s != pkm::Status::Ok) {
    ctx.log.discard("SetContinuousStates: the pose x = %.9g m, y = %.9g m, z = %.9g m, phi = %.9g rad at t = %.17g "
                    "cannot be assembled (%s: %s); the states are unchanged (a smaller step may stay within the "
                    "workspace)",
                    x[0], x[1], x[2], x[3], absolute_time(ctx), pkm::status_name(s), plant->last_error().c_str());
    return Status::Discard;
  }
  return Status::OK;
}

Status PlantData::get_derivatives(Context& ctx, double dx[]) {
  const Status st = ready(ctx, "GetDerivatives");
  if (st != Status::OK) return st;
  pkm::Vec10 xdot;
  const pkm::Status s = plant->derivative_now(inputs(plant->time()).signal(), xdot);
  if (s != pkm::Status::Ok || !xdot.allFinite()) {
    ctx.log.error("GetDerivatives: the state derivative at t = %.17g cannot be evaluated: %s", absolute_time(ctx),
                  s != pkm::Status::Ok ? pkm::status_name(s) : "not finite (singular configuration?)");
    return Status::Error;
  }
  for (int k = 0; k < kStates; ++k) dx[k] = xdot[k];
  return Status::OK;
}

// ---------------------------------------------------------------- partial derivatives

// Analytic (reduced_dynamics_derivatives.hpp) at the current state and
// inputs, the end stops acting when their joint is past them: der(x) ..
// der(dphi), der(actuator_work) (= Fa . drho + we . pd) and
// der(dissipated_energy) (machine.hpp, dissipated_power_slopes), the states
// as outputs, rho[i] and drho[i]. The other computed variables are refused
// with Error (not differentiated yet).
Status PlantData::partial_derivatives(Context& ctx, const Variable* const unknowns[], std::size_t nu,
                                      const Variable* const knowns[], std::size_t nk, double J[]) {
  const char* fn = "GetDirectionalDerivative";
  const Status st = ready(ctx, fn);
  if (st != Status::OK) return st;
  const pkm::Vec4 F(u[0], u[1], u[2], u[3]), we(u[4], u[5], u[6], u[7]), tau(u[8], u[9], u[10], u[11]);
  const pkm::Vec8& y = plant->state();
  pkm::Vec8 ydot;
  pkm::Mat8 A;
  pkm::Mat8x12 B;
  pkm::JointJacobians joints;
  const pkm::Status s =
      pkm::state_derivative_jacobians(plant->model(), y, F, tau, we, pkm::kStopsFromState, ydot, A, B, &joints);
  if (s != pkm::Status::Ok) {
    ctx.log.error("%s: the derivatives at t = %.17g cannot be evaluated: %s", fn, plant->time(), pkm::status_name(s));
    return Status::Error;
  }
  const pkm::Vec4 rhod = joints.J_rho * y.tail<4>();
  pkm::Vec4 rho;
  if (pkm::actuator_positions(plant->model(), y.head<4>(), rho) != pkm::Status::Ok) {
    ctx.log.error("%s: the actuator positions at t = %.17g cannot be evaluated", fn, plant->time());
    return Status::Error;
  }
  // One row over [the 10 states, the 12 inputs u] per unknown.
  Eigen::Matrix<double, 1, kStates + kInputs> row;
  for (std::size_t i = 0; i < nu; ++i) {
    const Variable& v = *unknowns[i];
    row.setZero();
    if (v.state_of >= 0 && v.state_of < 8) {
      row.head<8>() = A.row(v.state_of);
      row.tail<kInputs>() = B.row(v.state_of);
    } else if (v.state_of == 8) {  // der(actuator_work)
      const pkm::Vec4 Fa = F + plant->model().drive_ratio * tau;
      row.head<4>() = Fa.transpose() * joints.drhod_dp;
      row.segment<4>(4) = Fa.transpose() * joints.J_rho + we.transpose();
      row.segment<4>(kStates) = rhod.transpose();
      row.segment<4>(kStates + 4) = y.tail<4>().transpose();
      row.segment<4>(kStates + 8) = plant->model().drive_ratio * rhod.transpose();
    } else if (v.state_of == 9) {  // der(dissipated_energy): sum over the joints
      for (int l = 0; l < 4; ++l) {
        const pkm::PassiveSlopes d = pkm::dissipated_power_slopes(plant->model().p, l, pkm::kStopsFromState, rho[l], rhod[l]);
        row.head<4>() += d.drho * joints.J_rho.row(l) + d.drhod * joints.drhod_dp.row(l);
        row.segment<4>(4) += d.drhod * joints.J_rho.row(l);
      }
    } else if (v.state >= 0) {
      row[v.state] = 1.0;
    } else if (std::strncmp(v.name, "rho[", 4) == 0) {
      row.head<4>() = joints.J_rho.row(v.index);
    } else if (std::strncmp(v.name, "drho[", 5) == 0) {
      row.head<4>() = joints.drhod_dp.row(v.index);
      row.segment<4>(4) = joints.J_rho.row(v.index);
    } else {
      ctx.log.error("%s: the partial derivatives of %s are not provided (analytic so far: the states' "
                    "derivatives, the states, rho[1..4] and drho[1..4])",
                    fn, v.name);
      return Status::Error;
    }
    for (std::size_t j = 0; j < nk; ++j) {
      const Variable& k = *knowns[j];
      J[i * nk + j] = row[k.state >= 0 ? k.state : kStates + k.index];
    }
  }
  return Status::OK;
}

Status PlantData::get_event_indicators(Context& ctx, double z[]) {
  const Status st = ready(ctx, "GetEventIndicators");
  if (st != Status::OK) return st;
  const pkm::Pose pose_now = plant->state().head<4>();
  pkm::Status s = pkm::guard_indicators(plant->model(), pose_now, plant->solver().limits(), z);
  if (s == pkm::Status::Ok) s = pkm::stop_indicators(plant->model(), pose_now, z + pkm::kGuardIndicators);
  if (s != pkm::Status::Ok) {
    ctx.log.error("GetEventIndicators: not defined at t = %.17g: %s", absolute_time(ctx), pkm::status_name(s));
    return Status::Error;
  }
  return Status::OK;
}

Status PlantData::event_update(Context& ctx, bool& terminate) {
  terminate = false;
  double z[kIndicators];
  const Status st = get_event_indicators(ctx, z);
  if (st != Status::OK) return st;
  unsigned beyond = 0;
  for (int k = 0; k < pkm::kStopIndicators; ++k)
    if (z[pkm::kGuardIndicators + k] < 0.0) beyond |= 1u << k;
  log_stop_changes(ctx, beyond, "event");
  for (int k = 0; k < pkm::kGuardIndicators; ++k) {
    if (z[k] > 0.0) continue;
    terminate = true;
    if (k == 0) {
      ctx.log.warning("event at t = %.17g: the actuator Jacobian's condition number reached max_jacobian_condition "
                      "= %g (parallel-singularity guard); terminateSimulation = true",
                      absolute_time(ctx), plant->solver().max_jacobian_condition);
    } else {
      ctx.log.warning("event at t = %.17g: leg %d reached min_leg_measure = %g (leg-singularity guard: rod nearly "
                      "horizontal or vertical); terminateSimulation = true",
                      absolute_time(ctx), k, plant->solver().min_leg_measure);
    }
    return Status::Warning;
  }
  return Status::OK;
}

// ---------------------------------------------------------------- FMU state

void PlantData::save(StateWriter& w) const {
  const bool has = plant && plant->initialized();
  w.u8(has ? 1 : 0);
  if (!has) return;
  w.f64(plant->time());
  w.f64s(plant->state().data(), plant->state().data() + 8);
  w.f64s(plant->theta1_ref().data(), plant->theta1_ref().data() + 4);
  w.f64(plant->energy_integrals().actuator_work);
  w.f64(plant->energy_integrals().dissipated);
  w.u32(logged_stops);
}

bool PlantData::load(StateReader& r, Context& ctx) {
  if (r.u8() == 0) {
    plant.reset();
    return r.ok();
  }
  const double t = r.f64();
  pkm::Vec8 y;
  pkm::Vec4 ref;
  r.f64s(y.data(), y.data() + 8);
  r.f64s(ref.data(), ref.data() + 4);
  const pkm::EnergyIntegrals e{r.f64(), r.f64()};
  const unsigned beyond = r.u32();
  if (!r.ok()) return false;
  if (beyond >> pkm::kStopIndicators) {
    ctx.log.error("SetFMUState: malformed FMU state (end-stop record %#x names no stop)", beyond);
    return false;
  }
  // The plant, with its solver's objects, is kept when the restored
  // parameters are those it was built with (restore() restarts its
  // integrator): a restore allocates nothing. Otherwise a new one.
  pkm::Model model;
  pkm::SolverSettings settings;
  if (configuration(ctx, "SetFMUState", model, settings) != Status::OK) return false;
  std::unique_ptr<pkm::Plant> fresh;
  if (!built_from(model, settings) && make_plant(ctx, "SetFMUState", fresh) != Status::OK) return false;
  pkm::Plant& p = fresh ? *fresh : *plant;
  const pkm::Status s = p.restore(t, y, ref, e);
  if (s != pkm::Status::Ok) {
    ctx.log.error("SetFMUState: the saved state at t = %.17g cannot be restored: %s%s%s", t, pkm::status_name(s),
                  p.last_error().empty() ? "" : ": ", p.last_error().c_str());
    return false;
  }
  if (fresh) plant = std::move(fresh);
  contact_events = plant->contact_events();  // the count continues from here
  logged_stops = beyond;
  may_continue = false;  // the integrator restarts here, as the original run does after saving
  return true;
}

// ---------------------------------------------------------------- the table

#define PLANT(member) \
  [](ModelData& d, int i) -> void* { return &static_cast<PlantData&>(d).member[i]; }
#define PLANT_SCALAR(member) \
  [](ModelData& d, int) -> void* { return &static_cast<PlantData&>(d).member; }

// The states' scales (nominal), which importers use for their absolute
// tolerance (rtol x nominal): the workspace spans centimetres, so 0.1 m; the
// spec's test motion peaks at 0.019 m/s and 0.065 rad/s, so 0.01 m/s and
// 0.1 rad/s (a rate scale of 0.1 m/s would let an importer's velocity error
// grow tenfold before its error test notices, and z, which no stiffness
// holds, integrates that error); the rotation 1 rad; the energy integrals
// 0.1 J (the auto-test does about 0.2 J of work).
constexpr double kNominalLength = 0.1, kNominalAngle = 1.0, kNominalEnergy = 0.1;
constexpr double kNominalSpeed = 0.01, kNominalAngularSpeed = 0.1;

// What the outputs depend on. Only the slider positions follow z (the
// mechanism is otherwise invariant to a vertical translation), and through
// them whatever the end stops act on; only the slider velocities follow dz,
// and through them friction and the stops' damping.
constexpr std::uint8_t kSliders = kOnPositions | kOnHeight;
constexpr std::uint8_t kSliderRates = kOnPositions | kOnRates | kOnHeightRate;
constexpr std::uint8_t kEverything = kSliders | kSliderRates | kOnInputs;
constexpr std::uint8_t kWrench = kOnInputs | kOnWrench;  // the kind of Fe, Me_z

// clang-format off
constexpr Variable kVariables[] = {
  time_variable(0),
  // Inputs: 1..8.
  real_input(1, "F[1]", kHoldingForce, "N", "Actuator force on the slider of leg 1, along +z", PLANT(u), 0, PLANT(du)),
  real_input(2, "F[2]", kHoldingForce, "N", "Actuator force on the slider of leg 2, along +z", PLANT(u), 1, PLANT(du)),
  real_input(3, "F[3]", kHoldingForce, "N", "Actuator force on the slider of leg 3, along +z", PLANT(u), 2, PLANT(du)),
  real_input(4, "F[4]", kHoldingForce, "N", "Actuator force on the slider of leg 4, along +z", PLANT(u), 3, PLANT(du)),
  real_input(5, "Fe[1]", 0.0, "N", "External force on the platform at P, x component (base frame)", PLANT(u), 4, PLANT(du), kWrench),
  real_input(6, "Fe[2]", 0.0, "N", "External force on the platform at P, y component (base frame)", PLANT(u), 5, PLANT(du), kWrench),
  real_input(7, "Fe[3]", 0.0, "N", "External force on the platform at P, z component (base frame)", PLANT(u), 6, PLANT(du), kWrench),
  real_input(8, "Me_z", 0.0, "N.m", "External moment on the platform about z", PLANT(u), 7, PLANT(du), kWrench),
  // Outputs: 10..53; x..dphi are the continuous states (Model Exchange).
  state_output(10, "x", "m", "Platform reference point P (centre of mass), x in the base frame", PLANT(pose), 0, 0, kOnPositions, kNominalLength, kGroupState),
  state_output(11, "y", "m", "Platform reference point P (centre of mass), y in the base frame", PLANT(pose), 1, 1, kOnPositions, kNominalLength, kGroupState),
  state_output(12, "z", "m", "Platform reference point P (centre of mass), z in the base frame", PLANT(pose), 2, 2, kOnHeight, kNominalLength, kGroupState),
  state_output(13, "phi", "rad", "Platform rotation about z of the base frame", PLANT(pose), 3, 3, kOnPositions, kNominalAngle, kGroupState),
  state_output(14, "dx", "m/s", "Velocity of P, x component", PLANT(vel), 0, 4, kOnRates, kNominalSpeed, kGroupState),
  state_output(15, "dy", "m/s", "Velocity of P, y component", PLANT(vel), 1, 5, kOnRates, kNominalSpeed, kGroupState),
  state_output(16, "dz", "m/s", "Velocity of P, z component", PLANT(vel), 2, 6, kOnHeightRate, kNominalSpeed, kGroupState),
  state_output(17, "dphi", "rad/s", "Platform angular velocity about z", PLANT(vel), 3, 7, kOnRates, kNominalAngularSpeed, kGroupState),
  state_output(18, "actuator_work", "J", "Work done on the machine since the start: integral of (F_i + (2 pi/screw_lead) tau_i) drho_i plus the external wrench's power", PLANT(energy), 0, 8, kOnEnergy, kNominalEnergy, kGroupState),
  state_output(19, "dissipated_energy", "J", "Energy dissipated since the start by joint friction and the end stops' damping", PLANT(energy), 1, 9, kOnEnergy, kNominalEnergy, kGroupState),
  real_output(20, "rho[1]", "m", "Actuated prismatic joint of leg 1 (slider position)", PLANT(rho), 0, kSliders, kGroupSliders),
  real_output(21, "rho[2]", "m", "Actuated prismatic joint of leg 2 (slider position)", PLANT(rho), 1, kSliders, kGroupSliders),
  real_output(22, "rho[3]", "m", "Actuated prismatic joint of leg 3 (slider position)", PLANT(rho), 2, kSliders, kGroupSliders),
  real_output(23, "rho[4]", "m", "Actuated prismatic joint of leg 4 (slider position)", PLANT(rho), 3, kSliders, kGroupSliders),
  real_output(24, "drho[1]", "m/s", "Slider velocity of leg 1", PLANT(drho), 0, kOnPositions | kOnRates | kOnHeightRate, kGroupJoints),
  real_output(25, "drho[2]", "m/s", "Slider velocity of leg 2", PLANT(drho), 1, kOnPositions | kOnRates | kOnHeightRate, kGroupJoints),
  real_output(26, "drho[3]", "m/s", "Slider velocity of leg 3", PLANT(drho), 2, kOnPositions | kOnRates | kOnHeightRate, kGroupJoints),
  real_output(27, "drho[4]", "m/s", "Slider velocity of leg 4", PLANT(drho), 3, kOnPositions | kOnRates | kOnHeightRate, kGroupJoints),
  real_output(28, "theta1[1]", "rad", "First revolute joint of leg 1 (axis parallel to the prismatic axis), continuous", PLANT(theta1), 0, kOnPositions, kGroupJoints),
  real_output(29, "theta1[2]", "rad", "First revolute joint of leg 2 (axis parallel to the prismatic axis), continuous", PLANT(theta1), 1, kOnPositions, kGroupJoints),
  real_output(30, "theta1[3]", "rad", "First revolute joint of leg 3 (axis parallel to the prismatic axis), continuous", PLANT(theta1), 2, kOnPositions, kGroupJoints),
  real_output(31, "theta1[4]", "rad", "First revolute joint of leg 4 (axis parallel to the prismatic axis), continuous", PLANT(theta1), 3, kOnPositions, kGroupJoints),
  real_output(32, "theta2[1]", "rad", "Second revolute joint of leg 1 (horizontal axis), elbow-down: -pi/2 < theta2 < 0", PLANT(theta2), 0, kOnPositions, kGroupJoints),
  real_output(33, "theta2[2]", "rad", "Second revolute joint of leg 2 (horizontal axis), elbow-down: -pi/2 < theta2 < 0", PLANT(theta2), 1, kOnPositions, kGroupJoints),
  real_output(34, "theta2[3]", "rad", "Second revolute joint of leg 3 (horizontal axis), elbow-down: -pi/2 < theta2 < 0", PLANT(theta2), 2, kOnPositions, kGroupJoints),
  real_output(35, "theta2[4]", "rad", "Second revolute joint of leg 4 (horizontal axis), elbow-down: -pi/2 < theta2 < 0", PLANT(theta2), 3, kOnPositions, kGroupJoints),
  real_output(36, "stop_force[1]", "N", "End-stop force on the slider of leg 1, along +z (0 within its travel)", PLANT(stop_force), 0, kEverything & ~kOnInputs, kGroupMachine),
  real_output(37, "stop_force[2]", "N", "End-stop force on the slider of leg 2, along +z", PLANT(stop_force), 1, kEverything & ~kOnInputs, kGroupMachine),
  real_output(38, "stop_force[3]", "N", "End-stop force on the slider of leg 3, along +z", PLANT(stop_force), 2, kEverything & ~kOnInputs, kGroupMachine),
  real_output(39, "stop_force[4]", "N", "End-stop force on the slider of leg 4, along +z", PLANT(stop_force), 3, kEverything & ~kOnInputs, kGroupMachine),
  real_output(40, "lambda[1]", "N", "Lagrange multiplier of leg 1's loop closure, x row (Eq. 1)", PLANT(lambda), 0, kEverything, kGroupDynamics),
  real_output(41, "lambda[2]", "N", "Lagrange multiplier of leg 1's loop closure, y row (Eq. 1)", PLANT(lambda), 1, kEverything, kGroupDynamics),
  real_output(42, "lambda[3]", "N", "Lagrange multiplier of leg 1's loop closure, z row (Eq. 1)", PLANT(lambda), 2, kEverything, kGroupDynamics),
  real_output(43, "lambda[4]", "N", "Lagrange multiplier of leg 2's loop closure, x row (Eq. 1)", PLANT(lambda), 3, kEverything, kGroupDynamics),
  real_output(44, "lambda[5]", "N", "Lagrange multiplier of leg 2's loop closure, y row (Eq. 1)", PLANT(lambda), 4, kEverything, kGroupDynamics),
  real_output(45, "lambda[6]", "N", "Lagrange multiplier of leg 2's loop closure, z row (Eq. 1)", PLANT(lambda), 5, kEverything, kGroupDynamics),
  real_output(46, "lambda[7]", "N", "Lagrange multiplier of leg 3's loop closure, x row (Eq. 1)", PLANT(lambda), 6, kEverything, kGroupDynamics),
  real_output(47, "lambda[8]", "N", "Lagrange multiplier of leg 3's loop closure, y row (Eq. 1)", PLANT(lambda), 7, kEverything, kGroupDynamics),
  real_output(48, "lambda[9]", "N", "Lagrange multiplier of leg 3's loop closure, z row (Eq. 1)", PLANT(lambda), 8, kEverything, kGroupDynamics),
  real_output(49, "lambda[10]", "N", "Lagrange multiplier of leg 4's loop closure, x row (Eq. 1)", PLANT(lambda), 9, kEverything, kGroupDynamics),
  real_output(50, "lambda[11]", "N", "Lagrange multiplier of leg 4's loop closure, y row (Eq. 1)", PLANT(lambda), 10, kEverything, kGroupDynamics),
  real_output(51, "lambda[12]", "N", "Lagrange multiplier of leg 4's loop closure, z row (Eq. 1)", PLANT(lambda), 11, kEverything, kGroupDynamics),
  real_output(52, "constraint_residual", "m", "Norm of the loop closures ||C(q)|| (Eq. 15) at the current state", PLANT_SCALAR(residual), 0, kOnPositions, kGroupHealth),
  real_output(53, "jacobian_condition", "", "Condition number of the 4x4 actuator Jacobian d(rho)/d(x, y, z, phi), its phi column divided by 0.1 m", PLANT_SCALAR(condition), 0, kOnPositions, kGroupHealth),
  real_output(54, "F_hold[1]", "N", "Actuator force of leg 1 that would hold the current pose at rest under gravity, the payload and the current external wrench", PLANT(F_hold), 0, kOnPositions | kOnWrench, kGroupMachine),
  real_output(55, "F_hold[2]", "N", "The same for leg 2", PLANT(F_hold), 1, kOnPositions | kOnWrench, kGroupMachine),
  real_output(56, "F_hold[3]", "N", "The same for leg 3", PLANT(F_hold), 2, kOnPositions | kOnWrench, kGroupMachine),
  real_output(57, "F_hold[4]", "N", "The same for leg 4", PLANT(F_hold), 3, kOnPositions | kOnWrench, kGroupMachine),
  real_output(58, "kinetic_energy", "J", "Kinetic energy of the mechanism, the payload and the rotors", PLANT_SCALAR(kinetic), 0, kSliderRates, kGroupMachine),
  real_output(59, "potential_energy", "J", "Potential energy: gravity plus the end stops' springs", PLANT_SCALAR(potential), 0, kSliders, kGroupMachine),
  // Derivatives of the continuous states: 60..67.
  state_derivative(60, "der(x)", "m/s", "Derivative of x", PLANT(dy), 0, 0, kOnRates, kGroupState),
  state_derivative(61, "der(y)", "m/s", "Derivative of y", PLANT(dy), 1, 1, kOnRates, kGroupState),
  state_derivative(62, "der(z)", "m/s", "Derivative of z", PLANT(dy), 2, 2, kOnRates, kGroupState),
  state_derivative(63, "der(phi)", "rad/s", "Derivative of phi", PLANT(dy), 3, 3, kOnRates, kGroupState),
  state_derivative(64, "der(dx)", "m/s2", "Acceleration of P, x component (Eq. 13)", PLANT(dy), 4, 4, kEverything, kGroupDynamics),
  state_derivative(65, "der(dy)", "m/s2", "Acceleration of P, y component (Eq. 13)", PLANT(dy), 5, 5, kEverything, kGroupDynamics),
  state_derivative(66, "der(dz)", "m/s2", "Acceleration of P, z component (Eq. 13)", PLANT(dy), 6, 6, kEverything, kGroupDynamics),
  state_derivative(67, "der(dphi)", "rad/s2", "Angular acceleration of the platform about z (Eq. 13)", PLANT(dy), 7, 7, kEverything, kGroupDynamics),
  state_derivative(68, "der(actuator_work)", "W", "Power of the actuators, drives and external wrench", PLANT(dy), 8, 8, kSliderRates | kOnInputs, kGroupMachine),
  state_derivative(69, "der(dissipated_energy)", "W", "Power dissipated by friction and the end stops' damping", PLANT(dy), 9, 9, kEverything & ~kOnInputs, kGroupMachine),
  // Event indicators (Model Exchange): 70..74.
  event_indicator(70, "guard_condition_margin", "",
                  "1/jacobian_condition - 1/max_jacobian_condition: event indicator of the parallel-singularity guard "
                  "(positive within it)", PLANT(z), 0, 0, kOnPositions, kGroupHealth),
  event_indicator(71, "guard_leg_margin[1]", "",
                  "|cos(theta2) sin(theta2)| of leg 1 - min_leg_measure: event indicator of the leg-singularity guard "
                  "(positive within it)", PLANT(z), 1, 1, kOnPositions, kGroupHealth),
  event_indicator(72, "guard_leg_margin[2]", "", "The same for leg 2", PLANT(z), 2, 2, kOnPositions, kGroupHealth),
  event_indicator(73, "guard_leg_margin[3]", "", "The same for leg 3", PLANT(z), 3, 3, kOnPositions, kGroupHealth),
  event_indicator(74, "guard_leg_margin[4]", "", "The same for leg 4", PLANT(z), 4, 4, kOnPositions, kGroupHealth),
  event_indicator(75, "stop_margin_lower[1]", "m", "rho[1] - rho_min: event indicator of leg 1's lower end stop (negative in contact)", PLANT(z), 5, 5, kSliders, kGroupMachine),
  event_indicator(76, "stop_margin_lower[2]", "m", "rho[2] - rho_min", PLANT(z), 6, 6, kSliders, kGroupMachine),
  event_indicator(77, "stop_margin_lower[3]", "m", "rho[3] - rho_min", PLANT(z), 7, 7, kSliders, kGroupMachine),
  event_indicator(78, "stop_margin_lower[4]", "m", "rho[4] - rho_min", PLANT(z), 8, 8, kSliders, kGroupMachine),
  event_indicator(79, "stop_margin_upper[1]", "m", "rho_max - rho[1]: event indicator of leg 1's upper end stop (negative in contact)", PLANT(z), 9, 9, kSliders, kGroupMachine),
  event_indicator(80, "stop_margin_upper[2]", "m", "rho_max - rho[2]", PLANT(z), 10, 10, kSliders, kGroupMachine),
  event_indicator(81, "stop_margin_upper[3]", "m", "rho_max - rho[3]", PLANT(z), 11, 11, kSliders, kGroupMachine),
  event_indicator(82, "stop_margin_upper[4]", "m", "rho_max - rho[4]", PLANT(z), 12, 12, kSliders, kGroupMachine),
  // Motor torques: 90..93.
  real_input(90, "tau[1]", 0.0, "N.m", "Motor torque of leg 1's drive: adds (2 pi/screw_lead) tau to F[1]", PLANT(u), 8, PLANT(du)),
  real_input(91, "tau[2]", 0.0, "N.m", "Motor torque of leg 2's drive", PLANT(u), 9, PLANT(du)),
  real_input(92, "tau[3]", 0.0, "N.m", "Motor torque of leg 3's drive", PLANT(u), 10, PLANT(du)),
  real_input(93, "tau[4]", 0.0, "N.m", "Motor torque of leg 4's drive", PLANT(u), 11, PLANT(du)),
  // Parameters: the mechanism (100..120), the initial state (130..137), the
  // solver (140..147), the end stops' compliance (148..149), the machine (150..160).
  PKM_FMI_MECHANISM_PARAMETERS,
  real_parameter(130, "x0", 0.0, "m", "Initial x of P", PLANT(pose0), 0, -pkm::kMaxLength, pkm::kMaxLength),
  real_parameter(131, "y0", 0.0, "m", "Initial y of P", PLANT(pose0), 1, -pkm::kMaxLength, pkm::kMaxLength),
  real_parameter(132, "z0", 0.05, "m", "Initial z of P (home pose: 0.05 m)", PLANT(pose0), 2, -pkm::kMaxLength, pkm::kMaxLength),
  real_parameter(133, "phi0", 0.0, "rad", "Initial platform rotation about z", PLANT(pose0), 3, -pkm::kMaxAngle, pkm::kMaxAngle),
  real_parameter(134, "dx0", 0.0, "m/s", "Initial velocity of P, x component", PLANT(vel0), 0, -pkm::kMaxSpeed, pkm::kMaxSpeed),
  real_parameter(135, "dy0", 0.0, "m/s", "Initial velocity of P, y component", PLANT(vel0), 1, -pkm::kMaxSpeed, pkm::kMaxSpeed),
  real_parameter(136, "dz0", 0.0, "m/s", "Initial velocity of P, z component", PLANT(vel0), 2, -pkm::kMaxSpeed, pkm::kMaxSpeed),
  real_parameter(137, "dphi0", 0.0, "rad/s", "Initial platform angular velocity about z", PLANT(vel0), 3, -pkm::kMaxSpeed / pkm::kConditionLength, pkm::kMaxSpeed / pkm::kConditionLength),
  integer_parameter(140, "solver", static_cast<int>(kDefaultSolver.solver),
                    "Co-Simulation integrator: 0 = CVODE (variable step, rtol and atol), 1 = fixed-step RK4 (rk4_step), as in the paper",
                    PLANT_SCALAR(solver), 0, 1),
  real_parameter(141, "rk4_step", kDefaultSolver.rk4_step, "s",
                 "RK4 step: a communication step is split into whole steps no longer than this", PLANT_SCALAR(rk4_step), 0,
                 pkm::kMinRk4Step, pkm::kMaxRk4Step),
  real_parameter(142, "rtol", kDefaultSolver.rtol, "", "CVODE relative tolerance", PLANT_SCALAR(rtol), 0, 0.0, 1.0),
  real_parameter(143, "atol", kDefaultSolver.atol, "", "CVODE absolute tolerance (on the pose, m and rad, the velocity, and the energy integrals, J)", PLANT_SCALAR(atol), 0, 0.0, 1.0),
  integer_parameter(144, "cvode_method", static_cast<int>(kDefaultSolver.cvode_method),
                    "CVODE method: 0 = Adams-Moulton (non-stiff), 1 = BDF", PLANT_SCALAR(cvode_method), 0, 1),
  integer_parameter(145, "formulation", static_cast<int>(kDefaultSolver.formulation),
                    "Forward dynamics: 0 = augmented saddle-point system (Eq. 12), 1 = null-space projection with a QR "
                    "(Eq. 13), 2 = null space from the leg blocks (Eq. 13, leg-partitioned)",
                    PLANT_SCALAR(formulation), 0, 2),
  PKM_FMI_GUARD_PARAMETERS,
  mechanism_parameter(148, "stop_stiffness", "N/m",
                 "Stiffness k of the compliant end stops: k delta + d delta_dot pushes a slider back past rho_min or rho_max by delta (never pulls)",
                 PKM_FMI_PARAM(stop_stiffness), 0),
  mechanism_parameter(149, "stop_damping", "N.s/m", "Damping d of the end stops",
                 PKM_FMI_PARAM(stop_damping), 0),
  PKM_FMI_MACHINE_PARAMETERS,
};
// clang-format on

#undef PLANT
#undef PLANT_SCALAR

static_assert(sorted_by_vr(kVariables, std::size(kVariables)), "the table must be sorted by value reference");

std::unique_ptr<ModelData> create() { return std::make_unique<PlantData>(); }

const ModelDefinition kDefinition{
    "PKM4PUU",
    "4-PUU Schoenflies-motion parallel robot: forward dynamics (the plant)",
    "<p>Forward dynamics of the 4-PUU parallel kinematics machine with three translations and one rotation "
    "(3T1R) of M. Ruggiu, P. Rea and E. Ottaviano, <i>Dynamic model of a 3T1R parallel kinematics machine</i>: "
    "Lagrange equations in 16 redundant coordinates with 12 loop-closure constraints (Eq. 1), integrated on "
    "the platform pose and velocity (4 degrees of freedom). Inputs are the four actuator forces and an external "
    "wrench on the platform; outputs are the platform pose and velocity, the joint coordinates of the legs, the "
    "Lagrange multipliers, the constraint residual and the condition number of the actuator Jacobian. The legs "
    "work elbow-down (the platform hangs below the rods).</p>"
    "<p><b>Co-Simulation:</b> each communication step is integrated by CVODE (default; restarted at every step, "
    "so results depend only on the state and inputs at the step start) or by fixed-step RK4. With FMI 2.0 the "
    "inputs can be interpolated linearly within a step (fmi2SetRealInputDerivatives, order 1). A step that cannot "
    "be completed, or that ends near a leg singularity (min_leg_measure) or a parallel singularity "
    "(max_jacobian_condition), returns Discard with the last good state kept at the last successful time and "
    "terminated = true. <b>Model Exchange:</b> the continuous states are x, y, z, phi, dx, dy, dz, dphi; the legs "
    "are reconstructed from them in closed form, so the loop closures hold exactly whatever the importer's "
    "integrator does. The five event indicators are the singularity guards (1/cond - 1/max_jacobian_condition, "
    "and |cos theta2 sin theta2| - min_leg_measure per leg); crossing one ends the simulation with a logged "
    "reason. A pose that no leg can reach is refused by SetContinuousStates with Discard. FMU states can be "
    "saved, restored and serialised.</p>",
    kVariables,
    std::size(kVariables),
    /*n_states=*/kStates,
    /*n_position_states=*/4,
    /*n_event_indicators=*/kIndicators,
    /*can_interpolate_inputs=*/true,
    /*default_step=*/1e-3,
    /*default_stop=*/2.0,
    &create,
    /*provides_derivatives=*/true,
};

}  // namespace

const ModelDefinition& pkm4puu_definition() { return kDefinition; }

}  // namespace pkm_fmi
