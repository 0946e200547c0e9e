// SPDX-License-Identifier: BSD-2-Clause
// CVODE across the end stops' switches: it stops at every root of the stop
// indicators (a joint reaching or leaving a stop), switches the held stops
// by each root's direction (not by the side of zero on which the located
// state happens to fall) and restarts its history there.
#pragma once

#include <cstdio>
#include <string>

#include "pkm4puu/integrators/cvode_integrator.hpp"
#include "pkm4puu/machine/end_stops.hpp"

namespace pkm {

/// At most this many roots in one advance (a chattering contact beyond).
constexpr int kMaxSwitchesPerAdvance = 100000;

/// Integrates x from CVODE's current point to t_end. `stops` holds the
/// contact mode (end_stops.hpp) at the start; it is switched at every root
/// and returned as it is at the end (on failure the caller restores its
/// own). CVODE's root function is the stop indicators under `stops`
/// (with the hysteresis). `switches` counts
/// the roots. On failure `error` says why (CVODE's message, or the
/// chattering bound: then `chattering` is set) and CVODE is left for the
/// caller to reset.
inline Status located_cvode_advance(CvodeIntegrator& cvode, double t_end, Vec10& x, unsigned& stops, long& switches,
                                    std::string& error, bool& chattering) {
  chattering = false;
  int located = 0;
  Status s = Status::Ok;
  for (;;) {
    double t_reached = t_end;
    bool root = false;
    int dirs[kContactIndicators] = {};
    s = cvode.advance(t_end, x, t_reached, root, dirs);
    if (s != Status::Ok || !root) break;
    stops = stops_after_crossings(stops, dirs);
    ++switches;
    if (++located > kMaxSwitchesPerAdvance) {
      char buf[160];
      std::snprintf(buf, sizeof buf, "more than %d end-stop events before t = %.17g s (chattering contact)",
                    kMaxSwitchesPerAdvance, t_end);
      error = buf;
      chattering = true;
      return Status::SolverFailure;
    }
    if (!(t_reached < t_end)) break;
    s = cvode.reset(t_reached, x);
    if (s != Status::Ok) break;
  }
  if (s != Status::Ok) error = cvode.last_error();
  return s;
}

}  // namespace pkm
