#!/usr/bin/python3
"""Regenerates the bundled measured tables (materials/data/measured/<dir>/).

Only for regenerating data: Weft's build, tests and programs read the files this writes and never
run this script. Needs python3, numpy and h5py.

For each material of MATERIALS it writes <dir>/nbrdf_weights.txt (the neural BRDF fit of Sztrajman,
Rainer, Ritschel, Weyrich, "Neural BRDF Representation and Importance Sampling", CGF 2021, from its
keras .h5 file) and <dir>/inplane.csv (that network, and for MERL materials the Shifted-Gamma-
Distribution and ABC fits, evaluated in the plane of incidence), then samples.json listing them.
README.md says where the inputs come from and what the columns mean.

  make_inplane.py --nbrdf DIR --dj-brdf FILE [--only DIR ...]
  make_inplane.py --check --nbrdf DIR --dj-brdf FILE
  make_inplane.py --albedo --nbrdf DIR --dj-brdf FILE

--nbrdf: the folder holding merl_nbrdf/ and rgl-isotropic_nbrdf/, unzipped from data/*.zip of
github asztr/Neural-BRDF. --dj-brdf: dj_brdf.h of github jdupuy/dj_brdf, whose parameter tables of
the SGD and ABC fits are read (its code is not used: the two models are evaluated below from the
papers' formulas). --check regenerates the first two materials (the original bundle) in memory and
compares every file with the bundled one: text of the comment and header lines, and every number
to one unit of its last printed digit; it prints the largest deviation per column group and
exits 1 on a mismatch. --albedo prints each network's directional albedo at normal incidence (the
colour-scale check of README.md).
"""
import argparse
import csv
import io
import json
import math
import os
import re
import sys

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
THETA_I_DEG = [0, 10, 20, 30, 40, 45, 50, 60, 70]
THETA_O_DEG = list(range(-85, 86, 5))
CHANNELS = "RGB"

MERL_KNOWN = ("MERL BRDF database (Matusik et al. 2003) sample named '{name}'; the database gives "
              "the name only (no fiber, construction or manufacturer)")
RGL_KNOWN = ("RGL material database (EPFL; Dupuy & Jakob 2018) RGB file '{name}'; known from the "
             "name only (the database's description of the sample was not available to us)")


def merl(name, colour, construction="unknown-woven"):
    return {"dir": "merl-" + name, "source": "merl", "h5": name, "colour": colour,
            "colour_space": "camera", "construction": construction, "fiber_hint": "",
            "known": MERL_KNOWN.format(name=name)}


def rgl(name, colour, construction, fiber_hint, what):
    return {"dir": "rgl-" + name.replace("_rgb", "").replace("_", "-"), "source": "rgl",
            "h5": name, "colour": colour, "colour_space": "srgb", "construction": construction,
            "fiber_hint": fiber_hint, "known": RGL_KNOWN.format(name=name) + "; " + what}


FELT = "the name says acrylic felt (fiber: acrylic; construction: felt)"
SATIN = ("the name says satin (a weave, or a satin-finish textile); fiber not stated")

# The first two are the original bundle (--check compares them with the files in the repository).
MATERIALS = [
    merl("red-fabric", "red"),
    merl("white-fabric", "white"),
    merl("red-fabric2", "red"),
    merl("white-fabric2", "white"),
    merl("blue-fabric", "blue"),
    merl("green-fabric", "green"),
    merl("pink-fabric", "pink"),
    merl("pink-fabric2", "pink"),
    merl("pink-felt", "pink", "felt"),
    merl("beige-fabric", "beige"),
    merl("black-fabric", "black"),
    merl("light-brown-fabric", "light brown"),
    merl("dark-specular-fabric", "dark"),
    rgl("acrylic_felt_green_rgb", "green", "felt", "acrylic", FELT),
    rgl("acrylic_felt_orange_rgb", "orange", "felt", "acrylic", FELT),
    rgl("acrylic_felt_pink_rgb", "pink", "felt", "acrylic", FELT),
    rgl("acrylic_felt_purple_rgb", "purple", "felt", "acrylic", FELT),
    rgl("acrylic_felt_white_rgb", "white", "felt", "acrylic", FELT),
    rgl("acrylic_felt_yellow_rgb", "yellow", "felt", "acrylic", FELT),
    rgl("satin_blue_rgb", "blue", "unknown-woven", "", SATIN),
    rgl("satin_gold_rgb", "gold", "unknown-woven", "", SATIN),
    rgl("satin_purple_rgb", "purple", "unknown-woven", "", SATIN),
    rgl("satin_rosaline_rgb", "rosaline", "unknown-woven", "", SATIN),
    rgl("satin_white_rgb", "white", "unknown-woven", "", SATIN),
]


