// SPDX-License-Identifier: BSD-2-Clause
// Directional and adjoint derivatives of the plant FMU, through the dlopen'd
// binary: in Model Exchange the derivatives and outputs with respect to the
// states and inputs against Richardson-extrapolated central differences of
// the same FMU (fmi2SetContinuousStates / fmi2SetReal, then
// fmi2GetDerivatives / fmi2GetReal), every machine term on; FMI 3.0's
// directional and adjoint derivatives against FMI 2.0's; in Co-Simulation
// the outputs with respect to the inputs at the current instant; and the
// refusals (an unknown not differentiated yet, a known that is not one).
#include <dlfcn.h>

#include <vector>

#include "fmi3FunctionTypes.h"
#include "fmu_loader.hpp"
#include "test_support.hpp"

namespace {

using pkm_test::PlantFmu;

constexpr int kStates = 10;

// Every machine term on (names of the FMU's parameters, docs/model.md).
const std::pair<const char*, double> kMachine[] = {
    {"rotor_inertia", 2e-7},    {"friction_viscous", 1.5}, {"friction_coulomb", 0.2},
    {"friction_velocity", 0.05}, {"payload_mass", 0.3},     {"payload_com[1]", 0.02},
    {"payload_com[2]", -0.012}, {"payload_Izz", 1.2e-4},
};
// The state (off-centre, rotated, moving) and inputs of the comparison.
const double kState[kStates] = {0.004, -0.003, 0.06, 0.05, 0.1, -0.05, 0.08, 0.7, 0.0, 0.0};
const std::pair<const char*, double> kInputs[] = {
    {"F[1]", 2.7}, {"F[2]", 2.5},  {"F[3]", 2.9},    {"F[4]", 2.6},   {"Fe[1]", 0.3},  {"Fe[2]", -0.2},
    {"Fe[3]", 0.5}, {"Me_z", 0.01}, {"tau[1]", 1e-3}, {"tau[2]", -2e-3}, {"tau[3]", 1.5e-3}, {"tau[4]", 0.0},
};

std::vector<fmi2ValueReference> vrs(const PlantFmu& f, std::initializer_list<const char*> names) {
  std::vector<fmi2ValueReference> v;
  for (const char* n : names) v.push_back(f.vr(n));
  return v;
}

/// A Model Exchange instance in continuous-time mode at kState with kInputs.
struct MeFmu {
  PlantFmu fmu{"derivatives", false, fmi2ModelExchange};
  MeFmu() {
    EXPECT_EQ(fmu.setup(), fmi2OK);
    for (const auto& p : kMachine) EXPECT_EQ(fmu.set(p.first, p.second), fmi2OK) << p.first;
    EXPECT_EQ(fmu.enter(), fmi2OK);
    EXPECT_EQ(fmu.exit(), fmi2OK) << fmu.log.dump();
    fmi2EventInfo info{};
    EXPECT_EQ(fmu.lib.fmi2NewDiscreteStates(fmu.c, &info), fmi2OK);
    EXPECT_EQ(fmu.lib.fmi2EnterContinuousTimeMode(fmu.c), fmi2OK);
    EXPECT_EQ(fmu.lib.fmi2SetContinuousStates(fmu.c, kState, kStates), fmi2OK) << fmu.log.dump();
    for (const auto& u : kInputs) EXPECT_EQ(fmu.set(u.first, u.second), fmi2OK);
  }
};

// The unknowns this FMU differentiates and the knowns of Model Exchange.
const std::initializer_list<const char*> kUnknowns = {
    "der(x)", "der(y)", "der(z)", "der(phi)", "der(dx)", "der(dy)", "der(dz)", "der(dphi)", "der(actuator_work)",
    "der(dissipated_energy)", "x", "dphi", "rho[1]", "rho[2]", "rho[3]", "rho[4]", "drho[1]", "drho[2]", "drho[3]", "drho[4]"};
const std::initializer_list<const char*> kKnowns = {
    "x", "y", "z", "phi", "dx", "dy", "dz", "dphi", "F[1]", "F[2]", "F[3]", "F[4]",
    "Fe[1]", "Fe[2]", "Fe[3]", "Me_z", "tau[1]", "tau[2]", "tau[3]", "tau[4]"};

/// The Jacobian by fmi2GetDirectionalDerivative, one unit seed per known.
Eigen::MatrixXd fmi2_jacobian(pkm_test::FmuInstance& f, const std::vector<fmi2ValueReference>& u,
                              const std::vector<fmi2ValueReference>& k) {
  Eigen::MatrixXd J(u.size(), k.size());
  std::vector<double> seed(k.size()), out(u.size());
  for (std::size_t j = 0; j < k.size(); ++j) {
    std::fill(seed.begin(), seed.end(), 0.0);
    seed[j] = 1.0;
    EXPECT_EQ(f.lib.fmi2GetDirectionalDerivative(f.c, u.data(), u.size(), k.data(), k.size(), seed.data(), out.data()),
              fmi2OK)
        << f.log.dump();
    for (std::size_t i = 0; i < u.size(); ++i) J(i, j) = out[i];
  }
  return J;
}

}  // namespace

