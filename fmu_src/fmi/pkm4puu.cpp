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
// reset to 0 whenever u is set) and restarts CVODE at the step start
// (Plant::advance with continuous = false): the result of a step depends
// only on the state and inputs at its start, so a restored FMU state
// continues bit-identically. After a step the inputs hold their
// extrapolated values u + du h, the inputs at the new time.
//
// Outputs are computed lazily, on the first get after anything changed:
// the accelerations, hence lambda, depend on the inputs at the current time.
#include <cmath>
#include <iterator>
#include <memory>

#include "constraints.hpp"
#include "mechanism_parameters.hpp"
#include "models.hpp"
#include "plant.hpp"

#ifndef PKM4PUU_GUID
#error "PKM4PUU_GUID must be defined (the build computes it from modelDescription/PKM4PUU.xml)"
#endif

namespace pkm_fmi {
namespace {

constexpr pkm::SolverSettings kDefaultSolver{};

struct PlantData final : MechanismData {
  // Parameters beyond the mechanism's: initial state and solver settings.
  double pose0[4] = {0.0, 0.0, 0.05, 0.0};
  double vel0[4] = {0.0, 0.0, 0.0, 0.0};
  fmi2Integer solver = static_cast<fmi2Integer>(kDefaultSolver.solver);
  double rk4_step = kDefaultSolver.rk4_step;
  double rtol = kDefaultSolver.rtol;
  double atol = kDefaultSolver.atol;
  fmi2Integer cvode_method = static_cast<fmi2Integer>(kDefaultSolver.cvode_method);
  fmi2Integer formulation = static_cast<fmi2Integer>(kDefaultSolver.formulation);
  double max_jacobian_condition = kDefaultSolver.max_jacobian_condition;
  double min_leg_measure = kDefaultSolver.min_leg_measure;
  // Inputs u = [F1..F4, Fe1..Fe3, Me_z] at the current time, and du/dt.
  double u[8] = {};
  double du[8] = {};
  // Outputs (computed by update_outputs).
  double pose[4] = {}, vel[4] = {};
  double rho[4] = {}, drho[4] = {}, theta1[4] = {}, theta2[4] = {};
  double lambda[12] = {};
  double residual = 0.0, condition = 0.0;
  // The simulated machine (nullptr before initialisation).
  std::unique_ptr<pkm::Plant> plant;

  void reset() override { plant.reset(); }
  fmi2Status exit_initialization(Context& ctx) override;
  fmi2Status do_step(Context& ctx, double t, double h, double& t_reached) override;
  fmi2Status update_outputs(Context& ctx) override;
  void save(StateWriter& w) const override;
  bool load(StateReader& r, Context& ctx) override;

