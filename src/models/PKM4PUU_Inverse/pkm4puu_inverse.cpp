// PKM4PUU_Inverse.fmu: inverse dynamics of the 4-PUU robot (computed-force
// feed-forward), over pkm::inverse_dynamics. An algebraic FMU: its outputs
// are functions of the inputs at the communication point (direct
// feedthrough), computed lazily on the first get after an input changed.
//
// Immutable: the table and ModelDefinition (shared), and pkm::Model built
// once per instance at the end of initialisation. Per instance
// (InverseData): parameter and input values and the output cache.
//
// The position problem starts from the closed-form elbow-down inverse
// kinematics every time (inverse_dynamics with warm_start = false), not
// from the previous solution: the closed form is already exact (Newton
// stops after 0 iterations), so this is faster than a warm start (about
// 3 us against 6 us per evaluation), cannot leave the elbow-down branch
// after a jump of the inputs, and makes the outputs a pure function of the
// current inputs and parameters (bit for bit, whatever was computed
// before; nothing to carry in FMU states).
//
// The plant's singularity guards (workspace_guard.hpp, the same parameters
// max_jacobian_condition and min_leg_measure): near a leg or parallel
// singularity the forces grow without bound (1e19 N with a rod horizontal),
// numbers no drive should be handed. A pose beyond a guard makes the get
// answer Discard with the reason logged and the outputs of the last pose
// within the guards; the outputs jacobian_condition and leg_measure_min tell
// the master how close it is.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <iterator>
#include <memory>

#include "pkm4puu/kinematics/constraints.hpp"
#include "pkm4puu/dynamics/inverse_dynamics.hpp"
#include "pkm4puu/dynamics/inverse_dynamics_derivatives.hpp"
#include "models/common/mechanism_parameters.hpp"
#include "models/models.hpp"
#include "pkm4puu/kinematics/workspace_guard.hpp"

namespace pkm_fmi {
namespace {

struct InverseData final : MechanismData {
  // Inputs.
  double pose[4] = {0.0, 0.0, 0.05, 0.0};  // x, y, z, phi
  double vel[4] = {}, acc[4] = {};
  double wrench[4] = {};  // Fe1..Fe3, Me_z
  // Outputs.
  double F[4] = {}, tau[4] = {}, rho[4] = {}, drho[4] = {}, lambda[12] = {};
  double condition = 0.0, leg_measure_min = 0.0;
  // Joints beyond their end stops at the last evaluation (bit i: below
  // rho_min, 4 + i: above rho_max): a warning is given on entering, once.
  unsigned beyond_stops = 0;
  // Built at the end of initialisation.
  std::unique_ptr<pkm::Model> model;

  void reset() override { model.reset(); }
  Status exit_initialization(Context& ctx) override;
  Status do_step(Context&, double t, double h, double& t_reached) override {
    t_reached = t + h;  // no dynamics: the outputs follow the inputs
    return Status::OK;
  }
  Status update_outputs(Context& ctx, unsigned groups) override;
  void save(StateWriter& w) const override;
  bool load(StateReader& r, Context& ctx) override;

  Status partial_derivatives(Context& ctx, const Variable* const unknowns[], std::size_t nu,
                             const Variable* const knowns[], std::size_t nk, double J[]) override;

