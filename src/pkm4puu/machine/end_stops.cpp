// SPDX-License-Identifier: BSD-2-Clause
#include "pkm4puu/machine/end_stops.hpp"

#include <cstdio>
#include <limits>

#include "pkm4puu/kinematics/actuator_positions.hpp"

namespace pkm {

Status stop_indicators(const Model& m, const Pose& pose, unsigned stops, double z[kStopIndicators]) {
  Vec4 rho;
  const Status s = actuator_positions(m, pose, rho);
  if (s == Status::Ok) stop_indicators(m.p, rho, stops, z);
  return s;
}

std::string describe_unsettled_mode(const Params& p, const Vec4& rho, const Vec4& rhod, unsigned stops) {
  const unsigned rule = stops_after_event(p, rho, rhod, stops);
  char head[160], what[320] = "";
  std::snprintf(head, sizeof head, "the contact mode %#x does not match the state (the event rule keeps %#x there): ",
                stops, rule);
  const unsigned wrong = rule ^ stops;
  for (int k = 0; k < kStopIndicators && !*what; ++k) {
    if (!(wrong & (1u << k))) continue;
    const int leg = k % kLegs;
    const bool lower = k < kLegs;
    const double clear = lower ? rho[leg] - p.rho_min : p.rho_max - rho[leg];  // > 0: within the travel
    if (stops & (1u << k)) {
      std::snprintf(what, sizeof what,
                    "the %s stop of leg %d is held while its slider is %.6g m clear of it (rho = %.9g m, %s = %.9g "
                    "m): a stop that pulls",
                    lower ? "lower" : "upper", leg + 1, clear, rho[leg], lower ? "rho_min" : "rho_max",
                    lower ? p.rho_min : p.rho_max);
    } else {
      std::snprintf(what, sizeof what, "the slider of leg %d is %.6g m past its %s stop, which is not held", leg + 1,
                    -clear, lower ? "lower" : "upper");
    }
  }
  for (int leg = 0; leg < kLegs && !*what; ++leg) {
    if (!(wrong & clamp_bit(leg))) continue;
    const StopContact c = stop_contact(p, leg, stops & ~clamp_bit(leg), rho[leg], rhod[leg]);
    std::snprintf(what, sizeof what, "the held stop of leg %d is %s while its spring and damper %s (%.6g N)", leg + 1,
                  (stops & clamp_bit(leg)) ? "clamped" : "not clamped",
                  (stops & clamp_bit(leg)) ? "push" : "would pull", -c.side * c.force);
  }
  return std::string(head) + what;
}

}  // namespace pkm