TEST(FmuDerivatives, ModelExchangeJacobianMatchesRichardsonDifferencesOfTheFmu) {
  MeFmu me;
  PlantFmu& f = me.fmu;
  const std::vector<fmi2ValueReference> u = vrs(f, kUnknowns), k = vrs(f, kKnowns);
  const Eigen::MatrixXd an = fmi2_jacobian(f, u, k);

  // The unknowns as the FMU computes them: der(...) from fmi2GetDerivatives
  // (table order: the states' derivatives), the outputs by fmi2GetReal.
  auto unknowns = [&]() {
    double dx[kStates];
    EXPECT_EQ(f.lib.fmi2GetDerivatives(f.c, dx, kStates), fmi2OK) << f.log.dump();
    const std::vector<fmi2ValueReference> outs(u.begin() + kStates, u.end());
    std::vector<double> o(outs.size());
    EXPECT_EQ(f.lib.fmi2GetReal(f.c, outs.data(), outs.size(), o.data()), fmi2OK) << f.log.dump();
    Eigen::VectorXd v(u.size());
    for (int i = 0; i < kStates; ++i) v[i] = dx[i];
    for (std::size_t i = 0; i < o.size(); ++i) v[kStates + i] = o[i];
    return v;
  };
  // Steps: pose 0.3 mm, 3 mrad; rates 5 mm/s, 50 mrad/s; forces 1 N; Me_z 0.01 N*m; tau 5 mN*m.
  const double h[20] = {3e-4, 3e-4, 3e-4, 3e-3, 5e-3, 5e-3, 5e-3, 5e-2, 1, 1, 1, 1, 1, 1, 1, 1e-2,
                        5e-3, 5e-3, 5e-3, 5e-3};
  Eigen::MatrixXd fd(u.size(), k.size());
  Eigen::VectorXd err(k.size());
  for (int j = 0; j < 20; ++j) {
    fd.col(j) = pkm_test::richardson([&](double s) {
      if (j < 8) {
        double x[kStates];
        std::copy(kState, kState + kStates, x);
        x[j] += s;
        EXPECT_EQ(f.lib.fmi2SetContinuousStates(f.c, x, kStates), fmi2OK);
      } else {
        EXPECT_EQ(f.set(kInputs[j - 8].first, kInputs[j - 8].second + s), fmi2OK);
      }
      const Eigen::VectorXd v = unknowns();
      EXPECT_EQ(f.lib.fmi2SetContinuousStates(f.c, kState, kStates), fmi2OK);
      if (j >= 8) {
        EXPECT_EQ(f.set(kInputs[j - 8].first, kInputs[j - 8].second), fmi2OK);
      }
      return v;
    }, h[j], &err[j]);
  }
  pkm_test::expect_columns_match("FMU d(der, outputs)/d(states, inputs)", an, fd, err, 1e-7);
}

