#!/usr/bin/env python3
"""Runs every benchmark of a build tree and writes bench/results/latest.json and latest.md.

    bench/run.py BUILD_DIR [--quick] [--results DIR] [--only NAME,...]

Each entry of PROGRAMS is one program and the keys it measures. A program writes a JSON
fragment {"results": {key: number}, "details": {...}, "samples": {name: file}}; Google Benchmark
programs are read through their own JSON. Fragments are merged in order; a program that is
missing (a peer not installed) or fails leaves its keys absent, and the report says why.
Adding a benchmark is one entry here, its keys in goals.py, and its program in CMakeLists.txt.
"""

import argparse
import datetime
import json
import os
import platform
import re
import shutil
import statistics
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Optional

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))
import goals  # noqa: E402
import dds_bridge  # noqa: E402
import windows as win  # noqa: E402
from windows import ServedRun  # noqa: E402
import history  # noqa: E402


@dataclass
class Program:
    name: str
    exe: str                                # in BUILD_DIR/bench, or a path below BUILD_DIR
    what: str
    keys: list
    run: Optional[Callable] = None          # custom runner (build, ctx) -> fragment
    args: list = field(default_factory=list)
    timeout_s: int = 300


# ---- Google Benchmark programs ----------------------------------------------------------------

def run_gbench(exe, ctx, filter_re=None):
    out = ctx.work / f"{Path(exe).name}.gbench.json"
    cmd = [str(exe), f"--benchmark_out={out}", "--benchmark_out_format=json",
           "--benchmark_format=console"]
    if ctx.quick:
        cmd += ["--benchmark_min_time=0.05"]
    else:
        # Five repetitions of 0.2 s; the median holds against the spikes of a shared machine.
        cmd += ["--benchmark_min_time=0.2", "--benchmark_repetitions=5",
                "--benchmark_report_aggregates_only=true"]
    if filter_re:
        cmd.append(f"--benchmark_filter={filter_re}")
    ctx.log(" ".join(cmd))
    subprocess.run(cmd, check=True, stdout=ctx.logfile, stderr=subprocess.STDOUT, timeout=600)
    data = json.loads(out.read_text())
    # CPU time, not wall time: these benchmarks are single-threaded, and CPU time leaves out the
    # time this process spent preempted by others on a shared machine.
    times = {}
    for b in data["benchmarks"]:
        name = b.get("run_name", b["name"])
        if b.get("aggregate_name") not in (None, "median"):
            continue
        if b.get("aggregate_name") is None and b.get("run_type") == "aggregate":
            continue
        scale = {"ns": 1, "us": 1e3, "ms": 1e6, "s": 1e9}[b["time_unit"]]
        if name.endswith("/manual_time"):
            # Timed by the benchmark itself around the part that counts (its CPU time would
            # include the handshake with another thread).
            times[name.removesuffix("/manual_time")] = b["real_time"] * scale
            continue
        times[name] = b["cpu_time"] * scale
    return times, data.get("context", {})


def run_svt_bench(build, ctx):
    times, context = run_gbench(build / "bench" / "svt_bench", ctx)
    res = {}
    for n in (1, 6, 36, 1024):
        suffix = "" if n == 6 else f"_{n}"
        for key, bm in (("svt_read", "BM_SvtReadNew"), ("svt_write", "BM_SvtWrite"),
                        ("mutex_read", "BM_MutexRead"), ("mutex_write", "BM_MutexWrite")):
            name = f"{bm}/{n}"
            if name in times:
                res[f"{key}{suffix}_ns"] = times[name]
    details = {"gbench_cpu_time_ns": times, "library_build_type": context.get("library_build_type")}
    return {"results": res, "details": details}


def run_cycle_bench(build, ctx):
    times, _ = run_gbench(build / "bench" / "cycle_bench", ctx)
    res = {}
    if "BM_PidCycleFramework" in times and "BM_ProducerWrites" in times:
        res["cycle_overhead_ns"] = times["BM_PidCycleFramework"] - times["BM_ProducerWrites"]
    details = {"gbench_cpu_time_ns": times}
    if "BM_PidCycleReal" in times and "BM_ProducerWrites" in times:
        details["pid_joint_cycle_with_framework_ns"] = times["BM_PidCycleReal"] - times["BM_ProducerWrites"]
    if "BM_PidCycleInputsFromOtherCpu" in times:
        # The same cycle with its four inputs just written on the other CPU (its producers there).
        details["cycle_overhead_inputs_from_other_cpu_ns"] = times["BM_PidCycleInputsFromOtherCpu"]
    if "BM_PidCycleRecorded" in times and "BM_PidCycleFramework" in times:
        # What the flight recorder (on by default in chimera run) adds to the framework's cycle.
        details["flight_recorder_cost_ns"] = times["BM_PidCycleRecorded"] - times["BM_PidCycleFramework"]
    return {"results": res, "details": details}


