// SPDX-License-Identifier: BSD-2-Clause
// SUNDIALS CVODE (variable-order, variable-step Adams or BDF) on the
// plant's integrated vector: the 8-dimensional state of state_derivative.hpp
// and the two running energy integrals (plant.hpp). Optional root finding
// (the end stops' event indicators). All SUNDIALS objects are created once
// in init(); advancing allocates nothing.
#pragma once

#include <string>

#include "pkm4puu/base/status.hpp"
#include "pkm4puu/base/types.hpp"

// SUNDIALS handle types, declared here so its headers stay in the .cpp.
struct _SUNContext;
struct _generic_N_Vector;
struct _generic_SUNMatrix;
struct _generic_SUNLinearSolver;
struct _generic_SUNNonlinearSolver;

namespace pkm {

enum class CvodeMethod { Adams = 0, BDF = 1 };

/// The Jacobian of CVODE's integrated vector (column-major, as SUNDIALS' dense matrix).
using Mat10 = Eigen::Matrix<double, 10, 10>;

/// Whether this build has CVODE: true when linked with cvode_integrator.cpp
/// (SUNDIALS), false with cvode_unavailable.cpp (the source-code FMUs,
/// built with nothing but a C++17 compiler; solver = 1, RK4, only).
bool cvode_available();

class CvodeIntegrator {
 public:
  /// ydot = rhs(t, y); returns 0 on success, > 0 for a recoverable failure
  /// (CVODE retries with a smaller step), < 0 to abort.
  using Rhs = int (*)(double t, const Vec10& y, Vec10& ydot, void* user);
  /// g[0..n_roots-1] at (t, y); returns 0 on success, nonzero to abort.
  using RootFn = int (*)(double t, const Vec10& y, double* g, void* user);
  /// J = d rhs / d y at (t, y) (BDF's Newton iteration); returns 0 on
  /// success, > 0 for a recoverable failure, < 0 to abort.
  using JacFn = int (*)(double t, const Vec10& y, Mat10& J, void* user);

  CvodeIntegrator() = default;
  ~CvodeIntegrator();
  CvodeIntegrator(const CvodeIntegrator&) = delete;
  CvodeIntegrator& operator=(const CvodeIntegrator&) = delete;

  /// `atol` per component (each positive). `roots` (may be null) with
  /// `n_roots` indicators: CVODE stops where one changes sign
  /// (CVodeRootInit). `jac` (may be null: difference quotients) is BDF's
  /// Jacobian; `min_step` CVODE's smallest step (cvode_min_step,
  /// fixed_step_stability.hpp).
  Status init(CvodeMethod method, double rtol, const Vec10& atol, Rhs rhs, void* user, int n_roots, RootFn roots,
              JacFn jac, double min_step);
  /// Restart the history at (t0, y0): needed after any jump in the inputs.
  Status reset(double t0, const Vec10& y0);
  /// Integrates towards t_out (stop time set, no overshoot). Returns at
  /// t_out, or earlier at a root of the indicators (`root_found` set,
  /// `t_reached` its time; the caller restarts there with reset()).
  /// `root_dirs` (may be null, n_roots entries) receives CVodeGetRootInfo:
  /// +1 / -1 for an indicator that rose / fell through zero, else 0.
  Status advance(double t_out, Vec10& y_out, double& t_reached, bool& root_found, int* root_dirs = nullptr);

  bool needs_reset() const { return needs_reset_; }
  const std::string& last_error() const { return error_; }
  /// Internal steps taken since init(), across restarts (the work per
  /// communication step: pkm_bench ticks). The derivative evaluations are the
  /// caller's to count (Plant::rhs_evaluations).
  long steps() const;

 private:
  static int rhs_trampoline(double t, _generic_N_Vector* y, _generic_N_Vector* ydot, void* self);
  static int root_trampoline(double t, _generic_N_Vector* y, double* g, void* self);
  static int jac_trampoline(double t, _generic_N_Vector* y, _generic_N_Vector* fy, _generic_SUNMatrix* J,
                            void* self, _generic_N_Vector* tmp1, _generic_N_Vector* tmp2, _generic_N_Vector* tmp3);
  static void error_handler(int code, const char* module, const char* function, char* msg,
                            void* self);
  Status create(CvodeMethod method, double rtol, const Vec10& atol, Rhs rhs, void* user, int n_roots, RootFn roots,
                JacFn jac, double min_step);
  static _generic_N_Vector* clone_or_spare(_generic_N_Vector* w);
  void release();

  _SUNContext* ctx_ = nullptr;
  void* mem_ = nullptr;  // CVODE memory
  _generic_N_Vector* y_ = nullptr;
  _generic_N_Vector* atol_ = nullptr;
  _generic_SUNMatrix* A_ = nullptr;                // BDF: dense Jacobian
  _generic_SUNLinearSolver* LS_ = nullptr;         // BDF: dense LU
  _generic_SUNNonlinearSolver* NLS_ = nullptr;     // Adams: fixed point
  _generic_N_Vector* spare_ = nullptr;  // handed out when a clone cannot be allocated (clone_or_spare)
  bool out_of_memory_ = false;
  Rhs rhs_ = nullptr;
  RootFn roots_ = nullptr;
  JacFn jac_ = nullptr;
  void* user_ = nullptr;
  bool needs_reset_ = true;
  long steps_before_reset_ = 0;  // steps() of the histories before the current one
  std::string error_;
};

}  // namespace pkm