TEST(FmuDerivatives, RepeatedCallsFollowEveryChangeOfStateAndInput) {
  // One evaluation serves every seed at the same point (plant_data.hpp's
  // JacobianCache); after a change of a state or an input the Jacobian must
  // be that of a fresh instance set to the new point directly.
  MeFmu me;
  PlantFmu& f = me.fmu;
  const std::vector<fmi2ValueReference> u = vrs(f, kUnknowns), k = vrs(f, kKnowns);
  const Eigen::MatrixXd J0 = fmi2_jacobian(f, u, k);
  EXPECT_EQ(fmi2_jacobian(f, u, k), J0) << "the same point, the same Jacobian";
  double x[kStates];
  std::copy(kState, kState + kStates, x);
  x[0] += 1e-3;  // 1 mm in x
  x[7] -= 0.2;   // and 0.2 rad/s in dphi
  ASSERT_EQ(f.lib.fmi2SetContinuousStates(f.c, x, kStates), fmi2OK);
  ASSERT_EQ(f.set("F[2]", 3.1), fmi2OK);
  const Eigen::MatrixXd J1 = fmi2_jacobian(f, u, k);
  MeFmu fresh;
  PlantFmu& g = fresh.fmu;
  ASSERT_EQ(g.lib.fmi2SetContinuousStates(g.c, x, kStates), fmi2OK);
  ASSERT_EQ(g.set("F[2]", 3.1), fmi2OK);
  EXPECT_EQ(J1, fmi2_jacobian(g, u, k));
  EXPECT_GT((J1 - J0).cwiseAbs().maxCoeff(), 0.0) << "the new point differs";
  // Back to the first state: the first Jacobian again, bit for bit.
  ASSERT_EQ(f.lib.fmi2SetContinuousStates(f.c, kState, kStates), fmi2OK);
  ASSERT_EQ(f.set("F[2]", 2.5), fmi2OK);
  EXPECT_EQ(fmi2_jacobian(f, u, k), J0);
}

