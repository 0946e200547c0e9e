// SPDX-License-Identifier: BSD-2-Clause
#include "pkm4puu/integrators/cvode_integrator.hpp"

#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace pkm {

bool cvode_available() { return true; }

namespace {

Eigen::Map<Vec10> as_vec(N_Vector v) { return Eigen::Map<Vec10>(N_VGetArrayPointer(v)); }

// Out of memory while SUNDIALS creates its vectors: SUNDIALS 6's N_VClone
// writes into the clone before anyone checks it for NULL (a crash inside
// CVodeInit). The vectors of this integrator clone through clone_or_spare
// instead: when a clone cannot be allocated it hands out the integrator's
// spare vector (allocated first, never destroyed through its ops) and notes
// the failure; init() then frees everything and reports it. The integrator
// being set up on this thread (clones happen only inside init()):
thread_local CvodeIntegrator* t_initializing = nullptr;

void keep_spare(N_Vector) {}

// CVODE's vector operations on this integrator's vectors (length 10, known
// to the compiler here) without SUNDIALS' generic loops: its predictor
// (cvPredict) alone adds up the Nordsieck array pairwise in every step, q (q +
// 1) / 2 calls of N_VLinearSum(1, zn[j-1], 1, zn[j], zn[j-1]), 78 at Adams'
// order 12; its corrector, error test and order selection take weighted RMS
// norms (about 18 per continued 1-ms tick) and scale vectors. Each case below
// is SUNDIALS 6.4.1's nvector_serial.c (N_VLinearSum_Serial and its
// Vaxpy/VSum/VDiff/VLin1/VLin2/VScaleSum/VScaleDiff, N_VScale_Serial with
// VScaleBy/VCopy/VNeg, N_VWrmsNorm_Serial with N_VWSqrSumLocal_Serial): the
// same cases in its order, the same per-component arithmetic, the norm's sum
// in its order, so bit for bit the same. Element-wise loops, so z may alias x
// or y as there. Other lengths go to the serial functions.
constexpr sunindextype kLength = 10;

void axpy10(realtype a, const realtype* x, realtype* y) {
  if (a == 1.0) {
    for (int i = 0; i < kLength; ++i) y[i] += x[i];
  } else if (a == -1.0) {
    for (int i = 0; i < kLength; ++i) y[i] -= x[i];
  } else {
    for (int i = 0; i < kLength; ++i) y[i] += a * x[i];
  }
}

void linear_sum10(realtype a, N_Vector xv, realtype b, N_Vector yv, N_Vector zv) {
  if (b == 1.0 && zv == yv) return axpy10(a, NV_DATA_S(xv), NV_DATA_S(yv));
  if (a == 1.0 && zv == xv) return axpy10(b, NV_DATA_S(yv), NV_DATA_S(xv));
  const realtype* x = NV_DATA_S(xv);
  const realtype* y = NV_DATA_S(yv);
  realtype* z = NV_DATA_S(zv);
  if (a == 1.0 && b == 1.0) {  // VSum
    for (int i = 0; i < kLength; ++i) z[i] = x[i] + y[i];
    return;
  }
  bool test;
  if ((test = (a == 1.0 && b == -1.0)) || (a == -1.0 && b == 1.0)) {  // VDiff(v2, v1)
    const realtype* v1 = test ? y : x;
    const realtype* v2 = test ? x : y;
    for (int i = 0; i < kLength; ++i) z[i] = v2[i] - v1[i];
    return;
  }
  if ((test = (a == 1.0)) || b == 1.0) {  // VLin1(c, v1, v2)
    const realtype c = test ? b : a;
    const realtype* v1 = test ? y : x;
    const realtype* v2 = test ? x : y;
    for (int i = 0; i < kLength; ++i) z[i] = (c * v1[i]) + v2[i];
    return;
  }
  if ((test = (a == -1.0)) || b == -1.0) {  // VLin2(c, v1, v2)
    const realtype c = test ? b : a;
    const realtype* v1 = test ? y : x;
    const realtype* v2 = test ? x : y;
    for (int i = 0; i < kLength; ++i) z[i] = (c * v1[i]) - v2[i];
    return;
  }
  if (a == b) {  // VScaleSum
    for (int i = 0; i < kLength; ++i) z[i] = a * (x[i] + y[i]);
    return;
  }
  if (a == -b) {  // VScaleDiff
    for (int i = 0; i < kLength; ++i) z[i] = a * (x[i] - y[i]);
    return;
  }
  for (int i = 0; i < kLength; ++i) z[i] = (a * x[i]) + (b * y[i]);
}

bool length10(N_Vector v) { return NV_LENGTH_S(v) == kLength; }

void linear_sum(realtype a, N_Vector x, realtype b, N_Vector y, N_Vector z) {
  if (length10(x) && length10(y) && length10(z)) return linear_sum10(a, x, b, y, z);
  N_VLinearSum_Serial(a, x, b, y, z);
}

void scale(realtype c, N_Vector xv, N_Vector zv) {
  if (!length10(xv) || !length10(zv)) return N_VScale_Serial(c, xv, zv);
  const realtype* x = NV_DATA_S(xv);
  realtype* z = NV_DATA_S(zv);
  if (zv == xv) {  // VScaleBy
    for (int i = 0; i < kLength; ++i) z[i] *= c;
  } else if (c == 1.0) {  // VCopy
    for (int i = 0; i < kLength; ++i) z[i] = x[i];
  } else if (c == -1.0) {  // VNeg
    for (int i = 0; i < kLength; ++i) z[i] = -x[i];
  } else {
    for (int i = 0; i < kLength; ++i) z[i] = c * x[i];
  }
}

realtype wrms_norm(N_Vector xv, N_Vector wv) {
  if (!length10(xv) || !length10(wv)) return N_VWrmsNorm_Serial(xv, wv);
  const realtype* x = NV_DATA_S(xv);
  const realtype* w = NV_DATA_S(wv);
  realtype sum = 0.0;  // N_VWSqrSumLocal_Serial
  for (int i = 0; i < kLength; ++i) {
    const realtype prodi = x[i] * w[i];
    sum += prodi * prodi;
  }
  sum = sum / static_cast<realtype>(kLength);
  return sum <= 0.0 ? 0.0 : std::sqrt(sum);  // SUNRsqrt
}

// The operations above on a vector of this integrator (its clones copy them),
// its clones made by `clone`.
void use_own_ops(N_Vector v, N_Vector (*clone)(N_Vector)) {
  v->ops->nvclone = clone;
  v->ops->nvlinearsum = &linear_sum;
  v->ops->nvscale = &scale;
  v->ops->nvwrmsnorm = &wrms_norm;
}

}  // namespace

