#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-2-Clause
"""The core bench's ticks built for two platforms, run in one go: pkm_bench
ticks --parseable of the host build (linux64) and of the Windows build
under wine (or the aarch64 build under qemu), alternately, so that both see
the same machine at the same time. Prints, per run (RK4, ROS2 and CVODE,
three kinds of inputs), each platform's time per 1-ms step (the smallest of
the rounds' medians), their ratio against the target, and how far the
other platform's pose after one simulated second is from the host's
(relative to the pose's largest coordinate).

    tests/platform_ticks.py --host build/bench/pkm_bench \\
        --other build/platforms/win64/bench/pkm_bench.exe [--runner wine] [--rounds 3]

Exit status 0 when every run worked and the poses agree within 1e-12 (the
test); the timings are printed, never asserted.
"""
import argparse
import os
import subprocess
import sys

TICKS = ("ticks", "--parseable")  # pkm_bench's tick runs, one line each
TARGET = 1.2  # other platform / host, per tick
POSE_TOLERANCE = 1e-12
# The runs the target applies to: the plant tick with RK4 and CVODE's ramp.
TARGET_RUNS = ("held: RK4, rk4_step 1 ms", "ramp: CVODE 1e-8, continued across steps")
# CVODE continued across the jumps of sampled or held inputs (a path the FMU
# never takes: it restarts there) is accurate to its tolerance only, and its
# step choices follow the rounding: no bound on how far the platforms' poses are.
UNBOUNDED_RUNS = ("sampled: CVODE 1e-8, continued across steps", "held: CVODE 1e-8, continued across steps")


def run(cmd):
    env = dict(os.environ, WINEDEBUG="-all", WINEDLLOVERRIDES="mscoree,mshtml=")
    out = subprocess.run(cmd, check=False, capture_output=True, text=True, env=env)
    rows = {}
    for line in out.stdout.splitlines():
        parts = line.split(";")
        if parts[0] != "tick":
            continue
        if parts[2] == "FAILED":
            rows[parts[1]] = None
        else:
            rows[parts[1]] = (float(parts[2]), [float(v) for v in parts[3:7]])
    if out.returncode != 0 or not rows:
        sys.stderr.write(f"{' '.join(cmd)}: exit {out.returncode}\n{out.stderr}")
        return None
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--host", required=True, help="the host build's pkm_bench")
    ap.add_argument("--other", required=True, help="the other platform's pkm_bench")
    ap.add_argument("--runner", default="wine", help="runs the other platform's binary (wine, qemu-aarch64 -L ...)")
    ap.add_argument("--name", default="win64", help="the other platform's name in the table")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--target", type=float, default=TARGET,
                    help="the ratio to print against (0: none, e.g. under an emulator)")
    a = ap.parse_args()
    runner = a.runner.split() if a.runner else []
    best = {"host": {}, "other": {}}
    poses = {"host": {}, "other": {}}
    for _ in range(a.rounds):
        for key, cmd in (("host", [a.host, *TICKS]), ("other", runner + [a.other, *TICKS])):
            rows = run(cmd)
            if rows is None:
                return 1
            for name, value in rows.items():
                if value is None:
                    print(f"{name}: FAILED on {key}")
                    return 1
                us, pose = value
                best[key][name] = min(us, best[key].get(name, us))
                poses[key][name] = pose
    print(f"pkm_bench ticks, linux64 and {a.name} ({' '.join(runner) or 'native'}) alternately, "
          f"{a.rounds} rounds; us per 1-ms step: the smallest of the rounds' medians (15 runs each)")
    print(f"{'run':44s} {'linux64':>9s} {a.name:>9s} {'ratio':>7s} {'target':>14s} {'pose diff':>10s}")
    worst = 0.0
    for name, host_us in best["host"].items():
        other_us = best["other"].get(name)
        if other_us is None:
            print(f"{name}: missing on {a.name}")
            return 1
        ph, po = poses["host"][name], poses["other"][name]
        scale = max(abs(v) for v in ph)
        diff = max(abs(x - y) for x, y in zip(ph, po)) / scale
        if name not in UNBOUNDED_RUNS:
            worst = max(worst, diff)
        ratio = other_us / host_us
        target = ""
        if name in TARGET_RUNS and a.target > 0:
            target = f"<= {a.target:g}x {'ok' if ratio <= a.target else 'OVER'}"
        note = "  (unbounded: continued across input jumps)" if name in UNBOUNDED_RUNS else ""
        print(f"{name:44s} {host_us:9.3f} {other_us:9.3f} {ratio:6.2f}x {target:>14s} {diff:10.1e}{note}")
    print(f"\npose after 1 s, largest difference relative to the largest coordinate (bounded runs): {worst:.1e} "
          f"(bound {POSE_TOLERANCE:g}) {'ok' if worst <= POSE_TOLERANCE else 'DIFFERS'}")
    return 0 if worst <= POSE_TOLERANCE else 1


if __name__ == "__main__":
    sys.exit(main())
