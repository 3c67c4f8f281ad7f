#!/usr/bin/python3
"""In-plane curves of two BSDF tables: the radiance coefficient beta = pi f against the view angle
(positive on the mirror side), one panel per incidence and plane, channels averaged.

Reads the CSV of `weft compare --csv` (columns light_zenith_deg, plane_azimuth_deg,
view_zenith_deg, a_<channel>..., b_<channel>...) and writes a PNG (or SVG, by extension).
"""
import csv
import os
import signal
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def save_whole(fig, out):
    """The figure at 'out' whole or not at all: drawn beside it, then moved in. weft ends the
    script with SIGTERM on Ctrl-C (main turns that into SystemExit, so the draft is removed)."""
    draft = f"{out}.tmp-{os.getpid()}{os.path.splitext(out)[1]}"
    try:
        fig.savefig(draft)
        os.replace(draft, out)
    finally:
        if os.path.exists(draft):
            os.remove(draft)


def main():
    signal.signal(signal.SIGTERM, lambda signum, frame: sys.exit(128 + signum))
    if len(sys.argv) != 5:
        sys.exit("usage: plot_compare.py CURVES.csv OUT.png LABEL_A LABEL_B")
    src, out, label_a, label_b = sys.argv[1:]
    with open(src, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"plot_compare: {src}: no rows")
    a_cols = [k for k in rows[0] if k.startswith("a_")]
    b_cols = [k for k in rows[0] if k.startswith("b_")]
    panels = sorted({(float(r["light_zenith_deg"]), float(r["plane_azimuth_deg"])) for r in rows})
    lights = sorted({p[0] for p in panels})
    planes = sorted({p[1] for p in panels})
    fig, axes = plt.subplots(len(planes), len(lights), figsize=(4 * len(lights), 3.2 * len(planes)),
                             squeeze=False)
    for (light, plane) in panels:
        ax = axes[planes.index(plane)][lights.index(light)]
        pts = [r for r in rows if float(r["light_zenith_deg"]) == light
               and float(r["plane_azimuth_deg"]) == plane]
        x = [float(r["view_zenith_deg"]) for r in pts]
        ya = [sum(float(r[c]) for c in a_cols) / len(a_cols) / 3.141592653589793 for r in pts]
        yb = [sum(float(r[c]) for c in b_cols) / len(b_cols) / 3.141592653589793 for r in pts]
        ax.plot(x, ya, "-", label=label_a)
        ax.plot(x, yb, "--", label=label_b)
        name = "warp plane" if plane == 0 else ("weft plane" if plane == 90 else f"azimuth {plane:g}")
        ax.set_title(f"light {light:g} deg, {name}")
        ax.set_xlabel("view zenith (deg, + = mirror side)")
        ax.set_ylabel("beta / pi")
        ax.legend(fontsize=8)
    fig.tight_layout()
    save_whole(fig, out)


if __name__ == "__main__":
    main()
