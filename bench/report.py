"""Writes the benchmark report (latest.md) and its plots (PNG) from run.py's results.

Called by bench/run.py; `bench/report.py RESULTS.json` rewrites the report of a saved run
(without the distribution plots, whose samples live in the build tree).
"""

import json
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
import analysis  # noqa: E402
import goals  # noqa: E402
import history  # noqa: E402

COLOURS = {"chimera": "#1f6fb4", "mutex": "#d62728", "iceoryx": "#2ca02c", "dds": "#9467bd",
           "cyclictest": "#ff7f0e"}


def load_samples(path):
    try:
        return np.fromfile(path, dtype="<u4").astype(np.float64)
    except OSError:
        return None


def distribution_plot(series, title, out_path, unit_ns=1.0, unit="ns", bins_per_decade=40, linear_bin=None):
    """Left: histogram on a log axis (or in linear bins of `linear_bin` units, for data that is
    already binned, such as cyclictest's 1 µs); right: the share of samples above x (CCDF), log-log."""
    fig, (ax_h, ax_c) = plt.subplots(1, 2, figsize=(11, 4.2))
    values = [v / unit_ns for _, v, _ in series if v is not None and len(v)]
    if not values:
        plt.close(fig)
        return False
    lo = max(min(float(np.min(v)) for v in values), 1.0 / unit_ns if unit_ns > 1 else 1.0)
    hi = max(float(np.max(v)) for v in values)
    if linear_bin:
        top = max(float(np.percentile(v, 99.9)) for v in values) * 1.5
        edges = np.arange(np.floor(lo), np.ceil(min(hi, top)) + linear_bin, linear_bin)
    else:
        edges = np.logspace(np.log10(lo * 0.9), np.log10(hi * 1.1), int(bins_per_decade * np.log10(hi * 1.2 / lo)) + 2)
    for label, v, colour in series:
        if v is None or not len(v):
            continue
        x = np.maximum(v / unit_ns, lo)
        ax_h.hist(x, bins=edges, histtype="step", color=colour, label=label, density=False, linewidth=1.3)
        xs = np.sort(x)
        ccdf = 1.0 - np.arange(1, len(xs) + 1) / len(xs)
        ax_c.step(xs, np.maximum(ccdf, 0.5 / len(xs)), where="post", color=colour, label=label, linewidth=1.3)
        p99 = np.percentile(x, 99)
        ax_c.axvline(p99, color=colour, linestyle=":", linewidth=0.9)
    if not linear_bin:
        ax_h.set_xscale("log")
    ax_h.set_yscale("log")
    ax_h.set_xlabel(f"latency ({unit})")
    ax_h.set_ylabel("samples per bin")
    ax_h.set_title("distribution" + (f" ({linear_bin:g} {unit} bins, to 1.5x p99.9)" if linear_bin else ""))
    ax_c.set_xscale("log")
    ax_c.set_yscale("log")
    ax_c.set_xlabel(f"latency ({unit})")
    ax_c.set_ylabel("share of samples above")
    ax_c.set_title("tail (dotted: p99)")
    for ax in (ax_h, ax_c):
        ax.grid(True, which="both", alpha=0.25)
        ax.legend(fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(out_path, dpi=110)
    plt.close(fig)
    return True


def uncontended_plot(doc, out_path):
    sizes = [1, 6, 36, 1024]
    rows = []
    for n in sizes:
        suffix = "" if n == 6 else f"_{n}"
        rows.append([doc.get(f"{k}{suffix}_ns") for k in ("svt_read", "mutex_read", "svt_write", "mutex_write")])
    if all(v is None for r in rows for v in r):
        return False
    fig, ax = plt.subplots(figsize=(9, 3.8))
    width = 0.2
    labels = ["svt read", "mutex read", "svt write", "mutex write"]
    colours = [COLOURS["chimera"], COLOURS["mutex"], "#7fb3e0", "#f08a8b"]
    for j in range(4):
        xs = [i + (j - 1.5) * width for i in range(len(sizes))]
        ys = [r[j] if r[j] is not None else 0 for r in rows]
        ax.bar(xs, ys, width, label=labels[j], color=colours[j])
    ax.set_xticks(range(len(sizes)), [f"{n} double{'s' if n > 1 else ''}" for n in sizes])
    ax.set_yscale("log")
    ax.set_ylabel("ns per operation (CPU time)")
    ax.set_title("Uncontended read and write: state variable vs std::mutex copy")
    ax.grid(True, axis="y", which="both", alpha=0.25)
    ax.legend(fontsize=8, ncol=4)
    fig.tight_layout()
    fig.savefig(out_path, dpi=110)
    plt.close(fig)
    return True


def fmt_value(v, unit):
    if v is None:
        return "absent"
    if unit == "ns":
        return goals._fmt(v, "ns")
    if unit == "x":
        return f"{v:.2f}x" if v < 10 else f"{v:.0f}x"
    if unit == "%":
        return f"{v:.1f} %"
    return f"{v:g}"


def machine_lines(m):
    fifo = {True: "granted", False: "refused", None: "unknown (no chrt)"}[m.get("sched_fifo_granted")]
    return [
        f"- CPU: {m.get('cpu_model')} ({m.get('cpus_online')} CPUs online, {m.get('cpus_usable')} usable; "
        f"virtual machine: {m.get('hypervisor')}), {m.get('memory_gib')} GiB",
        f"- Kernel: {m.get('kernel')}; clocksource {m.get('clocksource')}",
        f"- SCHED_FIFO: {fifo}; RT throttling {m.get('sched_rt_runtime_us')} µs per second",
        f"- Load average before / after: {', '.join(f'{x:.2f}' for x in m.get('load_average_before', []))} / "
        f"{', '.join(f'{x:.2f}' for x in m.get('load_average_after', []))} (after: inflated by the 1,000 "
        f"threads of the 1,000-task benchmark); CPUs busy "
        f"{m.get('cpu_busy_percent_during_run')} % during the run (this run included), steal "
        f"{m.get('steal_percent_during_run')} %",
    ]


def soak_section(results_dir):
    """The last `make soak` (bench/soak.py, soak.json beside this report): its own run, its own date."""
    path = Path(results_dir) / "soak.json"
    if not path.exists():
        return []
    r = json.loads(path.read_text())
    hours = r["simulated_or_real_s"] / 3600
    lines = ["## Soak", "",
             f"The soak (`bench/soak.py`, `make soak`) of {r.get('date', '?')} (commit `{r.get('commit', '?')}`), its own run: "
             f"`{r['command']}`, {hours:.3g} h of Figure 4 on the {r['clock']} clock with its data logger and "
             f"the flight recorder, memory sampled every {r['sample_every_s']:g} s. Machine: {r['machine']}."
             + (f" {r['note']}" if r.get("note") else ""), "",
             "| | |", "|---|---|",
             f"| exit code | {r['exit_code']} |",
             f"| memory (VmRSS) after the first tenth, at the end | {r['rss_kb_first_settled']} kB, {r['rss_kb_last']} kB |",
             f"| memory growth | {r['memory_growth_kb']} kB (at most {r['max_growth_kb']} kB) |",
             f"| logger rows, logger cycles, lost | {r['logger_rows']:,}, {r['logger_cycles']:,}, {r['lost_rows']} |",
             f"| cycles run, deadlines missed | {sum(t['cycles'] for t in r['tasks'].values()):,}, {r['missed_deadlines']:,} |",
             f"| verdict | {'passed' if not r['problems'] else '; '.join(r['problems'])} |", ""]
    return lines


def write_report(doc, samples, results_dir, name="latest"):
    results_dir = Path(results_dir)
    plots = {}
    s = {k: load_samples(v) for k, v in samples.items()}
    if distribution_plot([("state variable", s.get("contended_svt"), COLOURS["chimera"]),
                          ("std::mutex", s.get("contended_mutex"), COLOURS["mutex"])],
                         "Reader latency, 6 doubles, writer hammering from the other core",
                         results_dir / "contended_read.png"):
        plots["contended"] = "contended_read.png"
    if distribution_plot([("Chimera table", s.get("ipc_svt_ipc"), COLOURS["chimera"]),
                          ("iceoryx", s.get("ipc_iceoryx"), COLOURS["iceoryx"]),
                          ("Cyclone DDS (loopback)", s.get("ipc_dds"), COLOURS["dds"])],
                         "Latest value, one process to another (publish to seen), 1 kHz",
                         results_dir / "ipc_latency.png", unit_ns=1e3, unit="µs"):
        plots["ipc"] = "ipc_latency.png"
    if distribution_plot([("Chimera task, 1 kHz", s.get("release_chimera"), COLOURS["chimera"]),
                          ("cyclictest, 1 kHz", s.get("release_cyclictest"), COLOURS["cyclictest"])],
                         "Periodic release latency (release to start of cycle), run side by side",
                         results_dir / "release_latency.png", unit_ns=1e3, unit="µs", linear_bin=1.0):
        plots["release"] = "release_latency.png"
    if uncontended_plot(doc, results_dir / "uncontended.png"):
        plots["uncontended"] = "uncontended.png"
    # Rewriting a saved run's report (no samples): keep the plots that run drew.
    for key, png in (("contended", "contended_read.png"), ("ipc", "ipc_latency.png"),
                     ("release", "release_latency.png")):
        if key not in plots and not samples and (results_dir / png).exists():
            plots[key] = png

    lines = [f"# Chimera benchmarks: {doc['mode']} run of {doc['date']}", ""]
    lines += [f"Commit `{doc.get('commit')}`, `make bench{'-quick' if doc['mode'] == 'quick' else ''}` "
              f"({doc['machine'].get('run_wall_s')} s of measurements). The figures are in "
              f"[{name}.json]({name}.json); this page is written from it by `bench/report.py`.", ""]
    lines += ["**Read ratios, not absolutes.** This is a 2-CPU virtual machine shared with other busy "
              "programs; absolute figures move from run to run by tens of percent. Every comparison "
              "below was measured side by side in this one run, on the same machine, under the same "
              "load, which is what makes the ratios meaningful.", ""]
    lines += ["## Machine", ""] + machine_lines(doc["machine"]) + [""]

    lines += ["## The goals", "", "| goal (developers' guide) | measured | met |", "|---|---|---|"]
    for g in goals.GOALS:
        verdict = g.check(doc)
        measured = g.measured(doc) if verdict is not None else "not measured: " + "; ".join(
            sorted({doc.get("absent", {}).get(k, "absent") for k in g.keys if k not in doc}))
        mark = {True: "**met**", False: "**missed**", None: "—"}[verdict]
        lines.append(f"| {g.text} | {measured} | {mark} |")
    lines.append("")

    lines += analysis.sections(doc, plots)

    lines += soak_section(results_dir)

    runs = history.read(results_dir)
    lines += ["## Every key", "",
              f"Beside each figure, its lowest and highest over the {len(runs)} full runs recorded in "
              "[history.jsonl](history.jsonl) (this one included when it is a full run), each with the "
              "code of its own commit: how far a figure moves from run to run on these shared VMs.", "",
              "| key | value | over the full runs: lowest – highest (runs) | what |", "|---|---|---|---|"]
    for k in goals.KEYS:
        v = doc.get(k.name)
        why = doc.get("absent", {}).get(k.name, "")
        over = history.spread(runs, k.name)
        over_text = f"{fmt_value(over[0], k.unit)} – {fmt_value(over[1], k.unit)} ({over[2]})" if over else "none"
        lines.append(f"| `{k.name}` | {fmt_value(v, k.unit) if v is not None else 'absent: ' + why} | {over_text} "
                     f"| {k.what} |")
    lines.append("")
    lines += ["## Reproducing", "",
              "`make bench` (about 5 minutes: it installs the optional `bench` packages of "
              "`scripts/packages.txt`, builds `build-bench/` in Release, runs every program and rewrites "
              "this report); `make bench-quick` is a short run (under a minute once built) whose report "
              "goes to `build-bench/bench-results/quick/`, leaving this one alone. "
              "`bench/run.py build-bench --only NAME` runs one program; the programs and the keys "
              "they measure are listed in `bench/run.py` and `bench/goals.py`, and `bench/README.md` "
              "says how to add one.", ""]
    md = results_dir / f"{name}.md"
    md.write_text("\n".join(lines))
    return md


if __name__ == "__main__":
    path = Path(sys.argv[1])
    print(write_report(json.loads(path.read_text()), {}, path.parent, path.stem))
