// SPDX-License-Identifier: BSD-2-Clause
// The plant as FMI 2.0 Model Exchange, driven through the dlopen'd binary by
// an integrator of the test's own: classic RK4 at h = 1 ms with the auto-test's
// forces evaluated exactly at each stage time (in-process inverse dynamics,
// set through fmi2SetReal), as MODEL_SPEC "Auto-test" and the paper do.
// The in-process auto-test (pkm::run_autotest, RK4 at 1 ms) integrates the
// same ODE with the same method, so the two trajectories must agree to
// rounding (bound 1e-10 m and rad): a Model Exchange state,
// derivative or time handled differently from the core would show here.
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "apps/autotest.hpp"
#include "fmu_loader.hpp"
#include "test_support.hpp"

namespace {

using pkm_test::PlantFmu;

constexpr int kStates = 10;  // pose, velocity, actuator_work, dissipated_energy
using State = std::array<double, kStates>;

/// One Model Exchange instance at the home pose, in continuous-time mode.
struct MeInstance {
  PlantFmu fmu{"model exchange", false, fmi2ModelExchange};
  std::vector<fmi2ValueReference> force_vrs;

  MeInstance() {
    EXPECT_NE(fmu.c, nullptr) << fmu.log.dump();
    for (int i = 1; i <= 4; ++i) force_vrs.push_back(fmu.vr(pkm_test::force_name(i)));
  }
  void start() {
    ASSERT_EQ(fmu.setup(), fmi2OK) << fmu.log.dump();
    ASSERT_EQ(fmu.enter(), fmi2OK) << fmu.log.dump();
    ASSERT_EQ(fmu.exit(), fmi2OK) << fmu.log.dump();
    fmi2EventInfo info{};
    info.newDiscreteStatesNeeded = fmi2True;
    while (info.newDiscreteStatesNeeded == fmi2True && info.terminateSimulation == fmi2False)
      ASSERT_EQ(fmu.lib.fmi2NewDiscreteStates(fmu.c, &info), fmi2OK) << fmu.log.dump();
    ASSERT_EQ(info.terminateSimulation, fmi2False);
    ASSERT_EQ(fmu.lib.fmi2EnterContinuousTimeMode(fmu.c), fmi2OK) << fmu.log.dump();
  }
  State states() {
    State x{};
    EXPECT_EQ(fmu.lib.fmi2GetContinuousStates(fmu.c, x.data(), kStates), fmi2OK) << fmu.log.dump();
    return x;
  }
  /// dx/dt at (t, x) with the actuator forces F.
  State derivative(double t, const State& x, const pkm::Vec4& F) {
    State dx{};
    EXPECT_EQ(fmu.lib.fmi2SetTime(fmu.c, t), fmi2OK) << fmu.log.dump();
    EXPECT_EQ(fmu.lib.fmi2SetContinuousStates(fmu.c, x.data(), kStates), fmi2OK) << fmu.log.dump();
    EXPECT_EQ(fmu.lib.fmi2SetReal(fmu.c, force_vrs.data(), 4, F.data()), fmi2OK) << fmu.log.dump();
    EXPECT_EQ(fmu.lib.fmi2GetDerivatives(fmu.c, dx.data(), kStates), fmi2OK) << fmu.log.dump();
    return dx;
  }
};

State axpy(const State& x, double a, const State& k) {
  State y;
  for (int i = 0; i < kStates; ++i) y[i] = x[i] + a * k[i];
  return y;
}

TEST(ModelExchange, OwnRk4WithExactStageForcesMatchesTheInProcessAutoTest) {
  const pkm::Model model = pkm_test::default_model();
  pkm::AutotestOptions opt;
  opt.solver.solver = pkm::Solver::Rk4;
  opt.solver.rk4_step = 1e-3;
  opt.sample_dt = 1e-3;
  pkm::AutotestResult in_process;
  ASSERT_EQ(pkm::run_autotest(model, opt, in_process), pkm::Status::Ok) << in_process.error;
  ASSERT_EQ(in_process.samples.size(), 2001u);

  pkm::PathForces forces;
  forces.model = &model;
  forces.path = opt.path;
  const pkm::InputSignal signal = forces.signal();
  auto force_at = [&](double t) {
    pkm::Vec4 F;
    pkm::Wrench we;
    signal.eval(signal.user, t, F, we);
    EXPECT_EQ(forces.status, pkm::Status::Ok);
    EXPECT_TRUE(we.isZero()) << "the auto-test has no external wrench";
    return F;
  };

  MeInstance me;
  me.start();
  State x = me.states();
  const double energy_start = me.fmu.get("kinetic_energy") + me.fmu.get("potential_energy");
  const double h = opt.solver.rk4_step;
  double worst_position = 0.0, worst_angle = 0.0, min_indicator = INFINITY;
  for (std::size_t k = 1; k < in_process.samples.size(); ++k) {
    const double t = static_cast<double>(k - 1) * h;
    const State k1 = me.derivative(t, x, force_at(t));
    const State k2 = me.derivative(t + h / 2, axpy(x, h / 2, k1), force_at(t + h / 2));
    const State k3 = me.derivative(t + h / 2, axpy(x, h / 2, k2), force_at(t + h / 2));
    const State k4 = me.derivative(t + h, axpy(x, h, k3), force_at(t + h));
    for (int i = 0; i < kStates; ++i) x[i] += h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);

    // The step is accepted: time and states at its end, as an importer does.
    const double t_end = static_cast<double>(k) * h;
    ASSERT_EQ(me.fmu.lib.fmi2SetTime(me.fmu.c, t_end), fmi2OK);
    ASSERT_EQ(me.fmu.lib.fmi2SetContinuousStates(me.fmu.c, x.data(), kStates), fmi2OK) << me.fmu.log.dump();
    fmi2Boolean enter_event = fmi2True, terminate = fmi2True;
    ASSERT_EQ(me.fmu.lib.fmi2CompletedIntegratorStep(me.fmu.c, fmi2True, &enter_event, &terminate), fmi2OK);
    EXPECT_EQ(enter_event, fmi2False);
    EXPECT_EQ(terminate, fmi2False);
    std::vector<double> z(me.fmu.def.n_event_indicators);  // guards, then end stops
    ASSERT_EQ(me.fmu.lib.fmi2GetEventIndicators(me.fmu.c, z.data(), z.size()), fmi2OK);
    for (double zi : z) min_indicator = std::min(min_indicator, zi);

    const pkm::Pose& simulated = in_process.samples[k].simulated;
    for (int i = 0; i < 3; ++i) worst_position = std::max(worst_position, std::abs(x[i] - simulated[i]));
    worst_angle = std::max(worst_angle, std::abs(x[3] - simulated[3]));
  }
  std::printf("  Model Exchange + own RK4 vs in-process auto-test: %.2e m, %.2e rad (bound 1e-10); "
              "in-process vs the path: %.2e m, %.2e rad; smallest guard indicator %.3g\n",
              worst_position, worst_angle, in_process.max_position_error, in_process.max_angle_error, min_indicator);
  // The energy audit (the default machine: no friction, the stops never
  // touched): the work done equals the gain in kinetic plus potential energy.
  const double gain = me.fmu.get("kinetic_energy") + me.fmu.get("potential_energy") - energy_start;
  std::printf("  energy audit: actuator_work %.12f J, gain %.12f J, difference %.2e J (bound 1e-9)\n", x[8], gain,
              x[8] - gain);
  EXPECT_NEAR(x[8], gain, 1e-9);
  EXPECT_GT(gain, 0.1) << "the platform is lifted 2 cm: about 10.6 N x 0.02 m of work";
  EXPECT_EQ(x[9], 0.0) << "nothing dissipates in the default machine";
  EXPECT_LE(worst_position, 1e-10);
  EXPECT_LE(worst_angle, 1e-10);
  EXPECT_GT(min_indicator, 0.0) << "the auto-test stays inside both guards and the sliders' travel (MODEL_SPEC)";
  // Not trivially zero: the platform moved 2 cm and 4 degrees.
  EXPECT_NEAR(x[2], 0.07, 1e-7);
  EXPECT_NEAR(x[3], 4.0 * pkm_test::kPi / 180.0, 1e-7);
}

}  // namespace
