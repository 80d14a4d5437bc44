#!/usr/bin/env python3
"""Plots and fits the scaling study (docs/SCALING.md) from scripts/scaling_study.sh's CSVs.

    python3 -m venv /tmp/plotenv && /tmp/plotenv/bin/pip install matplotlib numpy
    /tmp/plotenv/bin/python scripts/scaling_plot.py DIR [docs/scaling.png]

DIR holds wx.csv, alg2.csv, pair.csv, segment.csv (any may be missing). Prints the fitted
growth exponents (least squares of log time on log size: all points, and the upper half of the
axis) as Markdown, and writes the PNG. Times are CPU seconds (user + system) of single-threaded
runs; memory is the peak resident size.
"""
import csv
import os
import sys

import numpy as np
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def rows(path):
    if not os.path.exists(path):
        return []
    with open(path) as f:
        return list(csv.DictReader(f))


def fit(x, y):
    """Exponent and prefactor of y = c x^e by least squares in log-log."""
    x, y = np.log(np.asarray(x, float)), np.log(np.asarray(y, float))
    e, c = np.polyfit(x, y, 1)
    return e, np.exp(c)


def exponents(x, y):
    """(all points, upper half of the axis) exponents."""
    half = len(x) // 2
    upper = fit(x[half:], y[half:])[0] if len(x) - half >= 2 else float("nan")
    return fit(x, y)[0], upper


def main():
    d = sys.argv[1]
    png = sys.argv[2] if len(sys.argv) > 2 else "docs/scaling.png"
    op = {k: rows(os.path.join(d, f"{k}.csv")) for k in ("wx", "alg2")}
    pair = rows(os.path.join(d, "pair.csv"))
    seg = rows(os.path.join(d, "segment.csv"))

    fig, ax = plt.subplots(2, 3, figsize=(12, 7))
    table = []

    def series(a, x, y, label, style, fit_line=True):
        x, y = np.asarray(x, float), np.asarray(y, float)
        if len(x) == 0:
            return
        e_all, e_up = exponents(x, y)
        a.loglog(x, y, style, label=f"{label} (exp. {e_all:.2f}; upper half {e_up:.2f})")
        if fit_line and len(x) >= 2:
            e, c = fit(x, y)
            a.loglog(x, c * x**e, ":", color="grey", lw=0.8)
        table.append((label, int(x[0]), int(x[-1]), e_all, e_up))

    # W·x and Algorithm 2 along the two axes: the 300-feature rows vary vertices, the
    # 10,000-vertex rows vary features (the point 10,000 × 300 belongs to both).
    def axis(r, key, fixed_key, fixed, value):
        """(size, value) along one axis; the least of repeated points (10,000 × 300 is on both)."""
        best = {}
        for p in r:
            if p[fixed_key] == fixed:
                x = int(p[key])
                best[x] = min(best.get(x, float("inf")), value(p))
        return sorted(best.items())

    cpu = lambda p: float(p["cpu_s"])  # noqa: E731
    for kind, label, style in (("wx", "W·x", "o-"), ("alg2", "Algorithm 2", "s-")):
        r = op[kind]
        by_v = axis(r, "vertices", "features", "300", cpu)
        by_f = axis(r, "features", "vertices", "10000", cpu)
        if by_v:
            series(ax[0, 0], *zip(*by_v), f"{label}, 300 features", style)
        if by_f:
            series(ax[0, 1], *zip(*by_f), f"{label}, 10k vertices", style)
        mem = axis(r, "vertices", "features", "300", lambda p: float(p["hwm_kb"]) / 1024)
        if mem and kind == "wx":
            series(ax[1, 0], *zip(*mem), "W·x: tables + operator", "o-")
    ax[0, 0].set(xlabel="vertices per shape", ylabel="CPU s", title="one W·x / one Algorithm 2 vs vertices")
    ax[0, 1].set(xlabel="features", ylabel="CPU s", title="... vs features")

    if pair:
        v = [(int(p["vertices_a"]) + int(p["vertices_b"])) / 2 for p in pair]
        cpu = [float(p["user_s"]) + float(p["sys_s"]) for p in pair]
        series(ax[0, 2], v, cpu, "pair CPU", "D-")
        series(ax[0, 2], v, [float(p["wall_s"]) for p in pair], "pair wall", "x--")
        series(ax[1, 0], v, [float(p["max_rss_kb"]) / 1024 for p in pair], "pair peak RSS", "D-")
        ax[0, 2].set(xlabel="vertices per shape", ylabel="s", title="coseg pair (defaults, warm, 1 thread)")
    ax[1, 0].set(xlabel="vertices per shape", ylabel="MB", title="peak memory vs vertices")

    if seg:
        n = [int(p["shapes"]) for p in seg]
        cpu = [float(p["user_s"]) + float(p["sys_s"]) for p in seg]
        series(ax[1, 1], n, cpu, "segment CPU", "^-")
        series(ax[1, 1], n, [float(p["wall_s"]) for p in seg], "segment wall", "x--")
        ax[1, 1].set(xlabel="shapes (2.4k-9.5k vertices each)", ylabel="s", title="coseg segment (warm, 1 thread)")
        series(ax[1, 2], n, [float(p["max_rss_kb"]) / 1024 for p in seg], "segment peak RSS", "^-")
        ax[1, 2].set(xlabel="shapes", ylabel="MB", title="coseg segment peak memory")

    for a in ax.flat:
        a.grid(True, which="both", lw=0.3)
        if a.lines:
            a.legend(fontsize=7, loc="lower right")
    fig.suptitle("coseg scaling study (docs/SCALING.md); dotted: log-log least-squares fits", fontsize=10)
    fig.tight_layout()
    fig.savefig(png, dpi=72)

    print_points(op, pair, seg)
    print()
    print("| series | from | to | exponent (all points) | exponent (upper half) |")
    print("|---|---|---|---|---|")
    for label, lo, hi, e_all, e_up in table:
        print(f"| {label} | {lo:,} | {hi:,} | {e_all:.2f} | {e_up:.2f} |")