N_Vector CvodeIntegrator::clone_or_spare(N_Vector w) {
  N_Vector v = N_VClone_Serial(w);  // copies w's ops: its clones clone through here too
  if (v) return v;
  CvodeIntegrator* me = t_initializing;
  if (!me || !me->spare_) return nullptr;
  me->out_of_memory_ = true;
  return me->spare_;
}

CvodeIntegrator::~CvodeIntegrator() { release(); }

void CvodeIntegrator::release() {
  if (mem_) CVodeFree(&mem_);
  if (NLS_) SUNNonlinSolFree(NLS_);
  if (LS_) SUNLinSolFree(LS_);
  if (A_) SUNMatDestroy(A_);
  if (y_) N_VDestroy(y_);
  if (atol_) N_VDestroy(atol_);
  if (spare_) N_VDestroy_Serial(spare_);  // its ops' destroy is keep_spare
  spare_ = nullptr;
  out_of_memory_ = false;
  atol_ = nullptr;
  if (ctx_) SUNContext_Free(&ctx_);
  mem_ = nullptr;
  NLS_ = nullptr;
  LS_ = nullptr;
  A_ = nullptr;
  y_ = nullptr;
  ctx_ = nullptr;
}

int CvodeIntegrator::rhs_trampoline(double t, N_Vector y, N_Vector ydot, void* self) {
  auto* me = static_cast<CvodeIntegrator*>(self);
  Vec10 out;
  const int r = me->rhs_(t, as_vec(y), out, me->user_);
  if (r == 0) as_vec(ydot) = out;
  return r;
}

