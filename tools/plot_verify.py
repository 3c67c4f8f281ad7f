#!/usr/bin/python3
"""Plots of `weft verify`: beta / pi against the view zenith, one panel per incidence and channel.

Usage: plot_verify.py INPLANE.csv METRICS.json OUT_DIR

Reads the long-form inplane.csv of `weft verify` (theta_i_deg, view_zenith_deg, model, channel,
beta, beta_err, beta_norm, norm_factor; view > 0 on the mirror side, the paper's Fig. 7) and
writes OUT_DIR/inplane-normalized.{png,svg} (the paper's normalization, each model's factor
printed on every panel) and OUT_DIR/inplane-absolute.{png,svg}. Error bars: one standard error
(beta_err). Run with /usr/bin/python3 (weft does): only it is known to have matplotlib.
"""
import csv
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

STYLE = {
    "measured": dict(color="black", linestyle="--", marker="", label="measured"),
    "computed_raytrace": dict(color="tab:red", linestyle="-", marker="o", markersize=2.5),
    "computed_summation": dict(color="tab:orange", linestyle=":", marker=""),
    "classic": dict(color="tab:blue", linestyle="-.", marker="s", markersize=2.5),
    # weft verify --fit: the fitted parameters at the run's quality, thinner and lighter.
    "computed_raytrace_fitted": dict(color="salmon", linestyle="-", marker="", alpha=0.8),
    "classic_fitted": dict(color="lightskyblue", linestyle="-.", marker="", alpha=0.8),
}
SHORT = {"computed_raytrace": "ray trace", "computed_summation": "summation",
         "classic": "classic", "computed_raytrace_fitted": "ray trace fitted",
         "classic_fitted": "classic fitted"}


def main():
    if len(sys.argv) != 4:
        sys.exit("usage: plot_verify.py INPLANE.csv METRICS.json OUT_DIR")
    src, metrics_path, out_dir = sys.argv[1:]
    with open(src, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"plot_verify: {src}: no rows")
    with open(metrics_path) as f:
        metrics = json.load(f)
    labels = {k: v["label"] for k, v in metrics["models"].items()}
    labels["measured"] = "measured"
    incidences = sorted({float(r["theta_i_deg"]) for r in rows})
    channels = ["R", "G", "B"]
    models = []
    for r in rows:
        if r["model"] not in models:
            models.append(r["model"])
    data = {}
    for r in rows:
        key = (float(r["theta_i_deg"]), r["model"], r["channel"])
        data.setdefault(key, []).append(
            (float(r["view_zenith_deg"]), float(r["beta"]), float(r["beta_err"]),
             float(r["beta_norm"]), float(r["norm_factor"])))

    for kind in ("normalized", "absolute"):
        fig, axes = plt.subplots(len(incidences), 3, figsize=(13, 2.9 * len(incidences)),
                                 squeeze=False, sharex=True)
        for i, ti in enumerate(incidences):
            for c, ch in enumerate(channels):
                ax = axes[i][c]
                factors = []
                for m in models:
                    pts = sorted(data.get((ti, m, ch), []))
                    if not pts:
                        continue
                    x = [p[0] for p in pts]
                    norm = kind == "normalized"
                    scale = [p[4] if norm else 1.0 for p in pts]
                    y = [(p[3] if norm else p[1]) / math.pi for p in pts]
                    err = [p[2] * s / math.pi for p, s in zip(pts, scale)]
                    style = dict(STYLE.get(m, {}))
                    style["label"] = labels.get(m, m)
                    if any(e > 0 for e in err):
                        ax.errorbar(x, y, yerr=err, capsize=1.5, linewidth=1, elinewidth=0.7,
                                    **style)
                    else:
                        ax.plot(x, y, linewidth=1, **style)
                    if norm and m != "measured":
                        factors.append(f"{SHORT.get(m, m)}: x{pts[0][4]:.3g}")
                ax.set_title(f"light {ti:g} deg, {ch} channel", fontsize=9)
                ax.grid(alpha=0.3)
                ax.set_xlim(-90, 90)
                ax.axvline(ti, color="grey", linewidth=0.5)
                if factors:
                    ax.text(0.02, 0.97, "normalization\n" + "\n".join(factors),
                            transform=ax.transAxes, fontsize=6, va="top",
                            bbox=dict(facecolor="white", alpha=0.7, linewidth=0))
                ax.legend(fontsize=6, loc="upper right")
                if c == 0:
                    ax.set_ylabel("beta / pi" + (" (normalized)" if kind == "normalized" else ""))
                if i == len(incidences) - 1:
                    ax.set_xlabel("view zenith (deg; > 0 on the mirror side)")
        title = ("paper's normalization: each model scaled per channel to the measurement at "
                 "normal incidence and view" if kind == "normalized" else "absolute beta / pi")
        fig.suptitle(title, fontsize=10)
        fig.tight_layout(rect=(0, 0, 1, 0.985))  # room for the title above the first row
        for ext in ("png", "svg"):
            fig.savefig(os.path.join(out_dir, f"inplane-{kind}.{ext}"), dpi=80)
        plt.close(fig)


if __name__ == "__main__":
    main()