  /// A Plant for the current parameters (not yet initialised).
  fmi2Status make_plant(Context& ctx, const char* function, std::unique_ptr<pkm::Plant>& out) const;
  /// make_plant, then the consistent initial state from x0..phi0, dx0..dphi0.
  fmi2Status build(Context& ctx, const char* function);
  pkm::LinearInputs inputs(double t0) const;
};

fmi2Status PlantData::make_plant(Context& ctx, const char* function, std::unique_ptr<pkm::Plant>& out) const {
  pkm::Model model;
  std::string why;
  if (pkm::make_model(params, model, &why) != pkm::Status::Ok) {
    ctx.log.error("%s: %s", function, why.c_str());
    return fmi2Error;
  }
  if (solver != 0 && solver != 1) {
    ctx.log.error("%s: parameter solver = %d must be 0 (CVODE) or 1 (RK4)", function, static_cast<int>(solver));
    return fmi2Error;
  }
  if (cvode_method != 0 && cvode_method != 1) {
    ctx.log.error("%s: parameter cvode_method = %d must be 0 (Adams) or 1 (BDF)", function,
                  static_cast<int>(cvode_method));
    return fmi2Error;
  }
  if (formulation < 0 || formulation > 2) {
    ctx.log.error("%s: parameter formulation = %d must be 0 (Eq. 12), 1 (Eq. 13, QR) or 2 (Eq. 13, leg-partitioned)",
                  function, static_cast<int>(formulation));
    return fmi2Error;
  }
  pkm::SolverSettings s;
  s.solver = static_cast<pkm::Solver>(solver);
  s.rk4_step = rk4_step;
  s.rtol = rtol;
  s.atol = atol;
  s.cvode_method = static_cast<pkm::CvodeMethod>(cvode_method);
  s.formulation = static_cast<pkm::Formulation>(formulation);
  s.max_jacobian_condition = max_jacobian_condition;
  s.min_leg_measure = min_leg_measure;
  auto plant_new = std::make_unique<pkm::Plant>(model);
  if (plant_new->set_solver(s, &why) != pkm::Status::Ok) {
    ctx.log.error("%s: parameter %s", function, why.c_str());
    return fmi2Error;
  }
  out = std::move(plant_new);
  return fmi2OK;
}

fmi2Status PlantData::build(Context& ctx, const char* function) {
  std::unique_ptr<pkm::Plant> p;
  const fmi2Status st = make_plant(ctx, function, p);
  if (st != fmi2OK) return st;
  const pkm::Pose pose_0(pose0[0], pose0[1], pose0[2], pose0[3]);
  const pkm::Pose vel_0(vel0[0], vel0[1], vel0[2], vel0[3]);
  const pkm::Status s = p->initialize(ctx.start_time, pose_0, vel_0);
  if (s != pkm::Status::Ok) {
    const char* what = s == pkm::Status::Unreachable ? "cannot be assembled elbow-down"
                       : s == pkm::Status::Singular  ? "lies beyond the singularity limits"
                                                     : "cannot be used";
    ctx.log.error("%s: the initial state x0 = %.9g m, y0 = %.9g m, z0 = %.9g m, phi0 = %.9g rad (velocity dx0 = %g, "
                  "dy0 = %g, dz0 = %g m/s, dphi0 = %g rad/s) %s: %s: %s",
                  function, pose0[0], pose0[1], pose0[2], pose0[3], vel0[0], vel0[1], vel0[2], vel0[3], what,
                  pkm::status_name(s), p->last_error().c_str());
    return fmi2Error;
  }
  plant = std::move(p);
  return fmi2OK;
}

pkm::LinearInputs PlantData::inputs(double t0) const {
  pkm::LinearInputs in;
  in.t0 = t0;
  in.F0 = pkm::Vec4(u[0], u[1], u[2], u[3]);
  in.dF = pkm::Vec4(du[0], du[1], du[2], du[3]);
  in.we0 = pkm::Wrench(u[4], u[5], u[6], u[7]);
  in.dwe = pkm::Wrench(du[4], du[5], du[6], du[7]);
  return in;
}

fmi2Status PlantData::exit_initialization(Context& ctx) { return build(ctx, "fmi2ExitInitializationMode"); }

fmi2Status PlantData::do_step(Context& ctx, double t, double h, double& t_reached) {
  if (!plant || !plant->initialized()) {
    ctx.log.error("fmi2DoStep: no state (initialisation did not succeed)");
    return fmi2Error;
  }
  const double t_start = plant->time();
  const double t_end = t + h;
  t_reached = t_start;
  pkm::LinearInputs in = inputs(t_start);
  const double span = t_end - t_start;
  if (!(in.F0 + in.dF * span).allFinite() || !(in.we0 + in.dwe * span).allFinite()) {
    ctx.log.error("fmi2DoStep: the inputs extrapolated with their derivatives to t = %.17g are not finite", t_end);
    return fmi2Error;
  }
  const pkm::Status s = plant->advance(t_end, in.signal(), /*continuous=*/false);
  t_reached = plant->time();
  // The inputs now refer to the time reached.
  if (t_reached != t_start)
    for (int k = 0; k < 8; ++k)
      if (du[k] != 0.0) u[k] += du[k] * (t_reached - t_start);
  switch (s) {
    case pkm::Status::Ok:
      return fmi2OK;
    case pkm::Status::SolverFailure:
    case pkm::Status::Unreachable:
    case pkm::Status::Singular:
    case pkm::Status::NotConverged:
      // The plant kept its last good state (RK4: last whole step; CVODE: the
      // step start), within the singularity limits. fmi2Terminated is set by
      // the generic layer: a master stops at fmi2LastSuccessfulTime instead
      // of retrying the same step.
      ctx.log.discard("fmi2DoStep: integration from t = %.17g to %.17g failed (%s%s%s); the state is kept at "
                      "t = %.17g (fmi2LastSuccessfulTime), fmi2Terminated = true",
                      t_start, t_end, pkm::status_name(s), plant->last_error().empty() ? "" : ": ",
                      plant->last_error().c_str(), t_reached);
      return fmi2Discard;
    default:
      ctx.log.error("fmi2DoStep: integration from t = %.17g to %.17g failed: %s%s%s", t_start, t_end,
                    pkm::status_name(s), plant->last_error().empty() ? "" : ": ", plant->last_error().c_str());
      return fmi2Error;
  }
}

fmi2Status PlantData::update_outputs(Context& ctx) {
  if (ctx.mode == kInitializationMode) {
    // Initial values for the parameters set so far.
    const fmi2Status st = build(ctx, "fmi2GetReal (initialization mode)");
    if (st != fmi2OK) return st;
  }
  if (!plant || !plant->initialized()) {
    ctx.log.error("fmi2GetReal: outputs not available (initialisation did not succeed)");
    return fmi2Error;
  }
  pkm::MechanismState ms;
  const pkm::Status s = plant->mechanism(inputs(plant->time()).signal(), ms);
  if (s != pkm::Status::Ok) {
    ctx.log.error("fmi2GetReal: the mechanism cannot be evaluated at t = %.17g: %s", plant->time(),
                  pkm::status_name(s));
    return fmi2Error;
  }
  const pkm::Vec8& y = plant->state();
  for (int i = 0; i < 4; ++i) {
    pose[i] = y[i];
    vel[i] = y[4 + i];
    const int o = pkm::leg_offset(i);
    rho[i] = ms.q[o];
    drho[i] = ms.qd[o];
    theta1[i] = ms.q[o + 1];
    theta2[i] = ms.q[o + 2];
  }
  for (int k = 0; k < 12; ++k) lambda[k] = ms.lambda[k];
  // From the q just evaluated: one closed-form expansion serves every output.
  residual = pkm::constraints(plant->model(), ms.q).norm();
  condition = pkm::actuator_jacobian_condition(plant->model(), ms.q);  // +inf at a singularity, never NaN
  bool finite = std::isfinite(residual) && !std::isnan(condition);
  for (const double* block : {pose, vel, rho, drho, theta1, theta2})
    for (int i = 0; i < 4; ++i) finite = finite && std::isfinite(block[i]);
  for (double v : lambda) finite = finite && std::isfinite(v);
  if (!finite) {
    ctx.log.error("fmi2GetReal: non-finite outputs at t = %.17g (singular configuration?)", plant->time());
    return fmi2Error;
  }
  return fmi2OK;
}

void PlantData::save(StateWriter& w) const {
  const bool has = plant && plant->initialized();
  w.u8(has ? 1 : 0);
  if (!has) return;
  w.f64(plant->time());
  w.f64s(plant->state().data(), plant->state().data() + 8);
  w.f64s(plant->theta1_ref().data(), plant->theta1_ref().data() + 4);
}

bool PlantData::load(StateReader& r, Context& ctx) {
  plant.reset();
  if (r.u8() == 0) return r.ok();
  const double t = r.f64();
  pkm::Vec8 y;
  pkm::Vec4 ref;
  r.f64s(y.data(), y.data() + 8);
  r.f64s(ref.data(), ref.data() + 4);
  if (!r.ok()) return false;
  std::unique_ptr<pkm::Plant> p;
  if (make_plant(ctx, "fmi2SetFMUstate", p) != fmi2OK) return false;
  const pkm::Status s = p->restore(t, y, ref);
  if (s != pkm::Status::Ok) {
    ctx.log.error("fmi2SetFMUstate: the saved state at t = %.17g cannot be restored: %s", t, pkm::status_name(s));
    return false;
  }
  plant = std::move(p);
  return true;
}

// ---------------------------------------------------------------- the table

#define PLANT(member) \
  [](ModelData& d, int i) -> void* { return &static_cast<PlantData&>(d).member[i]; }
#define PLANT_SCALAR(member) \
  [](ModelData& d, int) -> void* { return &static_cast<PlantData&>(d).member; }

// clang-format off
constexpr Variable kVariables[] = {
  // Inputs: 1..8.
  real_input(1, "F[1]", 0.0, "N", "Actuator force on the slider of leg 1, along +z", PLANT(u), 0, PLANT(du)),
  real_input(2, "F[2]", 0.0, "N", "Actuator force on the slider of leg 2, along +z", PLANT(u), 1, PLANT(du)),
  real_input(3, "F[3]", 0.0, "N", "Actuator force on the slider of leg 3, along +z", PLANT(u), 2, PLANT(du)),
  real_input(4, "F[4]", 0.0, "N", "Actuator force on the slider of leg 4, along +z", PLANT(u), 3, PLANT(du)),
  real_input(5, "Fe[1]", 0.0, "N", "External force on the platform at P, x component (base frame)", PLANT(u), 4, PLANT(du)),
  real_input(6, "Fe[2]", 0.0, "N", "External force on the platform at P, y component (base frame)", PLANT(u), 5, PLANT(du)),
  real_input(7, "Fe[3]", 0.0, "N", "External force on the platform at P, z component (base frame)", PLANT(u), 6, PLANT(du)),
  real_input(8, "Me_z", 0.0, "N.m", "External moment on the platform about z", PLANT(u), 7, PLANT(du)),
  // Outputs: 10..53.
  real_output(10, "x", "m", "Platform reference point P (centre of mass), x in the base frame", PLANT(pose), 0),
  real_output(11, "y", "m", "Platform reference point P (centre of mass), y in the base frame", PLANT(pose), 1),
  real_output(12, "z", "m", "Platform reference point P (centre of mass), z in the base frame", PLANT(pose), 2),
  real_output(13, "phi", "rad", "Platform rotation about z of the base frame", PLANT(pose), 3),
  real_output(14, "dx", "m/s", "Velocity of P, x component", PLANT(vel), 0),
  real_output(15, "dy", "m/s", "Velocity of P, y component", PLANT(vel), 1),
  real_output(16, "dz", "m/s", "Velocity of P, z component", PLANT(vel), 2),
  real_output(17, "dphi", "rad/s", "Platform angular velocity about z", PLANT(vel), 3),
  real_output(20, "rho[1]", "m", "Actuated prismatic joint of leg 1 (slider position)", PLANT(rho), 0),
  real_output(21, "rho[2]", "m", "Actuated prismatic joint of leg 2 (slider position)", PLANT(rho), 1),
  real_output(22, "rho[3]", "m", "Actuated prismatic joint of leg 3 (slider position)", PLANT(rho), 2),
  real_output(23, "rho[4]", "m", "Actuated prismatic joint of leg 4 (slider position)", PLANT(rho), 3),
  real_output(24, "drho[1]", "m/s", "Slider velocity of leg 1", PLANT(drho), 0),
  real_output(25, "drho[2]", "m/s", "Slider velocity of leg 2", PLANT(drho), 1),
  real_output(26, "drho[3]", "m/s", "Slider velocity of leg 3", PLANT(drho), 2),
  real_output(27, "drho[4]", "m/s", "Slider velocity of leg 4", PLANT(drho), 3),
  real_output(28, "theta1[1]", "rad", "First revolute joint of leg 1 (axis parallel to the prismatic axis), continuous", PLANT(theta1), 0),
  real_output(29, "theta1[2]", "rad", "First revolute joint of leg 2 (axis parallel to the prismatic axis), continuous", PLANT(theta1), 1),
  real_output(30, "theta1[3]", "rad", "First revolute joint of leg 3 (axis parallel to the prismatic axis), continuous", PLANT(theta1), 2),
  real_output(31, "theta1[4]", "rad", "First revolute joint of leg 4 (axis parallel to the prismatic axis), continuous", PLANT(theta1), 3),
  real_output(32, "theta2[1]", "rad", "Second revolute joint of leg 1 (horizontal axis), elbow-down: -pi/2 < theta2 < 0", PLANT(theta2), 0),
  real_output(33, "theta2[2]", "rad", "Second revolute joint of leg 2 (horizontal axis), elbow-down: -pi/2 < theta2 < 0", PLANT(theta2), 1),
  real_output(34, "theta2[3]", "rad", "Second revolute joint of leg 3 (horizontal axis), elbow-down: -pi/2 < theta2 < 0", PLANT(theta2), 2),
  real_output(35, "theta2[4]", "rad", "Second revolute joint of leg 4 (horizontal axis), elbow-down: -pi/2 < theta2 < 0", PLANT(theta2), 3),
  real_output(40, "lambda[1]", "N", "Lagrange multiplier of leg 1's loop closure, x row (Eq. 1)", PLANT(lambda), 0),
  real_output(41, "lambda[2]", "N", "Lagrange multiplier of leg 1's loop closure, y row (Eq. 1)", PLANT(lambda), 1),
  real_output(42, "lambda[3]", "N", "Lagrange multiplier of leg 1's loop closure, z row (Eq. 1)", PLANT(lambda), 2),
  real_output(43, "lambda[4]", "N", "Lagrange multiplier of leg 2's loop closure, x row (Eq. 1)", PLANT(lambda), 3),
  real_output(44, "lambda[5]", "N", "Lagrange multiplier of leg 2's loop closure, y row (Eq. 1)", PLANT(lambda), 4),
  real_output(45, "lambda[6]", "N", "Lagrange multiplier of leg 2's loop closure, z row (Eq. 1)", PLANT(lambda), 5),
  real_output(46, "lambda[7]", "N", "Lagrange multiplier of leg 3's loop closure, x row (Eq. 1)", PLANT(lambda), 6),
  real_output(47, "lambda[8]", "N", "Lagrange multiplier of leg 3's loop closure, y row (Eq. 1)", PLANT(lambda), 7),
  real_output(48, "lambda[9]", "N", "Lagrange multiplier of leg 3's loop closure, z row (Eq. 1)", PLANT(lambda), 8),
  real_output(49, "lambda[10]", "N", "Lagrange multiplier of leg 4's loop closure, x row (Eq. 1)", PLANT(lambda), 9),
  real_output(50, "lambda[11]", "N", "Lagrange multiplier of leg 4's loop closure, y row (Eq. 1)", PLANT(lambda), 10),
  real_output(51, "lambda[12]", "N", "Lagrange multiplier of leg 4's loop closure, z row (Eq. 1)", PLANT(lambda), 11),
  real_output(52, "constraint_residual", "m", "Norm of the loop closures ||C(q)|| (Eq. 15) at the current state", PLANT_SCALAR(residual), 0),
  real_output(53, "jacobian_condition", "", "Condition number of the 4x4 actuator Jacobian d(rho)/d(x, y, z, phi), its phi column divided by 0.1 m", PLANT_SCALAR(condition), 0),
  // Parameters: the mechanism (100..120), the initial state (130..137), the solver (140..145).
  PKM_FMI_MECHANISM_PARAMETERS,
  real_parameter(130, "x0", 0.0, "m", "Initial x of P", PLANT(pose0), 0),
  real_parameter(131, "y0", 0.0, "m", "Initial y of P", PLANT(pose0), 1),
  real_parameter(132, "z0", 0.05, "m", "Initial z of P (home pose: 0.05 m)", PLANT(pose0), 2),
  real_parameter(133, "phi0", 0.0, "rad", "Initial platform rotation about z", PLANT(pose0), 3),
  real_parameter(134, "dx0", 0.0, "m/s", "Initial velocity of P, x component", PLANT(vel0), 0),
  real_parameter(135, "dy0", 0.0, "m/s", "Initial velocity of P, y component", PLANT(vel0), 1),
  real_parameter(136, "dz0", 0.0, "m/s", "Initial velocity of P, z component", PLANT(vel0), 2),
  real_parameter(137, "dphi0", 0.0, "rad/s", "Initial platform angular velocity about z", PLANT(vel0), 3),
  integer_parameter(140, "solver", static_cast<int>(kDefaultSolver.solver),
                    "Integrator: 0 = CVODE (variable step, rtol and atol), 1 = fixed-step RK4 (rk4_step), as in the paper",
                    PLANT_SCALAR(solver)),
  real_parameter(141, "rk4_step", kDefaultSolver.rk4_step, "s",
                 "RK4 step: a communication step is split into whole steps no longer than this", PLANT_SCALAR(rk4_step), 0),
  real_parameter(142, "rtol", kDefaultSolver.rtol, "", "CVODE relative tolerance", PLANT_SCALAR(rtol), 0),
  real_parameter(143, "atol", kDefaultSolver.atol, "", "CVODE absolute tolerance (on the pose, m and rad, and velocity)", PLANT_SCALAR(atol), 0),
  integer_parameter(144, "cvode_method", static_cast<int>(kDefaultSolver.cvode_method),
                    "CVODE method: 0 = Adams-Moulton (non-stiff), 1 = BDF", PLANT_SCALAR(cvode_method)),
  integer_parameter(145, "formulation", static_cast<int>(kDefaultSolver.formulation),
                    "Forward dynamics: 0 = augmented saddle-point system (Eq. 12), 1 = null-space projection with a QR "
                    "(Eq. 13), 2 = null space from the leg blocks (Eq. 13, leg-partitioned)",
                    PLANT_SCALAR(formulation)),
  real_parameter(146, "max_jacobian_condition", kDefaultSolver.max_jacobian_condition, "",
                 "Parallel-singularity guard: a step whose end state has an actuator Jacobian condition number "
                 "(phi column divided by 0.1 m) above this is discarded (fmi2Discard, state kept); > 1",
                 PLANT_SCALAR(max_jacobian_condition), 0),
  real_parameter(147, "min_leg_measure", kDefaultSolver.min_leg_measure, "",
                 "Leg-singularity guard: a step whose end state has |cos(theta2) sin(theta2)| of a leg below this "
                 "(rod nearly horizontal or vertical) is discarded (fmi2Discard, state kept); in [0, 0.5)",
                 PLANT_SCALAR(min_leg_measure), 0),
};
// clang-format on

#undef PLANT
#undef PLANT_SCALAR

static_assert(sorted_by_vr(kVariables, std::size(kVariables)), "the table must be sorted by value reference");

std::unique_ptr<ModelData> create() { return std::make_unique<PlantData>(); }

const ModelDefinition kDefinition{
    "PKM4PUU",
    PKM4PUU_GUID,
    "4-PUU Schoenflies-motion parallel robot: forward dynamics (the plant)",
    "<p>Forward dynamics of the 4-PUU parallel kinematics machine with three translations and one rotation "
    "(3T1R) of M. Ruggiu, P. Rea and E. Ottaviano, <i>Dynamic model of a 3T1R parallel kinematics machine</i>: "
    "Lagrange equations in 16 redundant coordinates with 12 loop-closure constraints (Eq. 1), integrated on "
    "the platform pose and velocity (4 degrees of freedom). Inputs are the four actuator forces and an external "
    "wrench on the platform; outputs are the platform pose and velocity, the joint coordinates of the legs, the "
    "Lagrange multipliers, the constraint residual and the condition number of the actuator Jacobian. The legs "
    "work elbow-down (the platform hangs below the rods).</p>"
    "<p>Each communication step is integrated by CVODE (default; restarted at every step, so results depend only "
    "on the state and inputs at the step start) or by fixed-step RK4. The inputs can be interpolated linearly "
    "within a step (fmi2SetRealInputDerivatives, order 1). A step that cannot be completed, or that ends near a "
    "leg singularity (min_leg_measure) or a parallel singularity (max_jacobian_condition), returns fmi2Discard "
    "with the last good state kept at fmi2LastSuccessfulTime and fmi2Terminated = true. FMU states can be saved, "
    "restored and serialised.</p>",
    kVariables,
    std::size(kVariables),
    /*can_interpolate_inputs=*/true,
    &create,
};

}  // namespace

const ModelDefinition& pkm4puu_definition() { return kDefinition; }

}  // namespace pkm_fmi
