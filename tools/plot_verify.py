#!/usr/bin/python3
"""Plots of `weft verify`: beta / pi against the view zenith, one figure per incidence.

Usage: plot_verify.py [--describe LAYOUT.json] [--jobs N] INPLANE.csv METRICS.json OUT_DIR

Reads the long-form inplane.csv of `weft verify` (theta_i_deg, view_zenith_deg, model, channel,
beta, beta_err, beta_norm, norm_factor; view > 0 on the mirror side, the paper's Fig. 7) and
writes OUT_DIR/inplane-<theta_i>deg.{png,svg} (theta_i as 00.0, so the names sort by incidence):
one figure per incidence, one column per channel; the top row with the paper's normalization
(linear axis, each model's factors in the legend), the bottom row absolute on a log axis (values
<= 0 or not finite cannot be drawn there: they are masked and counted in the panel's title). One
legend per figure, below the panels; the mirror direction (view = theta_i) marked and labelled on
every panel. Error bars: one standard error (beta_err). --describe writes the layout as JSON
(files, axis scales, legend, axes, title and mirror-label boxes, mirror labels, masked points)
for the tests. --jobs draws the figures in that many processes (default 1; weft passes its
thread count): a default run's nine take about 5 s of CPU, 3.3 s wall on 2 cores at --jobs 2, and
a process clears its one figure to new between incidences, so the files and the layout are the
same for any count. Run with /usr/bin/python3 (weft does): only it is known to have matplotlib.
"""
import argparse
import concurrent.futures
import csv
import gc
import json
import math
import multiprocessing
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.lines  # noqa: E402
import matplotlib.ticker  # noqa: E402
import matplotlib.transforms  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402

STYLE = {
    "measured": dict(color="black", linestyle="--", marker=""),
    "computed_raytrace": dict(color="tab:red", linestyle="-", marker="o", markersize=3),
    "computed_summation": dict(color="tab:orange", linestyle=":", marker=""),
    "classic": dict(color="tab:blue", linestyle="-.", marker="s", markersize=3),
    # weft verify --fit: the fitted parameters at the run's quality, thinner and lighter.
    "computed_raytrace_fitted": dict(color="salmon", linestyle="-", marker="", alpha=0.8),
    "classic_fitted": dict(color="lightskyblue", linestyle="-.", marker="", alpha=0.8),
}
CHANNELS = ["R", "G", "B"]
TITLE_PAD_PT = 25  # a panel's title above its top edge, past the mirror label
KINDS = ["normalized", "absolute"]
DPI = 80  # the PNG files' resolution


def read_inputs(src, metrics_path):
    """The points per (incidence, model, channel), the model order and the models' labels."""
    with open(src, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"plot_verify: {src}: no rows")
    with open(metrics_path) as f:
        metrics = json.load(f)
    labels = {k: v["label"] for k, v in metrics["models"].items()}
    labels["measured"] = "measured"
    models, data = [], {}
    for r in rows:
        if r["model"] not in models:
            models.append(r["model"])
        key = (float(r["theta_i_deg"]), r["model"], r["channel"])
        data.setdefault(key, []).append(
            (float(r["view_zenith_deg"]), float(r["beta"]), float(r["beta_err"]),
             float(r["beta_norm"]), float(r["norm_factor"])))
    return data, models, labels


def legend_label(data, ti, model, labels):
    """The model's label; with its normalization factors per channel when it has any."""
    label = labels.get(model, model)
    if model == "measured":
        return label
    factors = [sorted(data.get((ti, model, ch), [(0, 0, 0, 0, math.nan)]))[0][4]
               for ch in CHANNELS]
    return label + ", normalization \u00d7 " + " / ".join(f"{f:.3g}" for f in factors) + " (R / G / B)"


