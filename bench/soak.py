#!/usr/bin/env python3
"""The soak (issue 13, item 7): Figure 4 with its data logger and the flight recorder, run long.

    bench/soak.py CHIMERA [--seconds 3600] [--sample 60] [--clock real|virtual] [--json OUT]
                          [--max-growth-kb 1024]

Runs `chimera run examples/fig4_pid_joint.yaml --record 10s --for SECONDS --stats-json`, reads the
process's resident memory (VmRSS) every SAMPLE seconds of wall time, and when it has ended says:

- memory growth: the last sample against the first one taken after the first tenth of the run
  (the logger's file buffer and the allocator's arenas settle in that time);
- lost rows: the rows the logger's file should have (one per logger cycle, from --stats-json)
  against the rows it has; a logger that cannot write also ends the run with a message and exit 1;
- missed deadlines and cycles run, per task.

Exits 0 only if the run ended with 0, no row is lost and memory grew by at most MAX_GROWTH_KB;
missed deadlines are reported, never judged here (on the real clock they measure the machine).
`make soak` runs an hour on the real clock (SOAK_SECONDS to shorten it); CI's short pass runs it on
the virtual clock (tests/integration/soak), where an hour of Figure 4 takes under a minute.
"""

import argparse
import json
import os
import platform
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
FIG4 = ROOT / "examples" / "fig4_pid_joint.yaml"
LOG_TASK = "log"  # Figure 4's data logger, writing fig4.csv below $CHIMERA_LOG_DIR


def rss_kb(pid):
    try:
        text = Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return None
    m = re.search(r"^VmRSS:\s+(\d+) kB", text, re.M)
    return int(m.group(1)) if m else None


def data_rows(csv_path):
    """Rows of a data_logger file, its header not counted; None if there is no file."""
    try:
        with open(csv_path, "rb") as f:
            return max(sum(1 for _ in f) - 1, 0)
    except OSError:
        return None


def soak(chimera, seconds, sample_s, clock, work):
    stats_path = work / "stats.json"
    cmd = [str(chimera), "run", str(FIG4), "--record", "10s", "--for", f"{seconds:g}s", "--clock", clock,
           "--stats-json", str(stats_path)]
    env = dict(os.environ, CHIMERA_LOG_DIR=str(work))
    err_path = work / "stderr.txt"
    samples = []  # (wall seconds since start, kB)
    t0 = time.monotonic()
    with open(err_path, "w") as err:
        proc = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=err, env=env)
        next_sample = 0.0
        while proc.poll() is None:
            now = time.monotonic() - t0
            if now >= next_sample:
                kb = rss_kb(proc.pid)
                if kb is not None:
                    samples.append((round(now, 3), kb))
                next_sample += sample_s
            time.sleep(min(0.05, sample_s / 4))
    wall_s = time.monotonic() - t0
    stderr = err_path.read_text()
    last_line = stderr.strip().splitlines()[-1] if stderr.strip() else ""
    stats = json.loads(stats_path.read_text()) if stats_path.exists() else {"tasks": {}}
    tasks = {name: {"cycles": t["cycles"], "missed": t["missed"], "state": t["state"]}
             for name, t in stats["tasks"].items()}

    logger_cycles = tasks.get(LOG_TASK, {}).get("cycles")
    rows = data_rows(work / "fig4.csv")
    lost_rows = None if logger_cycles is None or rows is None else logger_cycles - rows

    # The first sample after a tenth of the run (of wall time) is the baseline.
    settle = wall_s / 10
    settled = [s for s in samples if s[0] >= settle] or samples
    growth_kb = settled[-1][1] - settled[0][1] if settled else None
    return {
        "command": " ".join(["chimera"] + cmd[1:]),
        "clock": clock, "simulated_or_real_s": seconds, "wall_s": round(wall_s, 1), "exit_code": proc.returncode,
        "last_stderr_line": last_line, "sample_every_s": sample_s, "rss_kb_samples": samples,
        "rss_kb_first_settled": settled[0][1] if settled else None, "rss_kb_last": settled[-1][1] if settled else None,
        "memory_growth_kb": growth_kb, "logger_cycles": logger_cycles, "logger_rows": rows, "lost_rows": lost_rows,
        "missed_deadlines": sum(t["missed"] for t in tasks.values()), "tasks": tasks,
        "machine": f"{platform.node()}, {os.cpu_count()} CPUs, {platform.release()}",
    }


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("chimera", type=Path)
    p.add_argument("--seconds", type=float, default=float(os.environ.get("SOAK_SECONDS", 3600)))
    p.add_argument("--sample", type=float, default=60.0, help="seconds of wall time between memory samples")
    p.add_argument("--clock", choices=["real", "virtual"], default="real")
    p.add_argument("--json", type=Path, help="write the result here")
    p.add_argument("--max-growth-kb", type=int, default=1024)
    p.add_argument("--note", default="", help="what else the machine did meanwhile, for the report")
    args = p.parse_args()

    # The commit when it starts: the tree may move on during an hour's run.
    commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True, text=True)
    with tempfile.TemporaryDirectory(prefix="chimera-soak-") as tmp:
        r = soak(args.chimera.resolve(), args.seconds, args.sample, args.clock, Path(tmp))
    r["max_growth_kb"] = args.max_growth_kb
    r["note"] = args.note
    r["date"] = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    r["commit"] = commit.stdout.strip() if commit.returncode == 0 else None
    problems = []
    if r["exit_code"] != 0:
        problems.append(f"the run ended with {r['exit_code']}: {r['last_stderr_line']}")
    if r["lost_rows"] is None:
        problems.append("the logger's rows could not be counted (no fig4.csv, or no logger in --stats-json)")
    elif r["lost_rows"] != 0:
        problems.append(f"{r['lost_rows']} rows lost ({r['logger_rows']} in the file, {r['logger_cycles']} logger cycles)")
    if len(r["rss_kb_samples"]) < 3:
        problems.append(f"only {len(r['rss_kb_samples'])} memory samples: the run was too short to judge growth")
    elif r["memory_growth_kb"] > args.max_growth_kb:
        problems.append(f"memory grew by {r['memory_growth_kb']} kB (at most {args.max_growth_kb} kB)")
    r["problems"] = problems
    if args.json:
        args.json.write_text(json.dumps(r, indent=2) + "\n")

    print(f"soak: {r['command']}")
    print(f"  {r['clock']} clock, {r['simulated_or_real_s']:g} s of Figure 4 in {r['wall_s']:g} s of wall time, "
          f"exit {r['exit_code']}; {r['machine']}")
    print(f"  memory: {len(r['rss_kb_samples'])} samples every {r['sample_every_s']:g} s, "
          f"{r['rss_kb_first_settled']} kB settled -> {r['rss_kb_last']} kB, growth {r['memory_growth_kb']} kB")
    print(f"  logger: {r['logger_rows']} rows for {r['logger_cycles']} cycles, lost {r['lost_rows']}")
    for name, t in sorted(r["tasks"].items()):
        print(f"  {name}: {t['cycles']} cycles, {t['missed']} missed, {t['state']}")
    for problem in problems:
        print(f"soak: FAILED: {problem}", file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
