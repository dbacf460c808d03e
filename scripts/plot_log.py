#!/usr/bin/env python3
"""Plots a Chimera data log: the CSV file a data_logger task writes (header t,name[0],name[1],...).

One panel per variable against time t, one line per element. A desired/measured pair, NAME_d
and NAME_m of the same size (theta_d and theta_m, x_d and x_m), shares a panel (desired dashed,
measured solid, one colour per element) and gets a panel of its error, max_i |NAME_d[i] -
NAME_m[i]|, below. `chimera plot LOG.csv -o LOG.png` runs this script; so can you:

    plot_log.py LOG.csv -o LOG.png [--vars theta_d,theta_m] [--title TEXT]

A file that cannot be read as a log is one message naming the file and the line, exit code 2.
"""
import argparse
import csv
import math
import os
import re
import sys

COLUMN = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)(?:\[(\d+)\])?$")
MAX_LEGEND = 10


class LogError(Exception):
    """A problem with the log, worded for the user."""


def read_log(path):
    """Returns (times, variables): variables maps a name to a list of columns (lists of floats)."""
    try:
        handle = open(path, newline="", encoding="utf-8")
    except OSError as e:
        raise LogError(f"{path}: cannot open the file ({e.strerror})") from e
    with handle:
        rows = csv.reader(handle)
        header = next(rows, None)
        if not header:
            raise LogError(f"{path}:1: the file is empty (a data_logger log starts with a header t,...)")
        if header[0] != "t":
            raise LogError(f"{path}:1: the first column is '{header[0]}', not t (is this a data_logger log?)")
        names = []  # (variable, element) for each column after t
        for column in header[1:]:
            m = COLUMN.match(column)
            if not m:
                raise LogError(f"{path}:1: '{column}' is not a column name (name or name[i])")
            names.append((m.group(1), int(m.group(2) or 0)))
        times = []
        columns = [[] for _ in names]
        for line, row in enumerate(rows, start=2):
            if not row:
                continue
            if len(row) != len(header):
                raise LogError(f"{path}:{line}: {len(row)} values, but the header has {len(header)} columns")
            for i, cell in enumerate(row):
                try:
                    value = float(cell)
                except ValueError:
                    raise LogError(f"{path}:{line}: column {header[i]}: '{cell}' is not a number") from None
                if i == 0:
                    times.append(value)
                else:
                    columns[i - 1].append(value)
    if not times:
        raise LogError(f"{path}: the log has a header but no rows to plot")
    variables = {}
    for (name, _), column in zip(names, columns):
        variables.setdefault(name, []).append(column)
    return times, variables


def panels_of(variables):
    """The panels in header order: ("pair", base, desired, measured) or ("one", name)."""
    panels = []
    paired = set()
    for name in variables:
        if name in paired:
            continue
        if name.endswith("_d") or name.endswith("_m"):
            base = name[:-2]
            desired, measured = base + "_d", base + "_m"
            if (desired in variables and measured in variables
                    and len(variables[desired]) == len(variables[measured])):
                panels.append(("pair", base, desired, measured))
                paired.update((desired, measured))
                continue
        panels.append(("one", name))
    return panels


def plot(path, output, chosen, title):
    try:
        import matplotlib
    except ImportError:
        raise LogError("chimera plot needs matplotlib for python3 (on Debian: apt-get install python3-matplotlib)")
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    times, variables = read_log(path)
    if chosen:
        unknown = [v for v in chosen if v not in variables]
        if unknown:
            raise LogError(f"{path}: no variable '{unknown[0]}' in the log (variables: {', '.join(variables)})")
        variables = {v: variables[v] for v in chosen}
    panels = panels_of(variables)
    heights = []
    for p in panels:
        heights += [3.0, 1.4] if p[0] == "pair" else [1.8]
    fig, axes = plt.subplots(len(heights), 1, figsize=(9, 1.2 + 1.6 * sum(heights) / 1.8), sharex=True,
                             height_ratios=heights, squeeze=False)
    axes = [a[0] for a in axes]
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    at = 0
    for p in panels:
        ax = axes[at]
        if p[0] == "pair":
            _, base, desired, measured = p
            d, m = variables[desired], variables[measured]
            for i, (dc, mc) in enumerate(zip(d, m)):
                c = colors[i % len(colors)]
                ax.plot(times, dc, "--", color=c, linewidth=1)
                ax.plot(times, mc, "-", color=c, linewidth=1.5, label=f"[{i}]" if len(d) <= MAX_LEGEND else None)
            ax.set_ylabel(f"{desired} (dashed)\n{measured} (solid)")
            if len(d) <= MAX_LEGEND:
                ax.legend(ncol=min(len(d), 6), fontsize=7, loc="upper right")
            error = [max(abs(dc[k] - mc[k]) for dc, mc in zip(d, m)) for k in range(len(times))]
            axes[at + 1].plot(times, error, color="black", linewidth=1)
            axes[at + 1].set_ylabel(f"max |{desired} - {measured}|")
            at += 2
        else:
            _, name = p
            elements = variables[name]
            for i, column in enumerate(elements):
                label = (f"[{i}]" if len(elements) > 1 else None) if len(elements) <= MAX_LEGEND else None
                ax.plot(times, column, color=colors[i % len(colors)], linewidth=1.2, label=label)
            ax.set_ylabel(name)
            if 1 < len(elements) <= MAX_LEGEND:
                ax.legend(ncol=min(len(elements), 6), fontsize=7, loc="upper right")
            at += 1
    for ax in axes:
        ax.grid(True, linewidth=0.3)
    axes[-1].set_xlabel("t (s)")
    axes[0].set_title(title or os.path.basename(path))
    fig.tight_layout()
    try:
        fig.savefig(output, dpi=110)
    except OSError as e:
        raise LogError(f"{output}: cannot write the picture ({e.strerror})") from e
    nan_only = [n for n, cols in variables.items() if all(math.isnan(v) for c in cols for v in c)]
    return nan_only


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("log", help="a CSV file written by a data_logger task")
    p.add_argument("-o", "--output", help="the picture (PNG, or any format matplotlib knows by the name's ending); "
                                          "default: the log's name with .png")
    p.add_argument("--vars", default="", help="plot only these variables, comma-separated")
    p.add_argument("--title", default="", help="the title (default: the log's file name)")
    a = p.parse_args()
    output = a.output or (os.path.splitext(a.log)[0] + ".png")
    chosen = [v for v in a.vars.split(",") if v]
    try:
        empty = plot(a.log, output, chosen, a.title)
    except LogError as e:
        print(f"chimera plot: {e}", file=sys.stderr)
        return 2
    for name in empty:
        print(f"chimera plot: {a.log}: {name} has no data in the whole log (nan)", file=sys.stderr)
    print(output)
    return 0


if __name__ == "__main__":
    sys.exit(main())