TEST(FmuDerivatives, Fmi3DirectionalAndAdjointAgreeWithFmi2) {
  MeFmu me;
  PlantFmu& f = me.fmu;
  const std::vector<fmi2ValueReference> u = vrs(f, kUnknowns), k = vrs(f, kKnowns);
  const Eigen::MatrixXd J2 = fmi2_jacobian(f, u, k);

  // The same machine through FMI 3.0 (same binary, its fmi3 entry points).
  void* lib = f.lib.handle;
#define PKM_FN3(name) auto* name = reinterpret_cast<name##TYPE*>(dlsym(lib, #name)); ASSERT_NE(name, nullptr);
  PKM_FN3(fmi3InstantiateModelExchange) PKM_FN3(fmi3EnterInitializationMode) PKM_FN3(fmi3ExitInitializationMode)
  PKM_FN3(fmi3EnterContinuousTimeMode) PKM_FN3(fmi3SetFloat64) PKM_FN3(fmi3SetContinuousStates)
  PKM_FN3(fmi3GetDirectionalDerivative) PKM_FN3(fmi3GetAdjointDerivative) PKM_FN3(fmi3FreeInstance)
  PKM_FN3(fmi3UpdateDiscreteStates)
#undef PKM_FN3
  fmi3Instance c = fmi3InstantiateModelExchange("fmi3", PKM_FMU_PLANT_GUID, nullptr, fmi3False, fmi3False, nullptr,
                                                nullptr);
  ASSERT_NE(c, nullptr);
  for (const auto& p : kMachine) {
    const fmi3ValueReference r = f.vr(p.first);
    ASSERT_EQ(fmi3SetFloat64(c, &r, 1, &p.second, 1), fmi3OK) << p.first;
  }
  ASSERT_EQ(fmi3EnterInitializationMode(c, fmi3False, 0.0, 0.0, fmi3False, 0.0), fmi3OK);
  ASSERT_EQ(fmi3ExitInitializationMode(c), fmi3OK);
  fmi3Boolean b[5];
  fmi3Float64 next;
  ASSERT_EQ(fmi3UpdateDiscreteStates(c, &b[0], &b[1], &b[2], &b[3], &b[4], &next), fmi3OK);
  ASSERT_EQ(fmi3EnterContinuousTimeMode(c), fmi3OK);
  ASSERT_EQ(fmi3SetContinuousStates(c, kState, kStates), fmi3OK);
  for (const auto& in : kInputs) {
    const fmi3ValueReference r = f.vr(in.first);
    ASSERT_EQ(fmi3SetFloat64(c, &r, 1, &in.second, 1), fmi3OK);
  }
  Eigen::MatrixXd J3(u.size(), k.size()), J3adj(u.size(), k.size());
  std::vector<double> seed_k(k.size()), seed_u(u.size()), out_u(u.size()), out_k(k.size());
  for (std::size_t j = 0; j < k.size(); ++j) {
    std::fill(seed_k.begin(), seed_k.end(), 0.0);
    seed_k[j] = 1.0;
    ASSERT_EQ(fmi3GetDirectionalDerivative(c, u.data(), u.size(), k.data(), k.size(), seed_k.data(), k.size(),
                                           out_u.data(), u.size()),
              fmi3OK);
    for (std::size_t i = 0; i < u.size(); ++i) J3(i, j) = out_u[i];
  }
  for (std::size_t i = 0; i < u.size(); ++i) {
    std::fill(seed_u.begin(), seed_u.end(), 0.0);
    seed_u[i] = 1.0;
    ASSERT_EQ(fmi3GetAdjointDerivative(c, u.data(), u.size(), k.data(), k.size(), seed_u.data(), u.size(),
                                       out_k.data(), k.size()),
              fmi3OK);
    for (std::size_t j = 0; j < k.size(); ++j) J3adj(i, j) = out_k[j];
  }
  // A seed count that is not the knowns' is refused.
  EXPECT_EQ(fmi3GetDirectionalDerivative(c, u.data(), u.size(), k.data(), k.size(), seed_k.data(), k.size() - 1,
                                         out_u.data(), u.size()),
            fmi3Error);
  fmi3FreeInstance(c);
  EXPECT_EQ(J3, J2) << "one computation behind both versions";
  EXPECT_EQ(J3adj, J2) << "the adjoint applies the transpose of the same matrix";
}

TEST(FmuDerivatives, CoSimulationOutputsWithRespectToInputsAtTheCurrentInstant) {
  PlantFmu f("cs");
  f.initialize();
  ASSERT_EQ(f.step(0.0, 1e-3), fmi2OK);
  // The states and the sliders do not follow the inputs within an instant:
  // the ModelStructure says so, and the derivatives are exact zeros.
  const std::vector<fmi2ValueReference> u = vrs(f, {"x", "phi", "dz", "rho[2]", "drho[3]", "kinetic_energy"});
  const std::vector<fmi2ValueReference> k = vrs(f, {"F[1]", "Fe[2]", "Me_z", "tau[4]"});
  const double seed[4] = {1.0, -2.0, 0.5, 3.0};
  std::vector<double> out(u.size(), 99.0);
  ASSERT_EQ(f.lib.fmi2GetDirectionalDerivative(f.c, u.data(), u.size(), k.data(), k.size(), seed, out.data()), fmi2OK)
      << f.log.dump();
  for (double v : out) EXPECT_EQ(v, 0.0);
  // In Co-Simulation a state is not a known.
  const fmi2ValueReference x = f.vr("x");
  EXPECT_EQ(f.lib.fmi2GetDirectionalDerivative(f.c, &x, 1, &x, 1, seed, out.data()), fmi2Error);
  EXPECT_TRUE(f.log.contains("is not a known of this FMU")) << f.log.dump();
}

