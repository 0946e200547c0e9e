/* SPDX-License-Identifier: BSD-2-Clause */
/* The holding forces at the home pose through the installed C API: each
 * actuator carries 2.655616050 N (docs/model.md); the header's version and
 * ABI version must be the library's. Exit status 0 when all hold. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <pkm4puu/pkm.h>

int main(void) {
  const double home[4] = {0.0, 0.0, 0.05, 0.0}, zero[4] = {0.0, 0.0, 0.0, 0.0};
  pkm_model* m = NULL;
  pkm_inverse_result r = {.size = sizeof(pkm_inverse_result)};
  int i, bad = 0;
  if (strcmp(pkm_version(), PKM_VERSION_STRING) != 0 || pkm_abi_version() != PKM_ABI_VERSION) {
    fprintf(stderr, "library %s (ABI %d), header %s (ABI %d)\n", pkm_version(), pkm_abi_version(),
            PKM_VERSION_STRING, PKM_ABI_VERSION);
    return 1;
  }
  if (pkm_create(&m) != PKM_OK) {
    fprintf(stderr, "pkm_create failed\n");
    return 1;
  }
  if (pkm_inverse_dynamics(m, home, zero, zero, NULL, &r) != PKM_OK) {
    fprintf(stderr, "pkm_inverse_dynamics: %s\n", pkm_last_error(m));
    pkm_destroy(m);
    return 1;
  }
  for (i = 0; i < 4; ++i) {
    printf("F[%d] = %.9f N\n", i + 1, r.F[i]);
    if (fabs(r.F[i] - 2.655616050) > 5e-9) bad = 1;
  }
  pkm_destroy(m);
  printf("pkm4puu %s: %s\n", pkm_version(), bad ? "holding forces differ from 2.655616050 N" : "ok");
  return bad;
}