int CvodeIntegrator::jac_trampoline(double t, N_Vector y, N_Vector, SUNMatrix J, void* self, N_Vector, N_Vector,
                                    N_Vector) {
  auto* me = static_cast<CvodeIntegrator*>(self);
  Mat10 out;
  const int r = me->jac_(t, as_vec(y), out, me->user_);
  if (r == 0) Eigen::Map<Mat10>(SUNDenseMatrix_Data(J)) = out;  // both column-major
  return r;
}

int CvodeIntegrator::root_trampoline(double t, N_Vector y, double* g, void* self) {
  auto* me = static_cast<CvodeIntegrator*>(self);
  return me->roots_(t, as_vec(y), g, me->user_);
}

void CvodeIntegrator::error_handler(int code, const char* module, const char* function, char* msg,
                                    void* self) {
  // Keep the message for the caller's logger; never print. No exception
  // leaves this C callback (out of memory: the message is lost).
  auto* me = static_cast<CvodeIntegrator*>(self);
  try {
    me->error_ = std::string(module ? module : "CVODE") + "/" + (function ? function : "?") + " (" +
                 std::to_string(code) + "): " + (msg ? msg : "");
  } catch (...) {
  }
}

Status CvodeIntegrator::init(CvodeMethod method, double rtol, const Vec10& atol, Rhs rhs, void* user, int n_roots,
                             RootFn roots, JacFn jac, double min_step) {
  t_initializing = this;
  Status s = Status::SolverFailure;
  try {
    s = create(method, rtol, atol, rhs, user, n_roots, roots, jac, min_step);
  } catch (...) {  // std::bad_alloc from error_
  }
  t_initializing = nullptr;
  if (s == Status::Ok && out_of_memory_) s = Status::SolverFailure;
  if (s != Status::Ok) {
    const bool oom = out_of_memory_;
    release();
    if (oom) error_ = "out of memory";
  }
  return s;
}

Status CvodeIntegrator::create(CvodeMethod method, double rtol, const Vec10& atol, Rhs rhs, void* user, int n_roots,
                               RootFn roots, JacFn jac, double min_step) {
  release();
  error_.clear();
  steps_before_reset_ = 0;
  if (!(rtol > 0.0) || !std::isfinite(rtol) || !(atol.minCoeff() > 0.0) || !atol.allFinite() || !rhs)
    return Status::InvalidArgument;
  rhs_ = rhs;
  roots_ = roots;
  jac_ = jac;
  user_ = user;
  if (SUNContext_Create(nullptr, &ctx_) != 0) return Status::SolverFailure;
  spare_ = N_VNew_Serial(10, ctx_);
  if (!spare_) return Status::SolverFailure;
  use_own_ops(spare_, &CvodeIntegrator::clone_or_spare);
  spare_->ops->nvdestroy = &keep_spare;
  y_ = N_VNew_Serial(10, ctx_);
  if (!y_) return Status::SolverFailure;
  use_own_ops(y_, &CvodeIntegrator::clone_or_spare);  // CVodeInit's clones copy them
  mem_ = CVodeCreate(method == CvodeMethod::BDF ? CV_BDF : CV_ADAMS, ctx_);
  if (!mem_) return Status::SolverFailure;
  CVodeSetErrHandlerFn(mem_, &CvodeIntegrator::error_handler, this);
  N_VConst(0.0, y_);
  int flag = CVodeInit(mem_, &CvodeIntegrator::rhs_trampoline, 0.0, y_);
  if (flag != CV_SUCCESS) {
    // Out of memory inside CVodeInit: it has freed its vectors already, and
    // CVodeFree would free them again (SUNDIALS 6). Only the memory block
    // CVodeCreate allocated remains.
    std::free(mem_);
    mem_ = nullptr;
    return Status::SolverFailure;
  }
  flag |= CVodeSetUserData(mem_, this);
  // Every component under rtol and atol, the two running energy integrals
  // (8, 9; atol in J) too: out of the error test (as CVODES treats
  // quadratures by default) they drift from the motion's accuracy
  // (docs/performance.md). The contacts are located (root finding, a restart
  // at each), so the integrand's jump there costs no step.
  atol_ = N_VNew_Serial(10, ctx_);
  if (!atol_) return Status::SolverFailure;
  use_own_ops(atol_, &CvodeIntegrator::clone_or_spare);
  as_vec(atol_) = atol;
  flag |= CVodeSVtolerances(mem_, rtol, atol_);
  // Enough for a long communication interval at the natural step (~1 ms),
  // few enough that a run into a singularity fails in a fraction of a second.
  flag |= CVodeSetMaxNumSteps(mem_, 100000);
  // A floor on the step (min_step: cvode_min_step, fixed_step_stability.hpp):
  // without one CVODE creeps towards the edge of the workspace (a leg
  // singularity) in ever smaller steps until it has spent its 100000 (about
  // 0.2 s per failing call, 5 s under the sanitizers); with it, such a call
  // fails after a few hundred evaluations, at the same point.
  flag |= CVodeSetMinStep(mem_, min_step);
  if (roots && n_roots > 0) flag |= CVodeRootInit(mem_, n_roots, &CvodeIntegrator::root_trampoline);
  if (method == CvodeMethod::BDF) {
    A_ = SUNDenseMatrix(10, 10, ctx_);
    LS_ = SUNLinSol_Dense(y_, A_, ctx_);
    if (!A_ || !LS_) return Status::SolverFailure;
    flag |= CVodeSetLinearSolver(mem_, LS_, A_);
    if (jac) flag |= CVodeSetJacFn(mem_, &CvodeIntegrator::jac_trampoline);
  } else {
    NLS_ = SUNNonlinSol_FixedPoint(y_, 0, ctx_);
    if (!NLS_) return Status::SolverFailure;
    flag |= CVodeSetNonlinearSolver(mem_, NLS_);
  }
  needs_reset_ = true;
  return flag == 0 ? Status::Ok : Status::SolverFailure;
}

