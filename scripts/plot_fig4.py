#!/usr/bin/env python3
"""Plots a run of the paper's Figure 4: desired and measured joint positions, and the tracking error.

Runs `chimera run examples/fig4_pid_joint.yaml --clock virtual` with a script on standard input
that samples theta_d and theta_m every 10 ms of simulated time (the virtual clock makes the run
deterministic and fast), then draws them with matplotlib (Debian's python3-matplotlib).
"""
import argparse
import re
import subprocess

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

LINE = re.compile(r"^(theta_d|theta_m) = \[(.*)\]$")


def sample(chimera, file, seconds, step_ms):
    steps = int(seconds * 1000 / step_ms)
    script = "".join(f"wait {step_ms}ms\nget theta_d\nget theta_m\n" for _ in range(steps)) + "quit\n"
    out = subprocess.run([chimera, "run", file, "--clock", "virtual", "--for", f"{seconds + 1}s"],
                         input=script, capture_output=True, text=True, check=True).stdout
    series = {"theta_d": [], "theta_m": []}
    for line in out.splitlines():
        m = LINE.match(line)
        if m:
            series[m.group(1)].append([float(x) for x in m.group(2).split(",")])
    n = min(len(series["theta_d"]), len(series["theta_m"]))
    times = [(i + 1) * step_ms / 1000 for i in range(n)]
    return times, series["theta_d"][:n], series["theta_m"][:n]


def main():
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--chimera", default="build/apps/chimera/chimera")
    p.add_argument("--file", default="examples/fig4_pid_joint.yaml")
    p.add_argument("--seconds", type=float, default=6.0)
    p.add_argument("-o", "--output", default="build/fig4.png")
    a = p.parse_args()

    t, desired, measured = sample(a.chimera, a.file, a.seconds, 10)
    joints = len(desired[0])
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(9, 6), sharex=True, height_ratios=[3, 1.4])
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for j in range(joints):
        c = colors[j % len(colors)]
        top.plot(t, [d[j] for d in desired], "--", color=c, linewidth=1)
        top.plot(t, [m[j] for m in measured], "-", color=c, linewidth=1.6, label=f"joint {j + 1}")
    top.set_ylabel("joint position (rad)")
    top.set_title("Figure 4 on the simulated arm: desired (dashed) and measured (solid), 1 kHz PID")
    top.legend(ncol=3, fontsize=8, loc="upper right")
    error = [max(abs(d - m) for d, m in zip(dd, mm)) * 1000 for dd, mm in zip(desired, measured)]
    bottom.plot(t, error, color="black", linewidth=1)
    bottom.set_ylabel("max |error| (mrad)")
    bottom.set_xlabel("time (s)")
    fig.tight_layout()
    fig.savefig(a.output, dpi=110)
    print(a.output)


if __name__ == "__main__":
    main()
