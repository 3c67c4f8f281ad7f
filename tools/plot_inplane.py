#!/usr/bin/python3
"""Scattering in the plane of incidence: computed vs measured vs the classic baseline.

Reads `weft sweep` CSVs (view_zenith_deg > 0 on the mirror side, the paper's Fig. 7 convention)
and a measured in-plane table (materials/data/measured/*/inplane.csv, whose theta_o has the
opposite sign), applies the paper's normalization (section 4: one factor so that the computed
value at the normal view equals the measured one), and writes a PNG with the three curves per
colour channel plus a JSON/markdown summary with the HSV comparison (paper's Table 1).

Caveat printed with the results: the MERL measurements are in the camera RGB of the MERL
database, Weft's are linear sRGB (D65), so hues compare only roughly.
"""
import argparse
import colorsys
import csv
import json
import math
import sys


def read_sweep(path):
    rows = []
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            rows.append((float(r["view_zenith_deg"]),
                         [float(r["beta_r"]), float(r["beta_g"]), float(r["beta_b"])],
                         float(r.get("beta_err", "nan"))))
    if not rows:
        sys.exit(f"plot_inplane: {path}: no rows")
    return sorted(rows)


def read_measured(path, theta_i):
    out = []
    with open(path, newline="") as f:
        lines = [l for l in f if not l.startswith('"#') and not l.startswith("#")]
    for r in csv.DictReader(lines):
        if abs(float(r["theta_i_deg"]) - theta_i) > 1e-9:
            continue
        # MERL's theta_o is negative on the mirror side; the paper's (and Weft's) is positive.
        out.append((-float(r["theta_o_deg"]),
                    [float(r["nbrdf_beta_R"]), float(r["nbrdf_beta_G"]), float(r["nbrdf_beta_B"])]))
    if not out:
        sys.exit(f"plot_inplane: {path}: no rows for theta_i = {theta_i}")
    return sorted(out)


def value_at(rows, angle):
    for a, v, *_ in rows:
        if abs(a - angle) < 1e-6:
            return v
    sys.exit(f"plot_inplane: no row at view {angle} deg (needed for the normalization)")


def normalize(rows, factor):
    return [(a, [c * factor for c in v], *rest) for a, v, *rest in rows]


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--computed", required=True, help="weft sweep CSV of the computed fabric")
    p.add_argument("--baseline", help="weft sweep CSV of the classic Lambert + Cook-Torrance model")
    p.add_argument("--measured", required=True, help="measured inplane.csv")
    p.add_argument("--theta-i", type=float, required=True, help="light zenith angle (deg)")
    p.add_argument("-o", "--output", required=True, help="output PNG")
    p.add_argument("--summary", help="output JSON summary")
    a = p.parse_args()

    measured = read_measured(a.measured, a.theta_i)
    m0 = value_at(measured, 0.0)
    curves = {"computed (fiber BSDF tables)": read_sweep(a.computed)}
    if a.baseline:
        curves["classic (Lambert + Cook-Torrance)"] = read_sweep(a.baseline)
    summary = {"theta_i_deg": a.theta_i, "normalization": "one factor per curve: mean RGB at view 0 "
               "set to the measured mean RGB at view 0 (paper, section 4)", "curves": {}}
    normalized = {}
    for name, rows in curves.items():
        c0 = value_at(rows, 0.0)
        factor = (sum(m0) / 3) / (sum(c0) / 3)
        normalized[name] = normalize(rows, factor)
        # Relative RMS difference to the measurement over the common angles, per channel mean.
        common = [(ang, v) for ang, v, *_ in normalized[name]
                  if any(abs(ang - mang) < 1e-6 for mang, _ in measured)]
        err = []
        for ang, v in common:
            mv = value_at(measured, ang)
            err.append(sum((x - y) ** 2 for x, y in zip(v, mv)) / max(1e-12, sum(y * y for y in mv)))
        summary["curves"][name] = {"factor": factor,
                                   "relative_rms_vs_measured": math.sqrt(sum(err) / len(err)) if err else None}

    def hsv(v):
        return colorsys.rgb_to_hsv(*[max(0.0, c) for c in v])
    table = [("measured (MERL red-fabric, NBRDF fit)", hsv(m0))]
    for name, rows in normalized.items():
        table.append((name, hsv(value_at(rows, 0.0))))
    summary["hsv_at_normal_view"] = {n: {"h": h, "s": s, "v": v} for n, (h, s, v) in table}
    summary["caveat"] = ("MERL RGB is the database's camera RGB, Weft's is linear sRGB (D65): "
                         "compare curve shapes and normalized values; hues only roughly.")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 3, figsize=(13, 4), sharex=True)
    styles = {"computed (fiber BSDF tables)": "-", "classic (Lambert + Cook-Torrance)": "-."}
    for ch, (ax, cname) in enumerate(zip(axes, ["R", "G", "B"])):
        ax.plot([m[0] for m in measured], [m[1][ch] for m in measured], "k--", label="measured")
        for name, rows in normalized.items():
            ax.plot([r[0] for r in rows], [r[1][ch] for r in rows], styles.get(name, "-"), label=name)
        ax.set_title(f"{cname} channel, light at {a.theta_i:g} deg")
        ax.set_xlabel("view zenith (deg; > 0 on the mirror side)")
        ax.set_xlim(-75, 75)
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("radiance coefficient (normalized as the paper)")
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(a.output, dpi=110)

    print(f"in-plane plot: {a.output}")
    print("HSV at the normal view (paper, Table 1):")
    print(f"  {'':42s}  H      S      V")
    for n, (h, s, v) in table:
        print(f"  {n:42s}  {h:.3f}  {s:.3f}  {v:.3f}")
    for n, c in summary["curves"].items():
        if c["relative_rms_vs_measured"] is not None:
            print(f"  relative RMS vs measured, {n}: {c['relative_rms_vs_measured']:.3f}")
    print("  note: " + summary["caveat"])
    if a.summary:
        with open(a.summary, "w") as f:
            json.dump(summary, f, indent=2)


if __name__ == "__main__":
    main()