Status CvodeIntegrator::reset(double t0, const Vec10& y0) {
  if (!mem_) return Status::NotInitialized;
  as_vec(y_) = y0;
  steps_before_reset_ = steps();
  if (CVodeReInit(mem_, t0, y_) != CV_SUCCESS) return Status::SolverFailure;
  needs_reset_ = false;
  return Status::Ok;
}

Status CvodeIntegrator::advance(double t_out, Vec10& y_out, double& t_reached, bool& root_found, int* root_dirs) {
  if (!mem_ || needs_reset_) return Status::NotInitialized;
  CVodeSetStopTime(mem_, t_out);
  t_reached = 0.0;
  root_found = false;
  const int flag = CVode(mem_, t_out, y_, &t_reached, CV_NORMAL);
  if (flag < 0) {
    needs_reset_ = true;  // its history is no longer trustworthy
    return Status::SolverFailure;
  }
  if (flag == CV_ROOT_RETURN) {
    if (!as_vec(y_).allFinite()) {
      needs_reset_ = true;
      return Status::SolverFailure;
    }
    root_found = true;
    if (root_dirs) CVodeGetRootInfo(mem_, root_dirs);
    y_out = as_vec(y_);
    return Status::Ok;
  }
  // CVODE (6.4) can report success without having integrated: when the
  // state derivative is so large that the initial step underflows to 0 it
  // warns "t + h = t", takes zero-length steps up to the stop time, fails to
  // interpolate there (ignored) and returns CV_SUCCESS with y unchanged.
  // Accept only an interval that CVODE's own time really reached.
  double t_cur = 0.0;
  CVodeGetCurrentTime(mem_, &t_cur);
  if (!(t_cur >= t_out - 1e-12 * (1.0 + std::fabs(t_out))) || !as_vec(y_).allFinite()) {
    char buf[200];
    std::snprintf(buf, sizeof buf,
                  "CVODE returned at t = %.17g without integrating past t = %.17g (step size underflow: "
                  "the state derivative is too large)",
                  t_out, t_cur);
    error_ = buf;
    needs_reset_ = true;
    return Status::SolverFailure;
  }
  y_out = as_vec(y_);
  t_reached = t_out;
  return Status::Ok;
}

long CvodeIntegrator::steps() const {
  long n = 0;
  if (mem_) CVodeGetNumSteps(mem_, &n);
  return steps_before_reset_ + n;
}

}  // namespace pkm
