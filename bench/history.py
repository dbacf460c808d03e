"""The figures of every full `make bench` run, one JSON line each (bench/results/history.jsonl).

A single run's figure on a shared VM says little of the next run's: the report puts beside each
key its lowest and highest value over the full runs recorded, so that a reader sees how far a
figure moves from run to run (issue 12). Quick runs and runs of some programs only (`--only`)
are never recorded: their figures are of shorter or partial work.

The first lines were taken from the full runs committed before the file existed (the history of
bench/results/latest.json in git); every full run since appends its own.
"""

import json
from pathlib import Path

import goals


def entry_of(doc):
    """What a run's document contributes: when, which code, on what, and every key it measured."""
    m = doc.get("machine", {})
    return {
        "date": doc.get("date"), "commit": doc.get("commit"),
        "machine": {k: m.get(k) for k in ("cpu_model", "cpus_online", "kernel", "clocksource",
                                          "load_average_before")},
        "keys": {k: doc[k] for k in goals.KEY_NAMES if isinstance(doc.get(k), (int, float))},
    }


def read(results_dir):
    path = Path(results_dir) / "history.jsonl"
    if not path.exists():
        return []
    return [json.loads(line) for line in path.read_text().splitlines() if line.strip()]


def append(doc, results_dir):
    """Records a full run (once: a run already recorded, same date and commit, is not repeated)."""
    if doc.get("mode") != "full":
        return
    entry = entry_of(doc)
    runs = read(results_dir)
    if any(r.get("date") == entry["date"] and r.get("commit") == entry["commit"] for r in runs):
        return
    with open(Path(results_dir) / "history.jsonl", "a") as out:
        out.write(json.dumps(entry, sort_keys=True) + "\n")


def spread(runs, key):
    """(lowest, highest, how many runs measured it) over the recorded runs, or None."""
    values = [r["keys"][key] for r in runs if key in r.get("keys", {})]
    if not values:
        return None
    return min(values), max(values), len(values)