# ------------------------------------------------------------------------------------ NBRDF
def read_h5(path):
    """W1, b1, W2, b2, W3, b3 of a keras 6-21-21-3 network, as float32 like the file."""
    with h5py.File(path, "r") as f:
        out = []
        for layer in ("dense_1", "dense_2", "dense_3"):
            g = f[layer][layer]
            out += [np.array(g["kernel:0"], dtype=np.float32), np.array(g["bias:0"], dtype=np.float32)]
    shapes = [(6, 21), (21,), (21, 21), (21,), (21, 3), (3,)]
    if [w.shape for w in out] != shapes:
        sys.exit(f"make_inplane: {path}: layer shapes {[w.shape for w in out]}, expected {shapes}")
    return out


def weights_text(weights, label):
    lines = [f"# NBRDF weights (Sztrajman et al. 2021, asztr/Neural-BRDF, MIT) for {label}",
             "# y = exp( W3^T relu( W2^T relu( W1^T x + b1 ) + b2 ) + b3 ) - 1 ; "
             "x=(hx,hy,hz,dx,dy,dz) with phi_h=0; W_k stored row-major as (in,out)"]
    for name, w in zip(("W1", "b1", "W2", "b2", "W3", "b3"), weights):
        lines.append(f"{name} {' '.join(str(n) for n in w.shape)}")
        rows = w if w.ndim == 2 else w[None, :]
        lines += [" ".join("%.9g" % v for v in row) for row in rows]
    return "\n".join(lines) + "\n"


def nbrdf_eval(weights, wi, wo):
    """f_r of the network (README formula), for arrays of directions (..., 3), wi toward the light."""
    w1, b1, w2, b2, w3, b3 = (w.astype(np.float64) for w in weights)
    h = wi + wo
    h = h / np.linalg.norm(h, axis=-1, keepdims=True)
    theta_h = np.arccos(np.clip(h[..., 2], -1.0, 1.0))
    phi_h = np.arctan2(h[..., 1], h[..., 0])
    cp, sp, ct, st = np.cos(phi_h), np.sin(phi_h), np.cos(theta_h), np.sin(theta_h)
    # d = R_y(-theta_h) R_z(-phi_h) wi
    rx = cp * wi[..., 0] + sp * wi[..., 1]
    ry = -sp * wi[..., 0] + cp * wi[..., 1]
    rz = wi[..., 2]
    x = np.stack([st, np.zeros_like(st), ct, ct * rx - st * rz, ry, st * rx + ct * rz], axis=-1)
    a = np.maximum(0.0, x @ w1 + b1)
    a = np.maximum(0.0, a @ w2 + b2)
    return np.maximum(0.0, np.exp(a @ w3 + b3) - 1.0)


# ------------------------------------------------------------------------- SGD and ABC fits
SGD_FIELDS = ["rhoD", "rhoS", "alpha", "p", "f0", "f1", "kap", "lambda", "c", "k", "theta0",
              "error"]