# ---- fragment programs ----------------------------------------------------------------------

def run_fragment(exe, ctx, extra=(), timeout_s=300):
    out = ctx.work / f"{Path(exe).name}.json"
    cmd = [str(exe), "--out", str(out), "--samples-dir", str(ctx.work)] + (["--quick"] if ctx.quick else []) \
        + list(extra)
    ctx.log(" ".join(cmd))
    proc = subprocess.run(cmd, stdout=ctx.logfile, stderr=subprocess.STDOUT, timeout=timeout_s)
    frag = json.loads(out.read_text()) if out.exists() else {}
    if proc.returncode != 0:
        frag.setdefault("details", {})["error"] = f"exit {proc.returncode} (see {ctx.logpath})"
    return frag


# ---- many tasks ------------------------------------------------------------------------------

SCALING_TASKS = (100, 1000, 5000, 10000)


def run_many_tasks(build, ctx):
    """1,000 tasks for the goal, then the scaling table: 100, 5,000 and 10,000 tasks (shorter runs)."""
    exe = build / "bench" / "many_tasks"
    frag = run_fragment(exe, ctx, ["--tasks", "1000"], timeout_s=300)
    rows = {}
    if "error" not in frag.get("details", {}):
        rows[1000] = dict(frag["details"])
    seconds = "3" if ctx.quick else "10"
    for n in SCALING_TASKS:
        if n == 1000:
            continue
        out = ctx.work / f"many_tasks_{n}.json"
        cmd = [str(exe), "--out", str(out), "--tasks", str(n), "--seconds", seconds]
        ctx.log(" ".join(cmd))
        proc = subprocess.run(cmd, stdout=ctx.logfile, stderr=subprocess.STDOUT, timeout=300)
        if proc.returncode == 0 and out.exists():
            rows[n] = json.loads(out.read_text()).get("details", {})
        else:
            rows[n] = {"tasks": n, "error": f"exit {proc.returncode} (see {ctx.logpath})"}
    frag.setdefault("details", {})["scaling"] = [rows[n] for n in SCALING_TASKS if n in rows]
    return frag


# ---- the virtual clock ----------------------------------------------------------------------

def run_virtual_clock(build, ctx):
    chimera = build / "apps" / "chimera" / "chimera"
    fig4 = ROOT / "examples" / "fig4_pid_joint.yaml"
    sim_s = 10 if ctx.quick else 60
    reps = 3

    def wall(seconds):
        cmd = [str(chimera), "run", str(fig4), "--clock", "virtual", "--for", f"{seconds}s"]
        t0 = time.perf_counter()
        subprocess.run(cmd, check=True, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                       stderr=ctx.logfile, timeout=600)
        return time.perf_counter() - t0

    ctx.log(f"{chimera} run {fig4} --clock virtual --for {sim_s}s  (x{reps}, and --for 1s)")
    long_runs = [wall(sim_s) for _ in range(reps)]
    short_runs = [wall(1) for _ in range(reps)]
    t_long = statistics.median(long_runs)
    t_short = statistics.median(short_runs)
    details = {"simulated_s": sim_s, "wall_s_runs": long_runs, "wall_s_1s_runs": short_runs,
               "command": f"chimera run examples/fig4_pid_joint.yaml --clock virtual --for {sim_s}s"}
    if t_long > t_short:
        details["steady_state_speedup"] = (sim_s - 1) / (t_long - t_short)
    return {"results": {"virtual_clock_speedup_fig4": sim_s / t_long}, "details": details}


# ---- the network API (issue 14, section 3) ---------------------------------------------------

EXTRA_TRAJECTORIES = 7  # soft trajectory generators beside Figure 4: 2 variables each, 20 in all