TEST(FmuDerivatives, AnUnknownNotDifferentiatedYetIsAnErrorThatNamesIt) {
  MeFmu me;
  PlantFmu& f = me.fmu;
  const fmi2ValueReference u[2] = {f.vr("der(dx)"), f.vr("lambda[1]")}, k = f.vr("F[1]");
  const double seed = 1.0;
  double out[2] = {99.0, 99.0};
  EXPECT_EQ(f.lib.fmi2GetDirectionalDerivative(f.c, u, 2, &k, 1, &seed, out), fmi2Error);
  EXPECT_TRUE(f.log.contains("lambda[1] are not provided")) << f.log.dump();
  EXPECT_EQ(out[0], 99.0) << "nothing written";
  // An input is not an unknown.
  EXPECT_EQ(f.lib.fmi2GetDirectionalDerivative(f.c, &k, 1, &k, 1, &seed, out), fmi2Error);
  EXPECT_TRUE(f.log.contains("is not an unknown of this FMU")) << f.log.dump();
}

TEST(FmuDerivatives, InverseFmuForcesMatchRichardsonDifferencesOfTheFmu) {
  pkm_test::InverseFmu f;
  ASSERT_EQ(f.setup(), fmi2OK);
  for (const auto& p : kMachine) ASSERT_EQ(f.set(p.first, p.second), fmi2OK) << p.first;
  const std::pair<const char*, double> inputs[16] = {
      {"x", 0.004}, {"y", -0.003}, {"z", 0.06}, {"phi", 0.05}, {"dx", 0.1}, {"dy", -0.05}, {"dz", 0.08},
      {"dphi", 0.7}, {"ddx", 0.8}, {"ddy", -0.5}, {"ddz", 1.1}, {"ddphi", 6.0}, {"Fe[1]", 0.3}, {"Fe[2]", -0.2},
      {"Fe[3]", 0.5}, {"Me_z", 0.01}};
  for (const auto& in : inputs) ASSERT_EQ(f.set(in.first, in.second), fmi2OK);
  ASSERT_EQ(f.enter(), fmi2OK);
  ASSERT_EQ(f.exit(), fmi2OK) << f.log.dump();
  std::vector<fmi2ValueReference> u, k;
  for (const char* n : {"F[1]", "F[2]", "F[3]", "F[4]", "tau[1]", "tau[4]", "rho[2]", "rho[3]", "drho[1]", "drho[4]"})
    u.push_back(f.vr(n));
  for (const auto& in : inputs) k.push_back(f.vr(in.first));
  const Eigen::MatrixXd an = fmi2_jacobian(f, u, k);
  Eigen::MatrixXd fd(u.size(), k.size());
  Eigen::VectorXd err(k.size());
  for (std::size_t j = 0; j < k.size(); ++j) {
    // Steps: pose 0.3 mm (phi 3 mrad), rates 5 mm/s (50 mrad/s), accelerations 0.1, wrench 1 N (0.01 N*m).
    const double h[16] = {3e-4, 3e-4, 3e-4, 3e-3, 5e-3, 5e-3, 5e-3, 5e-2, 0.1, 0.1, 0.1, 0.1, 1, 1, 1, 1e-2};
    fd.col(j) = pkm_test::richardson([&](double s) {
      EXPECT_EQ(f.set(inputs[j].first, inputs[j].second + s), fmi2OK);
      Eigen::VectorXd v(u.size());
      EXPECT_EQ(f.lib.fmi2GetReal(f.c, u.data(), u.size(), v.data()), fmi2OK) << f.log.dump();
      EXPECT_EQ(f.set(inputs[j].first, inputs[j].second), fmi2OK);
      return v;
    }, h[j], &err[j]);
  }
  pkm_test::expect_columns_match("inverse FMU d(F, tau, rho, drho)/d(inputs)", an, fd, err, 1e-7);
  // The multipliers are not differentiated yet: refused, named.
  const fmi2ValueReference lambda = f.vr("lambda[1]");
  const double seed = 1.0;
  double out = 99.0;
  EXPECT_EQ(f.lib.fmi2GetDirectionalDerivative(f.c, &lambda, 1, k.data(), 1, &seed, &out), fmi2Error);
  EXPECT_TRUE(f.log.contains("lambda[1] are not provided")) << f.log.dump();
}