def read_dj_tables(path):
    """Parameter tables of dj_brdf.h: {name: dict} for the SGD and the ABC fits."""
    text = open(path).read()

    def table(tag):
        m = re.search(r"const " + tag + r"::data " + tag + r"::s_data\[\] = \{(.*?)\n\};", text,
                      re.S)
        if not m:
            sys.exit(f"make_inplane: {path}: no {tag}::s_data table")
        return [line.strip() for line in m.group(1).splitlines() if line.strip().startswith("{")]

    number = r"[-+]?[0-9.]+(?:e[-+]?[0-9]+)?"
    sgd = {}
    for line in table("sgd"):
        names = re.findall(r'"([^"]*)"', line)
        triples = re.findall(r"\{\s*(" + number + r")\s*,\s*(" + number + r")\s*,\s*(" + number +
                             r")\s*\}", line)
        if len(triples) != len(SGD_FIELDS):
            sys.exit(f"make_inplane: {path}: SGD row for {names[0]}: {len(triples)} triples")
        sgd[names[0]] = {k: np.array([float(v) for v in t]) for k, t in zip(SGD_FIELDS, triples)}
    abc = {}
    for line in table("abc"):
        name = re.findall(r'"([^"]*)"', line)[0]
        nums = [float(v) for v in re.findall(number, line.split('"', 2)[2])]
        if len(nums) != 9:
            sys.exit(f"make_inplane: {path}: ABC row for {name}: {len(nums)} numbers")
        abc[name] = {"kD": np.array(nums[0:3]), "A": np.array(nums[3:6]), "B": nums[6],
                     "C": nums[7], "ior": nums[8]}
    return sgd, abc


def half_and_cosines(wi, wo):
    h = (wi + wo) / np.linalg.norm(wi + wo)
    return h, wi[2], wo[2], min(1.0, max(0.0, float(np.dot(wi, h))))


def sgd_eval(p, wi, wo):
    """Bagher, Soler, Holzschuch, "Accurate fitting of measured reflectances using a Shifted Gamma
    micro-facet distribution", CGF 2012: f = (rho_d + rho_s F D G / (cos_i cos_o)) / pi with
    D = kap exp(-a) / (pi a^p cos^4 theta_h), a = alpha + tan^2 theta_h / alpha, their Fresnel
    F = F0 - F1 cos_d + (1 - F0)(1 - cos_d)^5 and shadowing G = G1(wi) G1(wo),
    G1 = clamp(1 + Lambda (1 - exp(c max(0, theta - theta0)^k)), 0, 1)."""
    h, ci, co, cd = half_and_cosines(wi, wo)
    if ci <= 0 or co <= 0:
        return np.zeros(3)
    c2 = h[2] * h[2]
    a = p["alpha"] + (1.0 - c2) / c2 / p["alpha"]
    d = p["kap"] * np.exp(-a) / math.pi / (a ** p["p"] * c2 * c2)
    f = p["f0"] - cd * p["f1"] + (1.0 - cd) ** 5 * (1.0 - p["f0"])

    def g1(cos_t):
        t = np.maximum(0.0, math.acos(cos_t) - p["theta0"])
        return np.clip(1.0 + p["lambda"] * (1.0 - np.exp(p["c"] * t ** p["k"])), 0.0, 1.0)

    return (p["rhoD"] + p["rhoS"] * f * d * g1(ci) * g1(co) / (ci * co)) / math.pi


def fresnel_dielectric(cos_d, ior):
    """Unpolarized Fresnel reflectance of a dielectric interface (Cook & Torrance 1982 form)."""
    g = math.sqrt(ior * ior + cos_d * cos_d - 1.0)
    a = ((g - cos_d) / (g + cos_d)) ** 2
    b = ((cos_d * (g + cos_d) - 1.0) / (cos_d * (g - cos_d) + 1.0)) ** 2
    return 0.5 * a * (1.0 + b)


def abc_eval(p, wi, wo):
    """Low, Kronander, Ynnerman, Unger, "BRDF models for accurate and efficient rendering of glossy
    surfaces", ACM TOG 2012, microfacet variant: f = kd / pi + F D G / (pi cos_i cos_o) with
    D = A / (1 + B (1 - cos theta_h))^C, dielectric Fresnel of index ior and Cook-Torrance shadowing
    G = min(1, 2 cos_h cos_i / cos_d, 2 cos_h cos_o / cos_d)."""
    h, ci, co, cd = half_and_cosines(wi, wo)
    if ci <= 0 or co <= 0:
        return np.zeros(3)
    d = p["A"] / (1.0 + p["B"] * (1.0 - h[2])) ** p["C"]
    g = min(1.0, 2.0 * h[2] * ci / float(np.dot(h, wi)), 2.0 * h[2] * co / float(np.dot(h, wo)))
    return p["kD"] / math.pi + fresnel_dielectric(cd, p["ior"]) * d * g / (math.pi * ci * co)


