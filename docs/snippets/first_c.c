/* SPDX-License-Identifier: BSD-2-Clause */
/* The C API: the forces that hold the platform at home, then half a second
 * of forward dynamics driven by them (the pose stays home). */
#include <pkm4puu/pkm.h>
#include <stdio.h>

int main(void) {
  pkm_params p;  pkm_default_params(&p);            /* docs/model.md's machine, SI units */
  pkm_model* m;  char err[256];
  if (pkm_create(&p, &m, err, sizeof err) != PKM_OK) { fprintf(stderr, "%s\n", err); return 1; }

  const double home[4] = {0.0, 0.0, 0.05, 0.0}, zero[4] = {0};
  pkm_inverse_result inv;                            /* forces that hold the pose */
  pkm_inverse_dynamics(m, home, zero, zero, NULL, &inv);

  pkm_init_pose(m, 0.0, home, NULL);                 /* consistent initial state */
  pkm_status s = pkm_advance(m, 0.5, inv.F, NULL);   /* forward dynamics to t = 0.5 s */
  pkm_outputs out;
  pkm_get_outputs(m, inv.F, NULL, &out);             /* pose, rho, theta, lambda, ||C||, cond(J) */
  printf("%s: F = %.9f N, z(0.5 s) = %.12f m, ||C|| = %.1e m\n", pkm_status_string(s), inv.F[0], out.pose[2],
         out.constraint_residual);
  pkm_destroy(m);
  return s == PKM_OK ? 0 : 1;
}
