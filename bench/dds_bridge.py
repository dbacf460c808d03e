"""The DDS bridge in `make bench` (issue 16, item 6), side by side in one run.

1. A variable from one table to another through two bridges, against raw Cyclone DDS pub/sub of
   the very same message (bench/ipc/dds_bridge_ipc.cpp): five pairs of runs of 2,000 messages,
   raw and bridged alternating, and the ratios of the medians of p50 and p99 (goal: within 1.1x).
   One run of each was too few: on this VM one run's p50 moves from 32 to 81 us from one run to
   the next, more than the bridge costs.
2. The real-time tasks' release latency with the bridge streaming 100 variables at 1 kHz to a
   second subsystem, against the same subsystem without exports (goal: p99 at most 1.05x).
   Figure 4 with 47 more trajectory generators (100 variables, every task at 1 kHz) exports all
   of them; an importer, another `chimera run`, imports all 100. Runs with and without alternate,
   five pairs, and the ratio is of the medians, as network_api does: on a shared VM one run's p99
   moves several-fold from run to run.
"""

import json
import os
import re
import statistics
import subprocess
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PAIRS = 5
EXTRA = 47  # 6 variables of Figure 4 and 2 of each generator: 100
FIG4_TASKS = ["traj", "pid", "robot"]
COUNTS = {"theta_d": 6, "dtheta_d": 6, "theta_m": 6, "dtheta_m": 6, "tau_r": 6, "tracking_error": 3}
# Loopback only, unicast discovery (as bench/ipc/dds_ipc.cpp): the VM's own network stays out of it.
CYCLONE_LOOPBACK = ("<CycloneDDS><Domain id=\"any\"><General><Interfaces><NetworkInterface name=\"lo\"/></Interfaces>"
                    "<AllowMulticast>false</AllowMulticast></General><Discovery><ParticipantIndex>auto"
                    "</ParticipantIndex><MaxAutoParticipantIndex>30</MaxAutoParticipantIndex><Peers>"
                    "<Peer address=\"127.0.0.1\"/></Peers></Discovery></Domain></CycloneDDS>")


def exporter_yaml(name, partition, exports):
    text = (ROOT / "examples" / "fig4_pid_joint.yaml").read_text()
    text = re.sub(r"^subsystem: .*$", f"subsystem: {name}", text, count=1, flags=re.M)
    extra = "".join(
        f"  - name: traj{i}\n    module: joint_traj_gen\n    period: 1ms\n    criticality: soft\n"
        f"    rename: {{ theta_d: theta_d_{i}, dtheta_d: dtheta_d_{i} }}\n" for i in range(EXTRA))
    text = text.replace("configurations:\n", extra + "configurations:\n", 1)
    names = ", ".join(f"traj{i}" for i in range(EXTRA))
    text = text.replace("pid_control: [traj, pid, robot, monitor, log]",
                        f"pid_control: [traj, pid, robot, monitor, log, {names}]")
    variables = dict(COUNTS)
    variables.update({f"{v}_{i}": 6 for i in range(EXTRA) for v in ("theta_d", "dtheta_d")})
    if exports:
        text += f"exports: [{', '.join(variables)}]\ndds: {{ partition: {partition} }}\n"
    return text, variables


def importer_yaml(name, partition, variables):
    imports = "".join(f"  {v}: {{ type: f64, count: {n}, max_age: 1s }}\n" for v, n in variables.items())
    return (f"subsystem: {name}\ntasks:\n  - {{name: idle, module: cpu_load, period: 100ms, criticality: soft}}\n"
            f"imports:\n{imports}dds: {{ partition: {partition} }}\n")