def network_yaml():
    """Figure 4 with 7 more trajectory generators (renamed outputs): 20 variables to stream."""
    text = (ROOT / "examples" / "fig4_pid_joint.yaml").read_text()
    extra = "".join(
        f"  - name: traj{i}\n    module: joint_traj_gen\n    period: 1ms\n    criticality: soft\n"
        f"    rename: {{ theta_d: theta_d_{i}, dtheta_d: dtheta_d_{i} }}\n" for i in range(EXTRA_TRAJECTORIES))
    text = text.replace("configurations:\n", extra + "configurations:\n", 1)
    names = ", ".join(f"traj{i}" for i in range(EXTRA_TRAJECTORIES))
    text = text.replace("pid_control: [traj, pid, robot, monitor, log]", f"pid_control: [traj, pid, robot, monitor, log, {names}]")
    variables = ["theta_d", "dtheta_d", "theta_m", "dtheta_m", "tau_r", "tracking_error"]
    variables += [f"{v}_{i}" for i in range(EXTRA_TRAJECTORIES) for v in ("theta_d", "dtheta_d")]
    return text, variables


# What Onika asks for (onika/js/main.js): the samples in this many frames a second.
ONIKA_BATCH_HZ = 30


def run_network_api(build, ctx):
    chimera = build / "apps" / "chimera" / "chimera"
    node = shutil.which("node")
    if node is None:
        return {"details": {"error": "node not found (scripts/setup-browser.sh installs it)"}}
    load = [node, "--experimental-websocket", str(HERE / "net" / "api_load.mjs")]
    text, variables = network_yaml()
    yaml = ctx.work / "network_fig4.yaml"
    yaml.write_text(text)
    fig4_tasks = ["traj", "pid", "robot"]

    # Without clients and with 10 clients streaming 20 variables at 1 kHz, in one run: windows of
    # two seconds, quiet and streaming by turns (api_load.mjs `windows`), each task's release
    # latency histogram counted within each window (bench/windows.py says why windows).
    window_s, pairs = 2, (3 if ctx.quick else 15)
    run = ServedRun(chimera, yaml, pairs * 2 * (window_s + 2) + 10, ctx, "windows")
    clients_cpus = run.ordinary_cpus()
    cmd = load + ["windows", run.base, run.token, "10", "1000", str(window_s), str(pairs), ",".join(variables),
                  str(ONIKA_BATCH_HZ), ",".join(fig4_tasks)]
    ctx.log(" ".join(cmd[:4] + ["URL", "TOKEN"] + cmd[6:10] + ["..."]))
    try:
        # The clients stand in for browsers on other machines: they run where the server's own
        # ordinary threads do, off the CPU of Figure 4's tasks (docs/scheduling.md, "Ordinary threads").
        out = subprocess.run(cmd, capture_output=True, text=True, timeout=pairs * 2 * (window_s + 10) + 60,
                             **run.beside())
        if out.returncode != 0:
            raise RuntimeError(f"api_load windows: {out.stderr.strip()}")
        windows = json.loads(out.stdout)["windows"]
    except BaseException:
        run.proc.kill()  # not left running to hold the subsystem's name
        raise
    run.proc.stdin.close()
    run.finish(pairs * 2 * (window_s + 2) + 40)

    compared = win.compare(windows, fig4_tasks, "none", "clients")
    none, with_clients = compared["p99_ns"]["none"], compared["p99_ns"]["clients"]
    streams = [w["stream"] for w in windows if w["kind"] == "clients"]

    # The command round trip, and the memory with 100 clients streaming (each a connection and a thread).
    run = ServedRun(chimera, yaml, 20, ctx, "round_trip")
    time.sleep(1)
    out = subprocess.run(load + ["roundtrip", run.base, run.token, "2000"], capture_output=True, text=True, timeout=120,
                         **run.beside())
    if out.returncode != 0:
        raise RuntimeError(f"api_load roundtrip: {out.stderr.strip()}")
    round_trip = json.loads(out.stdout)
    out = subprocess.run(load + ["roundtrip", run.base, run.token, "2000", "keepalive"], capture_output=True, text=True,
                         timeout=120, **run.beside())
    if out.returncode != 0:
        raise RuntimeError(f"api_load roundtrip keepalive: {out.stderr.strip()}")
    kept_alive = json.loads(out.stdout)
    rss_idle = run.rss_kb()
    hold = subprocess.Popen(load + ["stream", run.base, run.token, "100", "10", "6", "theta_m"], stdout=subprocess.PIPE,
                            text=True, **run.beside())
    time.sleep(6)
    rss_held = run.rss_kb()
    held = json.loads(hold.communicate(timeout=60)[0])
    if held["accepted"] < 100:  # the memory of fewer clients is not the figure asked for
        rss_held = None
    run.proc.stdin.close()
    run.finish(40)

    ratios = compared["ratios"]
    # Met only when the work was done: the clients got (nearly) every one of their 1,000 samples a
    # second over the streaming windows; with fewer they measured a lighter load, and the ratio is
    # not reported (it stays in the details).
    clients_seconds = sum(s["accepted"] * s["seconds"] for s in streams)
    delivered = sum(s["samples"] for s in streams) / clients_seconds if clients_seconds > 0 else 0
    least = min((s["samples_per_client_per_s"] for s in streams), default=0)
    reported = ratios if delivered >= 950 and all(s["refused"] == 0 for s in streams) else {}
    results = {"api_stream_latency_p99_ratio": max(reported.values()) if reported else None,
               "api_stream_control_p99_ratio": compared["control_worst"] if reported else None,
               "api_round_trip_ns_p50": round_trip["p50_ns"], "api_round_trip_ns_p99": round_trip["p99_ns"],
               "api_round_trip_keepalive_ns_p50": kept_alive["p50_ns"],
               "api_round_trip_keepalive_ns_p99": kept_alive["p99_ns"],
               "api_memory_100_clients_kb": rss_held}
    details = {"window_s": window_s, "pairs": pairs, "variables": variables, "batch_hz": ONIKA_BATCH_HZ,
               "clients_cpus": sorted(clients_cpus),
               "samples_per_client_per_s": delivered, "samples_per_client_per_s_least_window": least,
               "p99_ns_without_clients": none, "p99_ns_with_clients": with_clients, "ratios": ratios,
               "control_ratios": compared["control_ratios"], "cycles_and_missed": compared["cycles_and_missed"],
               "windows": compared["windows"], "streams": streams,
               "round_trip": round_trip, "round_trip_kept_alive": kept_alive, "rss_kb_idle": rss_idle, "rss_kb_100_clients": rss_held,
               "hold_100_clients": held}
    return {"results": {k: v for k, v in results.items() if v is not None}, "details": details}