# ----------------------------------------------------------------------------- the table
def inplane_text(mat, weights, sgd, abc):
    src = "merl_nbrdf" if mat["source"] == "merl" else "rgl-isotropic_nbrdf"
    space = ("the database RGB space" if mat["source"] == "merl"
             else "linear sRGB (the database's RGB files)")
    comment = (f'# in-plane BRDF of measured material "{mat["h5"]}" ({src}), evaluated from NBRDF '
               f"network; wi=(sin ti,0,cos ti), wo=(sin to,0,cos to), mirror at to=-ti; fr in 1/sr, "
               f"beta=pi*fr (radiance coefficient); RGB in {space}")
    cols = ["theta_i_deg", "theta_o_deg"] + [f"nbrdf_fr_{c}" for c in CHANNELS] + \
        [f"nbrdf_beta_{c}" for c in CHANNELS]
    if sgd is not None:
        cols += [f"sgd_fr_{c}" for c in CHANNELS]
    if abc is not None:
        cols += [f"abc_fr_{c}" for c in CHANNELS]
    out = io.StringIO()
    w = csv.writer(out)  # "\r\n" line ends, like the original files
    w.writerow([comment])
    w.writerow([f"# colour_space: {mat['colour_space']}"])
    w.writerow(cols)
    for ti in THETA_I_DEG:
        for to in THETA_O_DEG:
            a, b = math.radians(ti), math.radians(to)
            wi = np.array([math.sin(a), 0.0, math.cos(a)])
            wo = np.array([math.sin(b), 0.0, math.cos(b)])
            fr = nbrdf_eval(weights, wi, wo)
            row = list(fr) + list(math.pi * fr)
            if sgd is not None:
                row += list(sgd_eval(sgd, wi, wo))
            if abc is not None:
                row += list(abc_eval(abc, wi, wo))
            w.writerow([ti, to] + ["%g" % v for v in row])
    return out.getvalue()


def generate(mat, args, tables):
    sub = "merl_nbrdf" if mat["source"] == "merl" else "rgl-isotropic_nbrdf"
    weights = read_h5(os.path.join(args.nbrdf, sub, mat["h5"] + ".h5"))
    sgd = tables[0].get(mat["h5"]) if mat["source"] == "merl" else None
    abc = tables[1].get(mat["h5"]) if mat["source"] == "merl" else None
    label = ("merl/" if mat["source"] == "merl" else "rgl/") + mat["h5"]
    return weights_text(weights, label), inplane_text(mat, weights, sgd, abc)


def samples_json():
    keys = ["name", "dir", "source", "colour_space", "known", "construction", "fiber_hint",
            "colour"]
    rows = [dict(mat, name=mat["h5"]) for mat in MATERIALS]
    return json.dumps([{k: r[k] for k in keys} for r in rows], indent=1) + "\n"


# ----------------------------------------------------------------------------- --albedo
def albedo_at_normal(weights, n=512):
    """Directional albedo at normal incidence, integral of f_r cos(theta_o) over the hemisphere,
    midpoint rule on an n x 2n (theta_o, phi_o) grid."""
    t = (np.arange(n) + 0.5) * (math.pi / 2 / n)
    ph = (np.arange(2 * n) + 0.5) * (math.pi / n)
    T, P = np.meshgrid(t, ph, indexing="ij")
    wo = np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], axis=-1)
    wi = np.broadcast_to(np.array([0.0, 0.0, 1.0]), wo.shape)
    weight = (np.cos(T) * np.sin(T))[..., None] * (math.pi / 2 / n) * (math.pi / n)
    return (nbrdf_eval(weights, wi, wo) * weight).sum(axis=(0, 1))


def print_albedos(args):
    """The colour-scale check of README.md: RGL's Spectralon (a near-white diffuse standard) and
    every bundled material."""
    ref = {"h5": "spectralon_rgb", "source": "rgl", "dir": "(reference) rgl spectralon_rgb"}
    for mat in [ref] + MATERIALS:
        sub = "merl_nbrdf" if mat["source"] == "merl" else "rgl-isotropic_nbrdf"
        a = albedo_at_normal(read_h5(os.path.join(args.nbrdf, sub, mat["h5"] + ".h5")))
        print(f"{mat['dir']:32s} albedo(0) R G B = {a[0]:.3f} {a[1]:.3f} {a[2]:.3f}   "
              f"G/R {a[1] / a[0]:.3f} B/R {a[2] / a[0]:.3f}")