class InViewLogLocator(matplotlib.ticker.LogLocator):
    """matplotlib's LogLocator less the ticks outside the view. It gives a decade or two beyond
    each end, which matplotlib makes tick objects for, then updates and formats at every
    measure and draw, and never draws: most of a log axis's ticks. (A log axis's labels do not
    depend on the other ticks, so they are the same.)"""

    def tick_values(self, vmin, vmax):
        ticks = super().tick_values(vmin, vmax)
        lo, hi = min(vmin, vmax), max(vmin, vmax)
        # A margin wider than matplotlib's own test of which ticks are in view.
        return ticks[(ticks >= lo * (1 - 1e-6)) & (ticks <= hi * (1 + 1e-6))]


def draw_curve(ax, pts, kind, style):
    """One model's curve on one panel; returns how many points it could not draw."""
    norm = kind == "normalized"
    x = [p[0] for p in pts]
    y = [(p[3] if norm else p[1]) / math.pi for p in pts]
    err = [p[2] * (p[4] if norm else 1.0) / math.pi for p in pts]
    # A log axis cannot show values <= 0; neither axis can show NaN: masked (NaN), and counted.
    bad = [not math.isfinite(v) or (kind == "absolute" and v <= 0) for v in y]
    y = [math.nan if b else v for v, b in zip(y, bad)]
    err = [0.0 if b or not math.isfinite(e) else e for e, b in zip(err, bad)]
    if any(e > 0 for e in err):
        ax.errorbar(x, y, yerr=err, capsize=1.5, linewidth=1.2, elinewidth=0.7, **style)
    else:
        ax.plot(x, y, linewidth=1.2, **style)
    return sum(bad)


def mark_mirror(ax, ti):
    """The mirror direction (view = theta_i, the paper's Fig. 7 sign): a line, labelled by a tick
    above the panel, clear of the curves. Returns the label."""
    ax.axvline(ti, color="dimgrey", linewidth=0.9, linestyle=(0, (5, 3)))
    # The tick and its label drawn as a top x axis draws them (matplotlib's XTick), not as a
    # secondary axis: that is a whole Axes to build, lay out and draw, a sixth of the figures'
    # time.
    rc = matplotlib.rcParams
    size = rc["xtick.major.size"]
    ax.add_line(matplotlib.lines.Line2D(
        [ti], [1], transform=ax.get_xaxis_transform("tick2"), clip_on=False,
        linestyle="none", marker=matplotlib.lines.TICKUP if rc["xtick.direction"] == "out"
        else matplotlib.lines.TICKDOWN, markersize=size, color=rc["xtick.color"],
        markeredgecolor=rc["xtick.color"], markeredgewidth=rc["xtick.major.width"],
        zorder=matplotlib.lines.Line2D.zorder + 0.01))
    pad = rc["xtick.major.pad"] + (size if rc["xtick.direction"] == "out" else 0)
    transform, va, ha = ax.get_xaxis_text2_transform(pad)
    return ax.text(ti, 1, f"mirror {ti:g}\u00b0", transform=transform, va=va, ha=ha,
                   fontsize=9, color="dimgrey", clip_on=False)


def draw_panel(ax, data, models, ti, kind, ch):
    """One panel (incidence, kind, channel); returns its layout entry."""
    masked = 0
    for m in models:
        pts = sorted(data.get((ti, m, ch), []))
        if pts:
            masked += draw_curve(ax, pts, kind, dict(STYLE.get(m, {}), label=m))
    if kind == "absolute":
        ax.set_yscale("log", nonpositive="clip")  # error bars below zero run off the axis
        ax.yaxis.set_major_locator(InViewLogLocator(10))  # the log scale's locators, in view
        ax.yaxis.set_minor_locator(InViewLogLocator(10, subs=None))
    title = f"{ch} channel, " + ("paper's normalization" if kind == "normalized" else "absolute")
    if masked:
        title += f"\n({masked} points <= 0 or NaN not shown)"
    # Placed, not left to matplotlib: its automatic height clears the axes' own top ticks, not
    # the mirror label (and measuring, when the label was a secondary axis, took a quarter of
    # the figures' time). TITLE_PAD_PT clears the label (its tick, pad and 9 pt text).
    ax.set_title(title, fontsize=11, y=1.0, pad=TITLE_PAD_PT)
    mirror = mark_mirror(ax, ti)
    return {"kind": kind, "channel": ch, "yscale": ax.get_yscale(), "mirror_deg": ti,
            "mirror_label": mirror.get_text(), "masked_points": masked,
            "has_own_legend": ax.get_legend() is not None,
            "_title": ax.title, "_mirror": mirror}