PROGRAMS = [
    Program("svt_uncontended", "svt_bench", "state variable vs std::mutex, uncontended (Google Benchmark)",
            [k.name for k in goals.KEYS if re.match(r"(svt|mutex)_(read|write)(_\d+)?_ns$", k.name)],
            run=run_svt_bench),
    Program("svt_contended", "svt_contended", "reader latency under a hammering writer",
            ["svt_read_p99_contended_ns", "mutex_read_p99_contended_ns",
             "svt_read_p50_contended_ns", "mutex_read_p50_contended_ns"]),
    Program("cycle_overhead", "cycle_bench", "framework cost per cycle of the PID task (Google Benchmark)",
            ["cycle_overhead_ns"], run=run_cycle_bench),
    Program("svt_ipc", "svt_ipc", "latest value between processes: Chimera's table",
            ["svt_ipc_latency_ns_p50", "svt_ipc_latency_ns_p99"]),
    Program("iceoryx_ipc", "iceoryx_ipc", "latest value between processes: iceoryx",
            ["iceoryx_latency_ns_p50", "iceoryx_latency_ns_p99"]),
    Program("dds_ipc", "dds_ipc", "latest value between processes: Cyclone DDS",
            ["dds_latency_ns_p50", "dds_latency_ns_p99"]),
    Program("release_latency", "release_latency", "release latency vs cyclictest",
            ["release_latency_ns_p50", "release_latency_ns_p99", "cyclictest_latency_ns_p50",
             "cyclictest_latency_ns_p99", "release_latency_p50_ratio", "release_latency_p99_ratio"]),
    Program("many_tasks", "many_tasks", "1,000 tasks at 100 Hz, and 100 to 10,000",
            ["tasks_1000_at_100hz_cpu_percent", "tasks_1000_cycles_run_percent", "tasks_1000_missed_deadlines",
             "tasks_1000_latency_p99_ns"], run=run_many_tasks, timeout_s=900),
    Program("stall", "stall_bench", "Figure 4's five-task chain after a 40 ms stall of both CPUs",
            ["stall_recovery_periods_max", "stall_tasks_in_error"]),
    Program("virtual_clock", "apps/chimera/chimera", "Figure 4 on the virtual clock",
            ["virtual_clock_speedup_fig4"], run=run_virtual_clock),
    Program("policies", "policy_bench", "rm, edf and muf on the real clock: deadlines missed", []),
    Program("processes", "process_bench", "module processes: the PID in its own process, switches across processes, "
            "a death to ERROR, clear to ON",
            ["process_fig4_latency_p50_ratio", "process_fig4_latency_p99_ratio", "process_pid_cycle_ns",
             "process_pid_cycle_extra_ns", "process_switch_lost_cycles", "process_death_to_error_ns_p50",
             "process_death_to_error_ns_max", "process_death_seen_ns_p50", "process_death_seen_ns_max",
             "process_clear_to_on_ns_p50", "process_clear_to_on_ns_max"]),
    Program("network_api", "apps/chimera/chimera", "the control API under load: 10 clients streaming, round trips, 100 clients",
            ["api_stream_latency_p99_ratio", "api_stream_control_p99_ratio", "api_round_trip_ns_p50", "api_round_trip_ns_p99",
             "api_round_trip_keepalive_ns_p50", "api_round_trip_keepalive_ns_p99", "api_memory_100_clients_kb"],
            run=run_network_api, timeout_s=300),
    Program("dds_bridge", "dds_bridge_ipc", "the DDS bridge: table to table against raw Cyclone DDS; 100 variables "
            "streamed beside Figure 4",
            ["dds_raw_array_latency_ns_p50", "dds_raw_array_latency_ns_p99", "dds_bridge_latency_ns_p50",
             "dds_bridge_latency_ns_p99", "dds_bridge_latency_p50_ratio", "dds_bridge_latency_p99_ratio",
             "dds_stream_latency_p99_ratio", "dds_stream_control_p99_ratio"],
            run=lambda build, ctx: dds_bridge.run(build, ctx, run_fragment), timeout_s=600),
    Program("switch", "switch_bench", "10,000 switches at 1 kHz on the real clock",
            ["switch_lost_cycles", "switch_commit_latency_ns_p50", "switch_commit_latency_ns_p99"],
            timeout_s=600),
]


