"""Windows of one run, quiet and loaded by turns: how network_api and dds_bridge measure what a
load costs the real-time tasks.

On this VM the noise moves tenfold within a minute (one run's p99 0.1 to 8 ms seen with nothing
added), so runs one after the other compare different machines; windows a second apart, in one
run of one subsystem, meet the same one. Each window's figures are the difference of two `stats`
replies taken around it: per task the cycles, the misses and the release latency histogram
counted within it.

The order is quiet-loaded, loaded-quiet, ... so that a drift of the machine's noise during the
run weighs on both alike. The control splits the quiet windows into the even and the odd pairs'
and compares them as the two modes are compared: two samples of the same thing, so its distance
from 1.00 is the method's own error in this run.
"""

import collections
import json
import os
import re
import subprocess
import time
import urllib.request
from pathlib import Path


class ServedRun:
    """chimera run FILE --listen 127.0.0.1:0 --for SECONDS --stats-json, its link read from stderr."""

    def __init__(self, chimera, yaml, seconds, ctx, name, env=None):
        self.stats = ctx.work / f"network_{name}.json"
        self.err = open(ctx.work / f"network_{name}.stderr", "w+")
        env = dict(env or os.environ, CHIMERA_LOG_DIR=str(ctx.work))
        self.proc = subprocess.Popen([str(chimera), "run", str(yaml), "--listen", "127.0.0.1:0", "--for", f"{seconds}s",
                                      "--stats-json", str(self.stats)], stdin=subprocess.PIPE, stdout=subprocess.DEVNULL,
                                     stderr=self.err, env=env)
        deadline = time.time() + 20
        self.base = self.token = None
        while time.time() < deadline and self.base is None:
            time.sleep(0.1)
            self.err.seek(0)
            m = re.search(r"Onika, the page, on (http://\S+/)#token=(\w+)", self.err.read())
            if m:
                self.base, self.token = m.group(1), m.group(2)
        if self.base is None:
            self.proc.kill()
            raise RuntimeError(f"chimera printed no link: see {self.err.name}")

    def ordinary_cpus(self):
        """The CPUs chimera keeps its ordinary threads on (its main thread's, after start): those no
        real-time task of it runs on, or every usable one when each has one."""
        return os.sched_getaffinity(self.proc.pid)

    def beside(self):
        """For subprocess: a client of this run started on its ordinary CPUs, as a browser on
        another machine stands apart from its real-time tasks."""
        cpus = self.ordinary_cpus()
        return {"preexec_fn": lambda: os.sched_setaffinity(0, cpus)}

    def rss_kb(self):
        try:
            m = re.search(r"^VmRSS:\s+(\d+) kB", Path(f"/proc/{self.proc.pid}/status").read_text(), re.M)
        except OSError:
            return 0
        return int(m.group(1)) if m else 0

    def command(self, text):
        """One command of the control API (docs/control-api.md), its JSON reply."""
        req = urllib.request.Request(f"{self.base}api/command", data=json.dumps({"command": text}).encode(),
                                     headers={"Authorization": f"Bearer {self.token}",
                                              "Content-Type": "application/json"}, method="POST")
        with urllib.request.urlopen(req, timeout=10) as reply:
            return json.loads(reply.read())

    def figures(self, tasks):
        """Per task its cumulative cycles, misses and release latency histogram (bound -> count)."""
        stats = self.command("stats")["stats"]["tasks"]
        return {t: {"cycles": stats[t]["cycles"], "missed": stats[t]["missed"],
                    "latency": {int(b): n for b, n in stats[t]["histograms"]["latency_ns"]}} for t in tasks}

    def finish(self, timeout_s):
        self.proc.wait(timeout=timeout_s)
        return json.loads(self.stats.read_text())


def between(before, after):
    """What happened between two `figures`: per task the cycles, misses and latency histogram."""
    out = {}
    for t, a in after.items():
        b = before[t]
        hist = sorted((bound, n - b["latency"].get(bound, 0)) for bound, n in a["latency"].items()
                      if n > b["latency"].get(bound, 0))
        out[t] = {"cycles": a["cycles"] - b["cycles"], "missed": a["missed"] - b["missed"], "latency_histogram": hist}
    return out


def merged(windows, tasks, keep):
    """Per task the histogram, cycles and misses of every window for which keep(index, window)."""
    out = {}
    for t in tasks:
        hist = collections.Counter()
        cycles = missed = 0
        for i, w in enumerate(windows):
            if not keep(i, w):
                continue
            hist.update({b: n for b, n in w["tasks"][t]["latency_histogram"]})
            cycles += w["tasks"][t]["cycles"]
            missed += w["tasks"][t]["missed"]
        out[t] = {"histogram": sorted(hist.items()), "cycles": cycles, "missed": missed}
    return out


def p99(histogram):
    """The upper bound of the bucket that holds the 99th percentile."""
    total = sum(n for _, n in histogram)
    seen = 0
    for bound, n in histogram:
        seen += n
        if seen >= 0.99 * total:
            return bound
    return 0


def compare(windows, tasks, quiet, loaded):
    """The two modes' p99 per task, their ratios, the cycles and misses behind them, and the control.

    Windows come in pairs (two a pair, in order); `quiet` and `loaded` name the modes' kinds."""
    per_mode = {m: merged(windows, tasks, lambda i, w, m=m: w["kind"] == m) for m in (quiet, loaded)}
    p99s = {m: {t: p99(per_mode[m][t]["histogram"]) for t in tasks} for m in per_mode}
    ratios = {t: p99s[loaded][t] / p99s[quiet][t] for t in tasks if p99s[quiet][t] > 0}
    halves = [merged(windows, tasks, lambda i, w, h=h: w["kind"] == quiet and (i // 2) % 2 == h) for h in (0, 1)]
    control = {t: p99(halves[1][t]["histogram"]) / p99(halves[0][t]["histogram"]) for t in tasks
               if p99(halves[0][t]["histogram"]) > 0}
    work = {m: {t: {k: per_mode[m][t][k] for k in ("cycles", "missed")} for t in tasks} for m in per_mode}
    per_window = [{"kind": w["kind"], "p99_ns": {t: p99(w["tasks"][t]["latency_histogram"]) for t in tasks},
                   "missed": {t: w["tasks"][t]["missed"] for t in tasks}} for w in windows]
    return {"p99_ns": p99s, "ratios": ratios, "control_ratios": control,
            "control_worst": max(control.values(), key=lambda r: max(r, 1 / r)) if control else None,
            "cycles_and_missed": work, "windows": per_window}
