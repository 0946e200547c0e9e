// SPDX-License-Identifier: BSD-2-Clause
// Every lane kernel (the state derivative's legs and the actuator positions,
// the derivatives' partials, the inverse dynamics in full and for the
// actuators, the regressor from the platform's motion and from the joints,
// the sliders' positions) at every copy this build and processor run
// (lanes::Kernel: Scalar where the kernel has it, Baseline, Avx, Best with
// Model::avx on and off), each against the Baseline copy bit for bit: the
// same template, the same expression order, no contraction.
#include <cstdio>
#include <string>
#include <vector>

#include "pkm4puu/dynamics/inverse_dynamics.hpp"
#include "pkm4puu/dynamics/inverse_lanes.hpp"
#include "pkm4puu/dynamics/lagrangian.hpp"
#include "pkm4puu/dynamics/leg_lanes_derivatives.hpp"
#include "pkm4puu/dynamics/regressor_lanes.hpp"
#include "pkm4puu/machine/passive_force.hpp"
#include "test_support.hpp"

using namespace pkm_test;
using lanes::Kernel;

namespace {

/// One kernel's results at one state, as bytes (compared bit for bit, a NaN
/// included), and its status.
struct KernelRun {
  Status status = Status::Ok;
  std::vector<unsigned char> bits;
  template <class... T>
  void keep(const T&... parts) {
    (append(&parts, sizeof(T)), ...);
  }
  void append(const void* p, size_t n) {
    const auto* c = static_cast<const unsigned char*>(p);
    bits.insert(bits.end(), c, c + n);
  }
};

/// A random motion with the applied forces and the stops held.
struct KernelInput : Motion {
  Vec16 f;
  unsigned stops;
};

const char* const kKernelNames[] = {"leg_sums", "lane_actuator_positions", "leg_partial_sums",
                                    "reduced_inverse (full)", "reduced_inverse (actuators)", "regressor_lanes",
                                    "joint_regressor_lanes", "slider_positions_lanes"};
constexpr int kKernels = 8;
// The kernels with a one-leg (Scalar) copy.
constexpr bool kHasScalar[kKernels] = {true, true, true, false, false, false, false, false};

KernelRun run_kernel(int which, const Model& m, const KernelInput& mo, Kernel kind) {
  KernelRun r;
  const PlatformConfig pc = platform_config(mo.pose);
  switch (which) {
    case 0: {
      LegSums s{};
      r.status = leg_sums(m, pc, mo.vel, mo.f, mo.stops, s, kind);
      r.keep(s.mr, s.rhs, s.rho, s.rhod);
      break;
    }
    case 1: {
      Vec4 rho = Vec4::Zero();
      r.status = lane_actuator_positions(m, pc, rho, kind);
      r.keep(rho);
      break;
    }
    case 2: {
      LegPartialSums p;
      r.status = leg_partial_sums(m, pc, mo.vel, mo.f, mo.stops, p, kind);
      r.keep(p.sums.mr, p.sums.rhs, p.pdd, p.dp, p.dpd, p.J_rho, p.drhod_dp);
      break;
    }
    case 3: {
      InverseDynamicsResult o;
      o.q.setZero(), o.qd.setZero(), o.qdd.setZero(), o.lambda.setZero(), o.F.setZero();
      r.status = reduced_inverse(m, mo.pose, mo.vel, mo.acc, mo.we, &o, nullptr, kind);
      r.keep(o.q, o.qd, o.qdd, o.lambda, o.F, o.tau, o.beyond_stops);
      break;
    }
    case 4: {
      InverseActuators o;
      r.status = reduced_inverse(m, mo.pose, mo.vel, mo.acc, mo.we, nullptr, &o, kind);
      r.keep(o.F, o.tau, o.rho, o.rhod, o.leg_measure, o.leg_measure_min, o.J_rho, o.beyond_stops);
      break;
    }
    case 5: {
      RegressorSample o;
      r.status = regressor_lanes(m, pc, mo.vel, mo.acc, mo.we, o, kind);
      r.keep(o.Y, o.F0, o.rho, o.rhod, o.pose_d, o.pose_dd, o.beyond_stops);
      break;
    }
    case 6: {
      RegressorSample o;
      r.status = joint_regressor_lanes(m, pc, mo.vel, mo.acc, mo.we, o, kind);  // as slider rates, accelerations
      r.keep(o.Y, o.F0, o.rho, o.rhod, o.pose_d, o.pose_dd, o.beyond_stops);
      break;
    }
    default: {
      Vec4 rho = Vec4::Zero();
      Mat4 A = Mat4::Zero();
      r.status = slider_positions_lanes(m, pc, rho, A, kind);
      r.keep(rho, A);
      break;
    }
  }
  if (r.status != Status::Ok) r.bits.clear();  // only the status is promised on failure
  return r;
}

/// A state from the auto-test's neighbourhood with forces, accelerations and
/// a wrench; every fourth pushed off the workspace, every fifth with fast
/// sliders (the friction's tanh saturated), stops held in several patterns.
KernelInput kernel_input(const Model& m, unsigned seed) {
  const unsigned stops[] = {kStopsFromState, 0u, 0x0Fu, 0xF0u, 0x5Au};
  KernelInput mo{random_motion(m, seed, 3.0, 0.5), Vec16::Zero(), stops[seed % 5]};
  if (seed % 5 == 0) mo.vel *= 20.0;
  if (seed % 4 == 0) mo.pose.head<3>() += random_vec<3>(seed + 500, 0.05);
  mo.f = generalized_forces(random_vec<4>(seed + 600, 3.0), mo.we);
  return mo;
}

}  // namespace

