/* SPDX-License-Identifier: BSD-2-Clause */
/* The C API: the forces that hold the platform at home, then half a second
 * of forward dynamics driven by them with RK4 (the pose stays home). */
#include <pkm4puu/pkm.h>
#include <stdio.h>

int main(void) {
  pkm_model* m;                                       /* docs/model.md's machine, SI units */
  if (pkm_create(&m) != PKM_OK) return 1;
  if (pkm_set_parameter(m, "solver", PKM_SOLVER_RK4) != PKM_OK) {  /* the FMUs' parameter names */
    fprintf(stderr, "%s\n", pkm_last_error(m));
    return 1;
  }

  const double home[4] = {0.0, 0.0, 0.05, 0.0}, zero[4] = {0};
  pkm_inverse_result inv = {.size = sizeof(pkm_inverse_result)};  /* forces that hold the pose */
  pkm_inverse_dynamics(m, home, zero, zero, NULL, &inv);

  double u[PKM_PLANT_INPUTS] = {0};                   /* F[1..4], Fe[1..3], Me_z, tau[1..4] */
  for (int i = 0; i < 4; ++i) u[i] = inv.F[i];
  pkm_init_pose(m, 0.0, home, NULL);                  /* consistent initial state */
  pkm_status s = pkm_advance(m, 0.5, u);              /* forward dynamics to t = 0.5 s */
  pkm_outputs out = {.size = sizeof(pkm_outputs)};
  pkm_get_outputs(m, u, &out);                        /* pose, rho, theta, lambda, ||C||, energies */
  printf("%s: F = %.9f N, z(0.5 s) = %.12f m, ||C|| = %.1e m\n", pkm_status_string(s), inv.F[0], out.pose[2],
         out.constraint_residual);
  pkm_destroy(m);
  return s == PKM_OK ? 0 : 1;
}