def box(bb, fig):
    """A display box in figure fractions, [x0, y0, x1, y1]."""
    f = bb.transformed(fig.transFigure.inverted())
    return [round(v, 4) for v in (f.x0, f.y0, f.x1, f.y1)]


def tight_layout(fig, rows, bottom, top):
    """fig.tight_layout(rect=(0, bottom, 1, top)) for a grid of 'rows' rows, measured once.

    Given a rect, matplotlib measures every panel (its ticks, labels and title) twice at the same
    place, once for the margins and again for the spacing within the rect, and the second
    measurement is the first: half the layout's time. Here the rect is applied as matplotlib
    applies it, to one measurement: the margins moved in by the rect's, the vertical gap between
    the rows (in figure fractions) kept."""
    fig.tight_layout()
    p = fig.subplotpars
    gap = p.hspace * (p.top - p.bottom) / (rows + p.hspace * (rows - 1))
    bottom, top = bottom + p.bottom, top - (1 - p.top)
    panel = (top - bottom - gap * (rows - 1)) / rows
    fig.subplots_adjust(bottom=bottom, top=top, hspace=gap / panel)


def new_figure():
    """A figure's panels without their curves: what every incidence's figure shares."""
    # At the files' resolution from the start, so that the layout, the PNG and the layout
    # description share one renderer and its text measurements.
    fig, axes = plt.subplots(2, 3, figsize=(13, 8), dpi=DPI, sharex=True, squeeze=False)
    for r, kind in enumerate(KINDS):
        for ax in axes[r]:
            ax.grid(alpha=0.3, which="both" if kind == "absolute" else "major")
            ax.set_xlim(-90, 90)
            ax.tick_params(labelsize=9)
    axes[0][0].set_ylabel("beta / pi, normalized", fontsize=11)
    axes[1][0].set_ylabel("beta / pi (log axis)", fontsize=11)
    for ax in axes[1]:
        ax.set_xlabel("view zenith (deg; > 0 on the mirror side)", fontsize=10)
    return fig, axes


def clear_figure(fig, axes):
    """The figure as new_figure made it: the curves, marks, legend and layout taken away, the
    data limits and the y scales as new."""
    for legend in list(fig.legends):
        legend.remove()
    for ax in axes.flat:
        for artist in [*ax.lines, *ax.collections, *ax.texts]:
            artist.remove()
        ax.containers.clear()  # the error bars' groups of those lines, for the legend
        ax.dataLim = matplotlib.transforms.Bbox.null()
        ax.ignore_existing_data_limits = True
        ax.set_yscale("linear")  # its locators and formatter new
    rc = matplotlib.rcParams
    fig.subplots_adjust(**{k: rc[f"figure.subplot.{k}"]
                           for k in ("left", "right", "bottom", "top", "wspace", "hspace")})


# This process's figure, cleared and drawn again for each incidence: a new figure's axes, ticks
# and text measurements took about a fifth of the figures' time. Cleared, it draws the same
# bytes as a new one (test_plot_verify.cpp compares one process's figures with several's).
_figure = None