# ---- the machine ------------------------------------------------------------------------------

def read(path, default=""):
    try:
        return Path(path).read_text().strip()
    except OSError:
        return default


def cpu_times():
    # /proc/stat "cpu" line: user nice system idle iowait irq softirq steal ...
    fields = read("/proc/stat").splitlines()[0].split()[1:]
    return [int(x) for x in fields]


def sched_fifo_granted():
    chrt = shutil.which("chrt")
    if chrt is None:
        return None
    return subprocess.run([chrt, "-f", "10", "true"], capture_output=True).returncode == 0


def machine_before():
    cpuinfo = read("/proc/cpuinfo")
    model = re.search(r"^model name\s*:\s*(.*)$", cpuinfo, re.M)
    mem = re.search(r"^MemTotal:\s*(\d+) kB", read("/proc/meminfo"), re.M)
    uname = platform.uname()
    return {
        "cpu_model": model.group(1) if model else platform.processor(),
        "cpus_online": os.cpu_count(),
        "cpus_usable": len(os.sched_getaffinity(0)),
        "hypervisor": "yes" if re.search(r"^flags\s*:.*\bhypervisor\b", cpuinfo, re.M) else "no",
        "memory_gib": round(int(mem.group(1)) / 2**20, 1) if mem else None,
        "kernel": f"{uname.system} {uname.release} {uname.version}",
        "clocksource": read("/sys/devices/system/clocksource/clocksource0/current_clocksource"),
        "sched_fifo_granted": sched_fifo_granted(),
        "sched_rt_runtime_us": read("/proc/sys/kernel/sched_rt_runtime_us"),
        "load_average_before": list(os.getloadavg()),
    }


def machine_after(m, t0_cpu, wall_s):
    t1 = cpu_times()
    delta = [b - a for a, b in zip(t0_cpu, t1)]
    total = sum(delta) or 1
    idle = delta[3] + delta[4]
    m["load_average_after"] = list(os.getloadavg())
    m["cpu_busy_percent_during_run"] = round(100.0 * (total - idle) / total, 1)
    m["steal_percent_during_run"] = round(100.0 * delta[7] / total, 2) if len(delta) > 7 else None
    m["run_wall_s"] = round(wall_s, 1)
    return m


