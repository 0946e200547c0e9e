// SPDX-License-Identifier: BSD-2-Clause
// pkm_bench [core|ticks] [--quick] [--parseable]: the core's timing figures as
// tables, each with its ratios to a baseline measured in the same run (never a
// pass/fail exit code). core: the state derivative, its analytic derivatives,
// the regressor, the inverse dynamics, the 2-s auto-test (core.cpp); ticks:
// 1-ms steps of the Plant per solver and input, then the stiff cases
// (ticks.cpp). --quick: short batches (the documentation build's run);
// --parseable (ticks): one line a run, tick;<run>;<us/step>;<x>;<y>;<z>;<phi>,
// the pose after 1 s (tests/platform_ticks.py).
#include <cstdio>
#include <string>

#include "core/core_bench.hpp"

pkm::bench::Effort pkm::bench::effort;

int main(int argc, char** argv) {
  bool core = false, ticks = false, parseable = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "core") core = true;
    else if (a == "ticks") ticks = true;
    else if (a == "--parseable") parseable = true;
    else if (a == "--quick") pkm::bench::effort = pkm::bench::Effort{7, 2e-3, 7, 3, 1.0, 3};
    else {
      std::fprintf(stderr, "pkm_bench: unknown argument %s (usage: pkm_bench [core|ticks] [--quick] [--parseable])\n",
                   argv[i]);
      return 2;
    }
  }
  if (!core && !ticks) core = !parseable, ticks = true;  // no part named: both (--parseable: the ticks)
  int status = core ? pkm::bench::core_part() : 0;
  if (ticks) status |= pkm::bench::ticks_part(parseable);
  return status;
}