def print_points(op, pair, seg):
    """The measured points as Markdown tables."""
    # Both CSVs list the same points in the same order (scripts/scaling_study.sh).
    alg2 = op["alg2"] + [None] * (len(op["wx"]) - len(op["alg2"]))
    print("| vertices | features | tables MB | W·x CPU ms | W·x wall ms | W·x peak MB | load | "
          "Alg. 2 CPU s | Alg. 2 wall s | Alg. 2 rounds | Alg. 2 peak MB | load |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for p, a in zip(op["wx"], alg2):
        a_cols = (
            f"{float(a['cpu_s']):.3f} | {float(a['wall_min_s']):.3f} | {a.get('rounds', '')} | "
            f"{float(a['hwm_kb']) / 1024:.0f} | {a['load1']}"
            if a
            else "| | | |"
        )
        print(f"| {int(p['vertices']):,} | {p['features']} | {int(p['table_bytes']) / 1e6:.1f} | "
              f"{float(p['cpu_s']) * 1e3:.2f} | {float(p['wall_min_s']) * 1e3:.2f} | "
              f"{float(p['hwm_kb']) / 1024:.0f} | {p['load1']} | {a_cols} |")
    if pair:
        print()
        print("| vertices A × B | warm wall s | warm CPU s | warm peak MB | cold wall s | "
              "cold peak MB | load |")
        print("|---|---|---|---|---|---|---|")
        for p in pair:
            print(f"| {int(p['vertices_a']):,} × {int(p['vertices_b']):,} | {p['wall_s']} | "
                  f"{float(p['user_s']) + float(p['sys_s']):.2f} | "
                  f"{float(p['max_rss_kb']) / 1024:.0f} | {p['cold_wall_s']} | "
                  f"{float(p['cold_max_rss_kb']) / 1024:.0f} | {p['load1']} |")
    if seg:
        print()
        print("| shapes | vertices (all shapes) | warm wall s | warm CPU s | warm peak MB | load |")
        print("|---|---|---|---|---|---|")
        for p in seg:
            print(f"| {p['shapes']} | {int(p['total_vertices']):,} | {p['wall_s']} | "
                  f"{float(p['user_s']) + float(p['sys_s']):.2f} | "
                  f"{float(p['max_rss_kb']) / 1024:.0f} | {p['load1']} |")


if __name__ == "__main__":
    main()