# ----------------------------------------------------------------------------- --check
def compare(got, want, what):
    """Per column group: the largest relative deviation and the largest deviation in units of the
    bundled number's last printed digit (6 significant digits); exits on a text mismatch."""
    g, w = got.splitlines(), want.splitlines()
    if len(g) != len(w):
        sys.exit(f"make_inplane --check: {what}: {len(g)} lines, bundled {len(w)}")
    worst = {}
    header = None
    for n, (a, b) in enumerate(zip(g, w), 1):
        if a.startswith(("#", '"#')) or a[:1].isalpha():
            if a != b:
                sys.exit(f"make_inplane --check: {what} line {n} differs:\n  {a}\n  {b}")
            if a.startswith("theta_i_deg,"):
                header = a.split(",")
            continue
        fa, fb = a.replace(",", " ").split(), b.replace(",", " ").split()
        if len(fa) != len(fb):
            sys.exit(f"make_inplane --check: {what} line {n}: {len(fa)} fields, bundled {len(fb)}")
        for k, (x, y) in enumerate(zip(fa, fb)):
            key = header[k].rsplit("_", 1)[0] if header else "weights"
            x, y = float(x), float(y)
            digits = 9 if key == "weights" else 6
            last = 10.0 ** (math.floor(math.log10(abs(y))) - digits + 1) if y else 1e-300
            rel, ulps = worst.get(key, (0.0, 0.0))
            worst[key] = (max(rel, abs(x - y) / max(abs(y), 1e-300)), max(ulps, abs(x - y) / last))
    return worst


def check(args, tables):
    """The original two bundled materials, regenerated: every number within one unit of its last
    printed digit (the rounding of a value computed in a different order)."""
    ok = True
    for mat in MATERIALS[:2]:
        weights, table = generate(mat, args, tables)
        for text, file in ((weights, "nbrdf_weights.txt"), (table, "inplane.csv")):
            with open(os.path.join(HERE, mat["dir"], file), newline="") as f:
                bundled = f.read()
            worst = compare(text, bundled, f"{mat['dir']}/{file}")
            same = text == bundled
            ok = ok and same
            print(f"{mat['dir']}/{file}: {'byte-identical' if same else 'DIFFERS in bytes'}")
            for key, (rel, ulps) in sorted(worst.items()):
                good = ulps <= 1.0001
                ok = ok and good
                print(f"{mat['dir']}/{file} {key}: max relative deviation {rel:.3g}, "
                      f"{ulps:.3g} of the last digit {'ok' if good else 'FAIL'}")
    return ok


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--nbrdf", required=True, help="folder with merl_nbrdf/, rgl-isotropic_nbrdf/")
    p.add_argument("--dj-brdf", required=True, help="dj_brdf.h (SGD and ABC parameter tables)")
    p.add_argument("--check", action="store_true", help="compare with the bundled original two")
    p.add_argument("--albedo", action="store_true", help="print albedos at normal incidence")
    p.add_argument("--only", nargs="*", help="material folders to write (default: all)")
    args = p.parse_args()
    tables = read_dj_tables(args.dj_brdf)
    if args.albedo:
        return print_albedos(args)
    if args.check:
        sys.exit(0 if check(args, tables) else 1)
    for mat in MATERIALS:
        if args.only and mat["dir"] not in args.only:
            continue
        weights, table = generate(mat, args, tables)
        os.makedirs(os.path.join(HERE, mat["dir"]), exist_ok=True)
        for text, file in ((weights, "nbrdf_weights.txt"), (table, "inplane.csv")):
            with open(os.path.join(HERE, mat["dir"], file), "w", newline="") as f:
                f.write(text)
        print(f"wrote {mat['dir']}")
    with open(os.path.join(HERE, "samples.json"), "w") as f:
        f.write(samples_json())


if __name__ == "__main__":
    main()