def git_commit():
    try:
        rev = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True,
                             text=True, check=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(ROOT), "status", "--porcelain", "--", "src", "include", "bench"],
                               capture_output=True, text=True).stdout.strip()
        return rev + ("+changes" if dirty else "")
    except (OSError, subprocess.CalledProcessError):
        return None


# ---- driver -------------------------------------------------------------------------------------

class Context:
    def __init__(self, quick, work):
        self.quick = quick
        self.work = work
        self.logpath = work / "run.log"
        self.logfile = open(self.logpath, "w")

    def log(self, text):
        self.logfile.write(f"$ {text}\n")
        self.logfile.flush()


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("build", type=Path)
    ap.add_argument("--quick", action="store_true", help="short runs (make bench-quick)")
    ap.add_argument("--results", type=Path, default=None,
                    help="where latest.json/.md go (default: bench/results, or BUILD/bench-results/quick "
                         "for --quick, so that a quick run never replaces the committed full report)")
    ap.add_argument("--only", default="", help="comma-separated program names")
    opts = ap.parse_args()

    build = opts.build.resolve()
    work = build / "bench-results"  # samples and raw outputs; only the report goes to results/
    work.mkdir(parents=True, exist_ok=True)
    ctx = Context(opts.quick, work)
    only = {n for n in opts.only.split(",") if n}

    machine = machine_before()
    t0_cpu = cpu_times()
    t0 = time.monotonic()
    merged = {"results": {}, "details": {}, "samples": {}, "absent": {}}
    for p in PROGRAMS:
        if only and p.name not in only:
            continue
        exe = build / "bench" / p.exe if "/" not in p.exe else build / p.exe
        print(f"bench: {p.name:<16} {p.what}", flush=True)
        started = time.monotonic()
        if not exe.exists():
            reason = f"{exe.relative_to(build)} was not built (a package of `scripts/setup.sh bench` is missing?)"
            for k in p.keys:
                merged["absent"][k] = reason
            print(f"bench: {p.name:<16} skipped: {reason}", flush=True)
            continue
        try:
            frag = p.run(build, ctx) if p.run else run_fragment(exe, ctx, p.args, p.timeout_s)
        except (subprocess.SubprocessError, OSError, ValueError, KeyError) as e:
            frag = {"details": {"error": f"{type(e).__name__}: {e} (see {ctx.logpath})"}}
        frag.setdefault("details", {})["seconds"] = round(time.monotonic() - started, 1)
        merged["results"].update(frag.get("results", {}))
        merged["details"][p.name] = frag.get("details", {})
        merged["samples"].update(frag.get("samples", {}))
        for k in p.keys:
            if k not in merged["results"]:
                merged["absent"][k] = frag["details"].get("error", "the program did not report it")
        status = frag["details"].get("error", "ok")
        print(f"bench: {p.name:<16} {frag['details']['seconds']:.0f} s, {status}", flush=True)
    for k in goals.KEYS:
        if k.pending and k.name not in merged["results"]:
            merged["absent"][k.name] = k.pending

    doc = {
        "schema": 1,
        "mode": "quick" if opts.quick else "full",
        "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "commit": git_commit(),
        "machine": machine_after(machine, t0_cpu, time.monotonic() - t0),
    }
    # The keys at the top level, in the table's order; nothing invented for absent ones.
    for k in goals.KEY_NAMES:
        if k in merged["results"]:
            doc[k] = round(merged["results"][k], 4)
    extra = {k: v for k, v in merged["results"].items() if k not in goals.KEY_NAMES}
    doc["absent"] = merged["absent"]
    doc["other_figures"] = extra
    doc["details"] = merged["details"]

    results = opts.results or (work / "quick" if opts.quick or only else HERE / "results")
    results.mkdir(parents=True, exist_ok=True)
    name = "latest"
    json_path = results / f"{name}.json"
    json_path.write_text(json.dumps(doc, indent=2) + "\n")
    if results == HERE / "results" and not only:
        history.append(doc, results)  # a full run into the committed results: recorded
    import report  # noqa: E402  (needs matplotlib; imported late so that a JSON is written anyway)
    md_path = report.write_report(doc, merged["samples"], results, name)
    print(f"bench: wrote {json_path.relative_to(ROOT) if json_path.is_relative_to(ROOT) else json_path} and "
          f"{md_path.relative_to(ROOT) if md_path.is_relative_to(ROOT) else md_path} "
          f"in {time.monotonic() - t0:.0f} s")


if __name__ == "__main__":
    main()