def incidence_figure(data, models, labels, ti, out_dir):
    """The figure of one incidence, saved as PNG and SVG; returns its layout entry."""
    global _figure
    if _figure is None:
        _figure = new_figure()
    else:
        clear_figure(*_figure)
    fig, axes = _figure
    panels = [draw_panel(axes[r][c], data, models, ti, kind, ch)
              for r, kind in enumerate(KINDS) for c, ch in enumerate(CHANNELS)]
    # One legend for the figure, below the panels, from the first panel's curves.
    handles, keys = axes[0][0].get_legend_handles_labels()
    order = sorted(range(len(keys)), key=lambda i: models.index(keys[i]))
    handles, keys = [handles[i] for i in order], [keys[i] for i in order]
    legend = fig.legend(handles, [legend_label(data, ti, k, labels) for k in keys],
                        loc="lower center", ncol=2, fontsize=10, frameon=False)
    fig.suptitle(f"light at {ti:g} deg: beta / pi in the plane of incidence", fontsize=13)
    rows = math.ceil(len(keys) / 2)
    tight_layout(fig, len(KINDS), bottom=0.035 + 0.03 * rows, top=0.97)  # the legend below
    name = f"inplane-{ti:04.1f}deg"
    for ext in ("png", "svg"):
        fig.savefig(os.path.join(out_dir, f"{name}.{ext}"))
    renderer = fig.canvas.get_renderer()
    legend_bb = legend.get_window_extent(renderer)
    for p, ax in zip(panels, axes.flat):
        p["axes_box"] = box(ax.get_window_extent(renderer), fig)
        p["title_box"] = box(p.pop("_title").get_window_extent(renderer), fig)
        p["mirror_label_box"] = box(p.pop("_mirror").get_window_extent(renderer), fig)
    entry = {"file": name + ".png", "theta_i_deg": ti, "panels": panels,
             "legends": 1 + sum(p["has_own_legend"] for p in panels),
             "legend_box": box(legend_bb, fig),
             "legend_outside_axes": not any(legend_bb.overlaps(ax.get_window_extent(renderer))
                                            for ax in axes.flat),
             "legend_labels": [t.get_text() for t in legend.get_texts()]}
    return entry


def draw_all(data, models, labels, incidences, out_dir, jobs):
    """Every incidence's figure, in 'jobs' processes; the layout entries in the incidences' order.
    The drawers are forked after the inputs are read, so each is handed an incidence alone."""
    def draw(ti):
        return incidence_figure(data, models, labels, ti, out_dir)
    first, rest = [], incidences
    if len(incidences) > jobs > 1:
        # Some drawer would draw two figures anyway: drawing the first here, before the drawers
        # are forked, takes no more wall time, and they start from its figure, ticks, fonts and
        # parsed labels instead of each making its own.
        first, rest = [draw(incidences[0])], incidences[1:]
    if jobs > 1 and len(rest) > 1:
        global _draw_forked
        _draw_forked = draw
        # Out of the collector's reach: a drawer's first collection would otherwise touch, and
        # so copy, every page of the objects it shares with this process (about a fifth of its
        # first figure's time).
        gc.freeze()
        try:
            context = multiprocessing.get_context("fork")
            with concurrent.futures.ProcessPoolExecutor(min(jobs, len(rest)),
                                                        mp_context=context) as pool:
                return first + list(pool.map(_draw_in_child, rest))
        except (OSError, concurrent.futures.BrokenExecutor) as e:
            # No processes here (a container without /dev/shm, a worker killed): one will do.
            print(f"plot_verify: drawing in this process alone ({e})", file=sys.stderr)
    return first + [draw(ti) for ti in rest]


_draw_forked = None  # draw_all's drawer, which a forked child inherits


def _draw_in_child(ti):
    return _draw_forked(ti)


def positive(text):
    n = int(text)
    if n < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, not {n}")
    return n


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("inplane")
    p.add_argument("metrics")
    p.add_argument("out_dir")
    p.add_argument("--describe", help="write the figures' layout here as JSON")
    p.add_argument("--jobs", type=positive, default=1, help="processes drawing the figures")
    a = p.parse_args()
    data, models, labels = read_inputs(a.inplane, a.metrics)
    incidences = sorted({k[0] for k in data})
    figures = draw_all(data, models, labels, incidences, a.out_dir, a.jobs)
    if a.describe:
        with open(a.describe, "w") as f:
            json.dump({"figures": figures}, f, indent=1)


if __name__ == "__main__":
    main()