  Status make(Context& ctx, const char* function, pkm::Model& out) const;
  /// The model to evaluate with: the instance's, or in initialisation mode
  /// one made into `temporary` from the current parameters; nullptr (logged)
  /// if there is none.
  const pkm::Model* current_model(Context& ctx, const char* function, pkm::Model& temporary) const;
};

Status InverseData::make(Context& ctx, const char* function, pkm::Model& out) const {
  std::string why;
  if (pkm::make_model(params, out, &why) != pkm::Status::Ok) {
    ctx.log.error("%s: %s", function, why.c_str());
    return Status::Error;
  }
  why = pkm::validate(limits);
  if (!why.empty()) {
    ctx.log.error("%s: parameter %s", function, why.c_str());
    return Status::Error;
  }
  return Status::OK;
}

Status InverseData::exit_initialization(Context& ctx) {
  auto m = std::make_unique<pkm::Model>();
  const Status st = make(ctx, "ExitInitializationMode", *m);
  if (st != Status::OK) return st;
  model = std::move(m);
  return Status::OK;
}

const pkm::Model* InverseData::current_model(Context& ctx, const char* function, pkm::Model& temporary) const {
  if (ctx.initialization_mode) return make(ctx, function, temporary) == Status::OK ? &temporary : nullptr;
  if (!model) ctx.log.error("%s: outputs not available (initialisation did not succeed)", function);
  return model.get();
}

Status InverseData::update_outputs(Context& ctx, unsigned) {  // one group: everything
  pkm::Model temporary;
  const pkm::Model* m = current_model(ctx, "get", temporary);
  if (!m) return Status::Error;
  const pkm::Pose p(pose[0], pose[1], pose[2], pose[3]);
  const pkm::Pose pd(vel[0], vel[1], vel[2], vel[3]);
  const pkm::Pose pdd(acc[0], acc[1], acc[2], acc[3]);
  const pkm::Wrench we(wrench[0], wrench[1], wrench[2], wrench[3]);
  pkm::GuardReport guard;
  if (pkm::check_configuration(*m, p, limits, &guard) == pkm::Status::Singular) {
    ctx.log.discard("get: the requested pose x = %.17g m, y = %.17g m, z = %.17g m, phi = %.17g rad is beyond a "
                    "singularity guard: %s; the outputs keep their values of the last pose within the guards",
                    pose[0], pose[1], pose[2], pose[3],
                    pkm::describe_configuration_failure(*m, p, limits, guard).c_str());
    return Status::Discard;
  }
  pkm::InverseDynamicsResult r;
  const pkm::Status s = pkm::inverse_dynamics(*m, p, pd, pdd, we, r, /*warm_start=*/false);
  if (s != pkm::Status::Ok) {
    ctx.log.error("get: inverse dynamics at x = %g m, y = %g m, z = %g m, phi = %g rad failed: %s "
                  "(outputs not written)",
                  pose[0], pose[1], pose[2], pose[3], pkm::status_name(s));
    return Status::Error;
  }
  for (int i = 0; i < 4; ++i) {
    const int o = pkm::leg_offset(i);
    F[i] = r.F[i];
    tau[i] = r.tau[i];
    rho[i] = r.q[o];
    drho[i] = r.qd[o];
  }
  for (int k = 0; k < 12; ++k) lambda[k] = r.lambda[k];
  condition = pkm::actuator_jacobian_condition(*m, r.q);
  leg_measure_min = 0.5;
  for (int i = 0; i < 4; ++i) {
    const double t2 = r.q[pkm::leg_offset(i) + 2];
    leg_measure_min = std::min(leg_measure_min, std::fabs(std::cos(t2) * std::sin(t2)));
  }
  const unsigned entered = r.beyond_stops & ~beyond_stops;
  beyond_stops = r.beyond_stops;
  if (entered == 0) return Status::OK;
  for (int k = 0; k < 8; ++k) {
    if (!(entered & (1u << k))) continue;
    const bool lower = k < 4;
    ctx.log.warning("get: the requested pose x = %g m, y = %g m, z = %g m, phi = %g rad puts slider %d at rho = %.9g m, "
                    "%s its %s end stop %s = %.9g m: the forces include the stop's reaction, a real machine would not "
                    "follow",
                    pose[0], pose[1], pose[2], pose[3], k % 4 + 1, rho[k % 4], lower ? "below" : "above",
                    lower ? "lower" : "upper", lower ? "rho_min" : "rho_max",
                    lower ? m->p.rho_min : m->p.rho_max);
  }
  return Status::Warning;
}

// Analytic (inverse_dynamics_derivatives.hpp): F, tau, rho and drho with
// respect to the inputs; the multipliers are refused with Error (not
// differentiated yet).
Status InverseData::partial_derivatives(Context& ctx, const Variable* const unknowns[], std::size_t nu,
                                        const Variable* const knowns[], std::size_t nk, double J[]) {
  const char* fn = "GetDirectionalDerivative";
  pkm::Model temporary;
  const pkm::Model* m = current_model(ctx, fn, temporary);
  if (!m) return Status::Error;
  pkm::InverseDynamicsPartials d;
  const pkm::Status s = pkm::inverse_dynamics_derivatives(*m, pkm::Pose(pose), pkm::Pose(vel), pkm::Pose(acc),
                                                          pkm::Wrench(wrench), d);
  if (s != pkm::Status::Ok) {
    ctx.log.error("%s: the derivatives at x = %g m, y = %g m, z = %g m, phi = %g rad cannot be evaluated: %s", fn,
                  pose[0], pose[1], pose[2], pose[3], pkm::status_name(s));
    return Status::Error;
  }
  // One row over the 16 inputs (value references 1..16: pose, rates, accelerations, wrench) per unknown.
  Eigen::Matrix<double, 1, 16> row;
  for (std::size_t i = 0; i < nu; ++i) {
    const Variable& v = *unknowns[i];
    row.setZero();
    if (std::strncmp(v.name, "F[", 2) == 0 || std::strncmp(v.name, "tau[", 4) == 0) {
      const double scale = v.name[0] == 'F' ? 1.0 : 1.0 / m->drive_ratio;  // tau = F p / (2 pi)
      row << d.dp.row(v.index), d.dpd.row(v.index), d.dpdd.row(v.index), d.dwe.row(v.index);
      row *= scale;
    } else if (std::strncmp(v.name, "rho[", 4) == 0) {
      row.head<4>() = d.J_rho.row(v.index);
    } else if (std::strncmp(v.name, "drho[", 5) == 0) {
      row.head<4>() = d.drhod_dp.row(v.index);
      row.segment<4>(4) = d.J_rho.row(v.index);
    } else {
      ctx.log.error("%s: the partial derivatives of %s are not provided (analytic so far: F, tau, rho and drho)", fn,
                    v.name);
      return Status::Error;
    }
    for (std::size_t j = 0; j < nk; ++j) J[i * nk + j] = row[static_cast<int>(knowns[j]->vr) - 1];
  }
  return Status::OK;
}

void InverseData::save(StateWriter& w) const { w.u8(model ? 1 : 0); }

bool InverseData::load(StateReader& r, Context& ctx) {
  const bool has_model = r.u8() != 0;
  if (!r.ok()) return false;
  model.reset();
  if (has_model) {
    auto m = std::make_unique<pkm::Model>();
    if (make(ctx, "SetFMUState", *m) != Status::OK) return false;
    model = std::move(m);
  }
  return true;
}

// ---------------------------------------------------------------- the table

#define INV(member) \
  [](ModelData& d, int i) -> void* { return &static_cast<InverseData&>(d).member[i]; }
#define INV_SCALAR(member) [](ModelData& d, int) -> void* { return &static_cast<InverseData&>(d).member; }

// The multipliers: invariant to a vertical translation. The forces follow z
// too, through the end stops (beyond them), and dz through the joints'
// friction and the stops' damping (which act on the sliders only, so the
// multipliers do not see them).
constexpr std::uint8_t kMultipliers = kOnPositions | kOnRates | kOnInputs;
constexpr std::uint8_t kForces = kMultipliers | kOnHeight | kOnHeightRate;

// clang-format off
constexpr Variable kVariables[] = {
  time_variable(0),
  // Inputs: 1..16.
  real_input(1, "x", 0.0, "m", "Platform reference point P (centre of mass), x in the base frame", INV(pose), 0, nullptr, kOnPositions),
  real_input(2, "y", 0.0, "m", "Platform reference point P (centre of mass), y in the base frame", INV(pose), 1, nullptr, kOnPositions),
  real_input(3, "z", 0.05, "m", "Platform reference point P (centre of mass), z in the base frame (home pose: 0.05 m)", INV(pose), 2, nullptr, kOnHeight),
  real_input(4, "phi", 0.0, "rad", "Platform rotation about z of the base frame", INV(pose), 3, nullptr, kOnPositions),
  real_input(5, "dx", 0.0, "m/s", "Velocity of P, x component", INV(vel), 0, nullptr, kOnRates),
  real_input(6, "dy", 0.0, "m/s", "Velocity of P, y component", INV(vel), 1, nullptr, kOnRates),
  real_input(7, "dz", 0.0, "m/s", "Velocity of P, z component", INV(vel), 2, nullptr, kOnHeightRate),
  real_input(8, "dphi", 0.0, "rad/s", "Platform angular velocity about z", INV(vel), 3, nullptr, kOnRates),
  real_input(9, "ddx", 0.0, "m/s2", "Acceleration of P, x component", INV(acc), 0, nullptr),
  real_input(10, "ddy", 0.0, "m/s2", "Acceleration of P, y component", INV(acc), 1, nullptr),
  real_input(11, "ddz", 0.0, "m/s2", "Acceleration of P, z component", INV(acc), 2, nullptr),
  real_input(12, "ddphi", 0.0, "rad/s2", "Platform angular acceleration about z", INV(acc), 3, nullptr),
  real_input(13, "Fe[1]", 0.0, "N", "External force on the platform at P, x component (base frame)", INV(wrench), 0, nullptr),
  real_input(14, "Fe[2]", 0.0, "N", "External force on the platform at P, y component (base frame)", INV(wrench), 1, nullptr),
  real_input(15, "Fe[3]", 0.0, "N", "External force on the platform at P, z component (base frame)", INV(wrench), 2, nullptr),
  real_input(16, "Me_z", 0.0, "N.m", "External moment on the platform about z", INV(wrench), 3, nullptr),
  // Outputs: 20..51.
  real_output(20, "F[1]", "N", "Actuator force on the slider of leg 1, along +z (Eq. 11)", INV(F), 0, kForces),
  real_output(21, "F[2]", "N", "Actuator force on the slider of leg 2, along +z (Eq. 11)", INV(F), 1, kForces),
  real_output(22, "F[3]", "N", "Actuator force on the slider of leg 3, along +z (Eq. 11)", INV(F), 2, kForces),
  real_output(23, "F[4]", "N", "Actuator force on the slider of leg 4, along +z (Eq. 11)", INV(F), 3, kForces),
  real_output(24, "rho[1]", "m", "Actuated prismatic joint of leg 1 (slider position)", INV(rho), 0, kOnPositions | kOnHeight),
  real_output(25, "rho[2]", "m", "Actuated prismatic joint of leg 2 (slider position)", INV(rho), 1, kOnPositions | kOnHeight),
  real_output(26, "rho[3]", "m", "Actuated prismatic joint of leg 3 (slider position)", INV(rho), 2, kOnPositions | kOnHeight),
  real_output(27, "rho[4]", "m", "Actuated prismatic joint of leg 4 (slider position)", INV(rho), 3, kOnPositions | kOnHeight),
  real_output(28, "drho[1]", "m/s", "Slider velocity of leg 1", INV(drho), 0, kOnPositions | kOnRates | kOnHeightRate),
  real_output(29, "drho[2]", "m/s", "Slider velocity of leg 2", INV(drho), 1, kOnPositions | kOnRates | kOnHeightRate),
  real_output(30, "drho[3]", "m/s", "Slider velocity of leg 3", INV(drho), 2, kOnPositions | kOnRates | kOnHeightRate),
  real_output(31, "drho[4]", "m/s", "Slider velocity of leg 4", INV(drho), 3, kOnPositions | kOnRates | kOnHeightRate),
  real_output(32, "tau[1]", "N.m", "Equivalent motor torque of leg 1, F[1] screw_lead/(2 pi)", INV(tau), 0, kForces),
  real_output(33, "tau[2]", "N.m", "Equivalent motor torque of leg 2", INV(tau), 1, kForces),
  real_output(34, "tau[3]", "N.m", "Equivalent motor torque of leg 3", INV(tau), 2, kForces),
  real_output(35, "tau[4]", "N.m", "Equivalent motor torque of leg 4", INV(tau), 3, kForces),
  real_output(40, "lambda[1]", "N", "Lagrange multiplier of leg 1's loop closure, x row (Eq. 10)", INV(lambda), 0, kMultipliers),
  real_output(41, "lambda[2]", "N", "Lagrange multiplier of leg 1's loop closure, y row (Eq. 10)", INV(lambda), 1, kMultipliers),
  real_output(42, "lambda[3]", "N", "Lagrange multiplier of leg 1's loop closure, z row (Eq. 10)", INV(lambda), 2, kMultipliers),
  real_output(43, "lambda[4]", "N", "Lagrange multiplier of leg 2's loop closure, x row (Eq. 10)", INV(lambda), 3, kMultipliers),
  real_output(44, "lambda[5]", "N", "Lagrange multiplier of leg 2's loop closure, y row (Eq. 10)", INV(lambda), 4, kMultipliers),
  real_output(45, "lambda[6]", "N", "Lagrange multiplier of leg 2's loop closure, z row (Eq. 10)", INV(lambda), 5, kMultipliers),
  real_output(46, "lambda[7]", "N", "Lagrange multiplier of leg 3's loop closure, x row (Eq. 10)", INV(lambda), 6, kMultipliers),
  real_output(47, "lambda[8]", "N", "Lagrange multiplier of leg 3's loop closure, y row (Eq. 10)", INV(lambda), 7, kMultipliers),
  real_output(48, "lambda[9]", "N", "Lagrange multiplier of leg 3's loop closure, z row (Eq. 10)", INV(lambda), 8, kMultipliers),
  real_output(49, "lambda[10]", "N", "Lagrange multiplier of leg 4's loop closure, x row (Eq. 10)", INV(lambda), 9, kMultipliers),
  real_output(50, "lambda[11]", "N", "Lagrange multiplier of leg 4's loop closure, y row (Eq. 10)", INV(lambda), 10, kMultipliers),
  real_output(51, "lambda[12]", "N", "Lagrange multiplier of leg 4's loop closure, z row (Eq. 10)", INV(lambda), 11, kMultipliers),
  real_output(52, "leg_measure_min", "", "Smallest |cos(theta2) sin(theta2)| of the four legs (0 at a leg singularity; the guard min_leg_measure)", INV_SCALAR(leg_measure_min), 0, kOnPositions),
  real_output(53, "jacobian_condition", "", "Condition number of the 4x4 actuator Jacobian d(rho)/d(x, y, z, phi), its phi column divided by 0.1 m (the guard max_jacobian_condition)", INV_SCALAR(condition), 0, kOnPositions),
  // Parameters: the mechanism (100..120), the guards (146..147), the machine (150..160).
  PKM_FMI_MECHANISM_PARAMETERS,
  PKM_FMI_GUARD_PARAMETERS,
  PKM_FMI_MACHINE_PARAMETERS,
};
// clang-format on

#undef INV
#undef INV_SCALAR

static_assert(sorted_by_vr(kVariables, std::size(kVariables)), "the table must be sorted by value reference");
static_assert(kVariables[1].vr == 1 && kVariables[16].vr == 16 && kVariables[17].vr == 20,
              "partial_derivatives: the inputs are value references 1..16, in the order of their row");

std::unique_ptr<ModelData> create() { return std::make_unique<InverseData>(); }

const ModelDefinition kDefinition{
    "PKM4PUU_Inverse",
    "4-PUU Schoenflies-motion parallel robot: inverse dynamics (computed-force feed-forward)",
    "<p>Inverse dynamics of the 4-PUU parallel kinematics machine with three translations and one rotation "
    "(3T1R) of M. Ruggiu, P. Rea and E. Ottaviano, <i>Dynamic model of a 3T1R parallel kinematics machine</i>. "
    "Given the platform pose, velocity and acceleration and an external wrench, it solves the position, "
    "velocity and acceleration problems of the legs (Eqs. 2-9, elbow-down) and then Eqs. 10-11 for the "
    "Lagrange multipliers and the four actuator forces. The outputs are algebraic functions of the inputs at "
    "the current time (direct feedthrough): in Co-Simulation a step only advances time; in Model Exchange it has "
    "no states and no event indicators.</p>"
    "<p>An unreachable pose makes the get of an output return Error with a message; no output is written "
    "then. A pose beyond a singularity guard (min_leg_measure, max_jacobian_condition, as in the plant) makes "
    "it return Discard with the reason logged and the outputs of the last pose within the guards. At rest at the home pose (0, 0, 0.05 m, 0) with g = 9.81 m/s2 each actuator carries "
    "2.655616050 N.</p>",
    kVariables,
    std::size(kVariables),
    /*n_states=*/0,
    /*n_position_states=*/0,
    /*n_event_indicators=*/0,
    /*can_interpolate_inputs=*/false,
    /*default_step=*/1e-3,
    /*default_stop=*/2.0,
    &create,
    /*provides_derivatives=*/true,
};

}  // namespace

const ModelDefinition& pkm4puu_inverse_definition() { return kDefinition; }

}  // namespace pkm_fmi