TEST(LaneKernels, EveryCopyGivesTheBaselineBits) {
  // With Coulomb friction the passive force is the scalar function per lane;
  // without it, and no stop acting, the lanes' own expression.
  Params p = every_machine_term();
  for (const double coulomb : {0.2, 0.0}) {
    p.friction_coulomb = coulomb;
    Model with_avx = model_of(p);
    Model without = with_avx;
    without.avx = false;
    const bool avx_runs = PKM_LANES_AVX_DISPATCH && lanes::cpu_runs_avx();
    EXPECT_EQ(with_avx.avx, lanes::cpu_runs_avx());
    int compared[kKernels] = {}, failed = 0;
    for (unsigned seed = 1; seed <= 120; ++seed) {
      const KernelInput mo = kernel_input(with_avx, seed);
      for (int k = 0; k < kKernels; ++k) {
        SCOPED_TRACE(std::string(kKernelNames[k]) + ", seed " + std::to_string(seed));
        const KernelRun base = run_kernel(k, with_avx, mo, Kernel::Baseline);
        ASSERT_NE(base.status, Status::InvalidArgument);
        if (base.status != Status::Ok) ++failed;
        struct Copy {
          const char* name;
          const Model* m;
          Kernel kind;
          bool runs;
        } copies[] = {{"Scalar", &with_avx, Kernel::Scalar, kHasScalar[k]},
                      {"Avx", &with_avx, Kernel::Avx, avx_runs},
                      {"Best (Model::avx)", &with_avx, Kernel::Best, true},
                      {"Best (Model::avx off)", &without, Kernel::Best, true}};
        for (const Copy& c : copies) {
          const KernelRun r = run_kernel(k, *c.m, mo, c.kind);
          if (!c.runs) {
            EXPECT_EQ(r.status, Status::InvalidArgument) << c.name;
            continue;
          }
          EXPECT_EQ(r.status, base.status) << c.name;
          EXPECT_TRUE(r.bits == base.bits) << c.name << ": not the baseline's bits";
          ++compared[k];
        }
      }
    }
    EXPECT_GT(failed, 0);  // the statuses off the workspace were compared too
    for (int k = 0; k < kKernels; ++k)
      EXPECT_EQ(compared[k], 120 * (2 + (kHasScalar[k] ? 1 : 0) + (avx_runs ? 1 : 0))) << kKernelNames[k];
    if (coulomb == 0.2)
      std::printf("lane kernels compared with the Baseline copy: Scalar (where the kernel has it), %s, Best\n",
                  avx_runs ? "Avx" : "no Avx (not in this build or processor)");
  }
}
