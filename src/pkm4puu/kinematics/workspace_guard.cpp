// SPDX-License-Identifier: BSD-2-Clause
#include "pkm4puu/kinematics/workspace_guard.hpp"

#include <cmath>
#include <cstdio>
#include <limits>

#include "pkm4puu/base/sin_cos.hpp"
#include "pkm4puu/kinematics/constraints.hpp"
#include "pkm4puu/kinematics/leg_kinematics.hpp"
#include "pkm4puu/model/parameter_table.hpp"

namespace pkm {
namespace {

// Per leg, in the base frame, with d = p + Rz(phi) r_Qi - B_i (the
// closed-form elbow-down inverse kinematics of leg_kinematics, written
// without theta1: everything here is invariant under Rz(beta_i)):
//   A^2 = d_x^2 + d_y^2 - h'^2,  cos theta2 = A / l,  sin theta2 = -sqrt(1 - A^2 / l^2),
//   rho = d_z - h - l sin theta2, so the actuator Jacobian's row is
//   d rho / d(x, y, z, phi) = (d_x k, d_y k, 1, k (d_y a_x - d_x a_y)),  k = 1 / (l sin theta2),
// with a = Rz(phi) r_Qi. Only one square root and one division per leg.
// Returns the first unreachable leg, or -1 with J (phi column scaled by
// kConditionLength) and the squared leg measures (cos theta2 sin theta2)^2.
int actuator_rows(const Model& m, const Pose& pose, Mat4& J, Vec4& measure2) {
  const Params& p = m.p;
  double cphi, sphi;
  sin_cos(pose[3], sphi, cphi);
  const double inv_l2 = 1.0 / (p.l * p.l);
  for (int i = 0; i < kLegs; ++i) {
    const Vec3& rq = m.r_Q[i];
    const double ax = cphi * rq.x() - sphi * rq.y(), ay = sphi * rq.x() + cphi * rq.y();
    const double dx = pose[0] + ax - m.B[i].x(), dy = pose[1] + ay - m.B[i].y();
    const double A2 = dx * dx + dy * dy - p.h_prime * p.h_prime;
    const double c2sq = A2 * inv_l2;
    if (!(c2sq >= 0.0) || !(c2sq <= 1.0)) return i;
    const double s2sq = 1.0 - c2sq;
    measure2[i] = c2sq * s2sq;
    const double k = -1.0 / (p.l * std::sqrt(s2sq));  // 1 / (l sin theta2), elbow-down
    J(i, 0) = dx * k;
    J(i, 1) = dy * k;
    J(i, 2) = 1.0;
    J(i, 3) = k * (dy * ax - dx * ay) / kConditionLength;
  }
  return -1;
}

double exact_condition(const Mat4& J) {
  const Eigen::JacobiSVD<Mat4> svd(J);
  const Vec4 s = svd.singularValues();
  return (s[3] > 0.0) ? s[0] / s[3] : std::numeric_limits<double>::infinity();
}

}  // namespace

std::string validate(const GuardLimits& g) {
  // Each limit against its row (parameter_table.hpp); +inf switches the
  // condition check off.
#define PKM_PARAMETER_ROW(...) PKM_PARAMETER_CHECK(g, __VA_ARGS__)
  PKM_PARAMETER_TABLE(PKM_PARAMETER_ONLY_Guard)
#undef PKM_PARAMETER_ROW
  return {};
}

Status check_configuration(const Model& m, const Pose& pose, const GuardLimits& lim, GuardReport* report) {
  GuardReport local;
  GuardReport& r = report ? *report : local;
  r = GuardReport{};
  if (!pose.allFinite()) return r.status = Status::NonFinite;
  Mat4 J;
  Vec4 measure2;
  const int unreachable = actuator_rows(m, pose, J, measure2);
  if (unreachable >= 0) {
    r.leg = unreachable;
    return r.status = Status::Unreachable;
  }
  return check_jacobian(J, measure2, lim, &r);
}

Status check_jacobian(const Mat4& J, const Vec4& measure2, const GuardLimits& lim, GuardReport* report) {
  GuardReport local;
  GuardReport& r = report ? *report : local;
  r = GuardReport{};
  const double min_measure = std::fmax(lim.min_leg_measure, kLegSingularFloor);
  for (int i = 0; i < kLegs; ++i) {
    if (!(measure2[i] >= min_measure * min_measure)) {
      r.leg = i;
      r.leg_measure = std::sqrt(measure2[i]);
      return r.status = Status::Singular;
    }
  }
  if (!(lim.max_jacobian_condition < std::numeric_limits<double>::infinity())) return r.status = Status::Ok;
  // Three tiers, cheapest first; each accepts when an upper bound of
  // cond_2(J) = s1 / s4 is within the limit.
  // 1. From det J = s1 s2 s3 s4 and s1^2 + s2^2 + s3^2 <= ||J||_F^2:
  //    s4^2 >= det^2 / (||J||_F^2 / 3)^3, so cond_2 <= ||J||_F^4 / (sqrt(27) |det J|).
  //    At most 42 along the auto-test path, within 1e3 on 98.5% of the workspace.
  const double fro2 = J.squaredNorm();
  if (fro2 * fro2 <= lim.max_jacobian_condition * 5.196152422706632 * std::fabs(J.determinant()))
    return r.status = Status::Ok;
  // 2. cond_2(J) <= ||J||_F ||J^-1||_F <= 4 cond_2(J).
  const Mat4 Jinv = J.inverse();
  const double bound = J.norm() * Jinv.norm();
  if (bound <= lim.max_jacobian_condition) return r.status = Status::Ok;
  // 3. Near the limit: the exact 2-norm condition number.
  const double exact = exact_condition(J);
  if (exact <= lim.max_jacobian_condition) return r.status = Status::Ok;
  r.condition = exact;
  return r.status = Status::Singular;
}

std::string describe_configuration_failure(const Model& m, const Pose& pose, const GuardLimits& lim,
                                           const GuardReport& r) {
  char buf[480];
  const Params& p = m.p;
  switch (r.status) {
    case Status::Ok:
      return "within the limits";
    case Status::NonFinite:
      return "the pose is not finite";
    case Status::Unreachable: {
      const int i = r.leg < 0 ? 0 : r.leg;
      const PlatformConfig pc = platform_config(pose);
      const Vec3 qt = rotate_to_leg(m, i, platform_point(m, i, pc) - m.B[i]);
      const double dist = std::hypot(qt.x(), qt.y());
      const double reach = std::hypot(p.l, p.h_prime);
      if (dist > p.h_prime) {
        std::snprintf(buf, sizeof buf,
                      "leg %d cannot reach: its platform joint Q_%d lies %.6g m from the leg's prismatic axis, "
                      "beyond the reach sqrt(l^2 + h_prime^2) = %.6g m of the rod (the rod would have to pass "
                      "the horizontal, theta2 = 0; parameters l, h_prime, r_b, r_Q, beta[%d], gamma[%d])",
                      i + 1, i + 1, dist, reach, i + 1, i + 1);
      } else {
        std::snprintf(buf, sizeof buf,
                      "leg %d cannot reach: its platform joint Q_%d lies %.6g m from the leg's prismatic axis, "
                      "closer than h_prime = %.6g m (the rod would have to pass the vertical, theta2 = -90 deg; "
                      "parameters h_prime, r_b, r_Q, beta[%d], gamma[%d])",
                      i + 1, i + 1, dist, p.h_prime, i + 1, i + 1);
      }
      return buf;
    }
    case Status::Singular: {
      if (r.leg >= 0) {
        const PlatformConfig pc = platform_config(pose);
        LegConfig c;
        LegAngles a{0.0, 0.0};
        leg_inverse_kinematics(m, r.leg, pc, c, &a);
        const bool horizontal = std::fabs(c.s2) < std::fabs(c.c2);
        std::snprintf(buf, sizeof buf,
                      "leg %d is at a leg singularity: |cos(theta2) sin(theta2)| = %.3g is below min_leg_measure = "
                      "%.3g (theta2 = %.4f deg, rod nearly %s)",
                      r.leg + 1, r.leg_measure, std::fmax(lim.min_leg_measure, kLegSingularFloor),
                      a.theta2 * 180.0 / kPi, horizontal ? "horizontal" : "vertical");
      } else {
        std::snprintf(buf, sizeof buf,
                      "parallel singularity: the condition number %.4g of the actuator Jacobian exceeds "
                      "max_jacobian_condition = %.4g",
                      r.condition, lim.max_jacobian_condition);
      }
      return buf;
    }
    default:
      return status_name(r.status);
  }
}

Status guard_indicators(const Model& m, const Pose& pose, const GuardLimits& lim, double z[kGuardIndicators],
                        double* condition) {
  if (!pose.allFinite()) return Status::NonFinite;
  Mat4 J;
  Vec4 measure2;
  if (actuator_rows(m, pose, J, measure2) >= 0) return Status::Unreachable;
  // 1 / cond is finite everywhere (0 at a parallel singularity), so the
  // indicator never overflows; it changes sign where cond crosses the limit.
  const double cond = exact_condition(J);
  if (condition) *condition = cond;
  z[0] = 1.0 / cond - 1.0 / lim.max_jacobian_condition;
  for (int i = 0; i < kLegs; ++i) z[1 + i] = std::sqrt(measure2[i]) - lim.min_leg_measure;
  return Status::Ok;
}

}  // namespace pkm
