"""Every run's metrics.json in one table (CSV, a row per case and setting, a column per scalar metric, nested
keys joined by dots) and one figure (SVG: rise, cavity and the viscera's posterior motion per case and
setting). Called by the Snakefile's `gather` rule."""
import csv
import json
import math
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

FIRST = ["case", "setting", "converged", "stop_reason", "pressure_mmhg", "anterior_rise_mm", "cavity_volume_ml",
         "anterior_viscera_posterior_motion_mm", "inverted_tetrahedra", "stage_seconds.total"]
FIGURE = [("anterior_rise_mm", "anterior rise (mm)"), ("cavity_volume_ml", "gas in the cavity (ml)"),
          ("anterior_viscera_posterior_motion_mm", "viscera back (mm)")]


def flatten(d, prefix=""):
    out = {}
    for key, value in d.items():
        name = prefix + key
        if isinstance(value, dict):
            out.update(flatten(value, name + "."))
        elif not isinstance(value, list):
            out[name] = value
    return out


def finite(value):
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def main(paths, cases, settings, table, figure):
    rows = []
    for path, (case, setting) in zip(paths, [(c, s) for c in cases for s in settings]):
        with open(path) as f:
            metrics = flatten(json.load(f))
        if not metrics.get("pipeline_complete", False):
            raise SystemExit(f"gather: {path} is from a run that did not finish (pipeline_complete is not true)")
        rows.append({"case": case, "setting": setting, **metrics})
    columns = [c for c in FIRST if any(c in r for r in rows)]
    columns += sorted({k for r in rows for k in r} - set(columns))
    tmp = table + ".tmp"
    with open(tmp, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=columns, restval="")
        writer.writeheader()
        writer.writerows(rows)
    os.replace(tmp, table)

    fig, axes = plt.subplots(1, len(FIGURE), figsize=(4 * len(FIGURE), 3.6), constrained_layout=True)
    width = 0.8 / max(len(settings), 1)
    for ax, (key, title) in zip(axes, FIGURE):
        for i, setting in enumerate(settings):
            values = [next((r.get(key) for r in rows if r["case"] == c and r["setting"] == setting), None)
                      for c in cases]
            xs = [j + (i - (len(settings) - 1) / 2) * width for j in range(len(cases))]
            ax.bar(xs, [v if finite(v) else 0.0 for v in values], width, label=setting)
        ax.set_xticks(range(len(cases)))
        ax.set_xticklabels(cases, rotation=20)
        ax.set_title(title)
    axes[0].legend(fontsize="small")
    tmp = figure + ".tmp.svg"
    fig.savefig(tmp, format="svg")
    os.replace(tmp, figure)


if __name__ == "__main__" and "snakemake" in globals():
    main(list(snakemake.input), list(snakemake.params.cases), list(snakemake.params.settings),
         snakemake.output.table, snakemake.output.figure)