def release_p99s(chimera, ctx, seconds, with_bridge, run_id):
    tag = f"{'bridge' if with_bridge else 'none'}_{run_id}"
    partition = f"bench_dds_{os.getpid()}"
    text, variables = exporter_yaml(f"bench_dds_exporter_{os.getpid()}", partition, with_bridge)
    exporter_file = ctx.work / f"dds_exporter_{tag}.yaml"
    exporter_file.write_text(text)
    stats = ctx.work / f"dds_exporter_{tag}.json"
    env = dict(os.environ, CYCLONEDDS_URI=CYCLONE_LOOPBACK, CHIMERA_LOG_DIR=str(ctx.work))
    importer = None
    importer_err = ctx.work / f"dds_importer_{tag}.stderr"
    if with_bridge:
        importer_file = ctx.work / f"dds_importer_{tag}.yaml"
        importer_file.write_text(importer_yaml(f"bench_dds_importer_{os.getpid()}", partition, variables))
        importer = subprocess.Popen([str(chimera), "run", str(importer_file), "--for", f"{seconds + 4}s"],
                                    stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                    stderr=open(importer_err, "w"), env=env)
        time.sleep(1)  # its readers exist before the exporter publishes
    cmd = [str(chimera), "run", str(exporter_file), "--for", f"{seconds}s", "--stats-json", str(stats)]
    ctx.log(" ".join(cmd))
    exporter = subprocess.run(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                              stderr=open(ctx.work / f"dds_exporter_{tag}.stderr", "w"), env=env,
                              timeout=seconds + 60)
    received = None
    if importer is not None:
        importer.wait(timeout=seconds + 60)
        received = len(re.findall(r"dds: import \S+: first sample", importer_err.read_text()))
    if exporter.returncode not in (0, 1):
        raise RuntimeError(f"the exporter's run ended with {exporter.returncode}: see {ctx.work}")
    doc = json.loads(stats.read_text())
    return {t: doc["tasks"][t]["latency_ns"]["p99"] for t in FIG4_TASKS}, \
        {t: doc["tasks"][t]["cycles"] for t in FIG4_TASKS}, {t: doc["tasks"][t]["missed"] for t in FIG4_TASKS}, \
        received, len(variables)


def latency_pairs(build, ctx, run_fragment):
    """Raw and bridged, alternating, PAIRS times (2,000 messages each unless quick); the medians."""
    exe = build / "bench" / "dds_bridge_ipc"
    per_run = {"raw": [], "bridge": []}
    results, details, samples = {}, {}, {}
    for _ in range(1 if ctx.quick else PAIRS):
        for transport in ("raw", "bridge"):
            frag = run_fragment(exe, ctx, [transport] + ([] if ctx.quick else ["--quick"]))
            if "error" in frag.get("details", {}):
                raise RuntimeError(f"dds_bridge_ipc {transport}: {frag['details']['error']}")
            key = "dds_raw_array" if transport == "raw" else "dds_bridge"
            d = frag["details"][key]
            per_run[transport].append({"p50": d["latency_ns"]["p50"], "p99": d["latency_ns"]["p99"],
                                       "seen": d["messages_seen"], "missed": d["messages_missed"]})
            details[key] = d
            samples.update(frag.get("samples", {}))
    for transport, key in (("raw", "dds_raw_array"), ("bridge", "dds_bridge")):
        runs = per_run[transport]
        for q in ("p50", "p99"):
            results[f"{key}_latency_ns_{q}"] = statistics.median(r[q] for r in runs)
        details[key] = dict(details[key], runs=runs, messages_seen_in_all=sum(r["seen"] for r in runs),
                            messages_missed_in_all=sum(r["missed"] for r in runs),
                            figures="the medians over the runs; latency_ns is the last run's")
    for q in ("p50", "p99"):
        results[f"dds_bridge_latency_{q}_ratio"] = \
            results[f"dds_bridge_latency_ns_{q}"] / results[f"dds_raw_array_latency_ns_{q}"]
    return results, details, samples


def run(build, ctx, run_fragment):
    results, details, samples = latency_pairs(build, ctx, run_fragment)

    chimera = build / "apps" / "chimera" / "chimera"
    seconds = 6 if ctx.quick else 12
    runs = {"none": [], "bridge": []}
    cycles, missed, received = {"none": [], "bridge": []}, {"none": [], "bridge": []}, []
    exported = 0
    for i in range(1 if ctx.quick else 5):
        for mode in ("none", "bridge"):
            p99, c, m, got, exported = release_p99s(chimera, ctx, seconds, mode == "bridge", i)
            runs[mode].append(p99)
            cycles[mode].append(c)
            missed[mode].append(m)
            if got is not None:
                received.append(got)

    def median_of(mode):
        return {t: statistics.median(r[t] for r in runs[mode]) for t in FIG4_TASKS}

    none, bridged = median_of("none"), median_of("bridge")
    ratios = {t: bridged[t] / none[t] for t in FIG4_TASKS if none[t] > 0}
    if ratios:
        results["dds_stream_latency_p99_ratio"] = max(ratios.values())
    details["dds_stream"] = {
        "seconds_per_run": seconds, "variables_exported": exported, "rate_hz": 1000,
        "imports_received_per_run": received, "p99_ns_without_bridge": none, "p99_ns_with_bridge": bridged,
        "ratios": ratios, "runs": runs, "cycles": cycles, "missed": missed}
    return {"results": results, "details": details, "samples": samples}
