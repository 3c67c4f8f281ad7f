#!/usr/bin/env python3
"""The table of scripts/perf-goals.sh: reads the programs' outputs in OUT and writes OUT/goals.md
and OUT/goals.json. Usage: perf_goals_table.py OUT BASELINE_REVISION SEEDS"""
import glob
import json
import os
import re
import statistics
import sys

TARGET = 0.01  # relative noise or error the goals are stated at


def read_json(path):
    with open(path) as f:
        return json.load(f)


def number(path):
    with open(path) as f:
        return float(f.read().split()[0])


def have(out, name):
    return os.path.exists(os.path.join(out, name + ".time"))


def have_backlit(out):
    return os.path.exists(os.path.join(out, "backlit-after.out"))


def raytrace(out, seeds):
    """CPU seconds to 1 % per channel, mean over the seeds, before and after."""
    cost = {}
    for who in ("before", "after"):
        per_seed = []
        for seed in range(1, seeds + 1):
            name = "raytrace-%s-%d" % (who, seed)
            j = read_json(os.path.join(out, name + ".out"))
            cpu = number(os.path.join(out, name + ".cpu"))
            per_seed.append([cpu * (n / TARGET) ** 2 for n in j["relative_noise_per_channel"]])
        cost[who] = [sum(s[c] for s in per_seed) / seeds for c in range(len(per_seed[0]))]
    rows = []
    for c, label in enumerate("RGB"):
        b, a = cost["before"][c], cost["after"][c]
        rows.append(("fabric ray trace, CPU-s to 1 %% %s" % label, b, a, b / a))
    return rows


def bake(out):
    """Photons per band and CPU seconds for a 1 % table error: the baseline's default bake against
    each variant this tree's bench ran. CPU per photon: a variant's CPU seconds per bake summed
    over the photon counts, over those counts (the baseline's bench has no per-bake CPU time: its
    process's CPU time over its seeds, which counts its start too)."""
    runs = {}
    for who in ("before", "after"):
        j = read_json(os.path.join(out, "bake-%s.out" % who))
        variants = j["variants"] if "variants" in j else [dict(j, estimator="plain")]
        runs[who] = []
        for v in variants:
            photons = sum(r["photons_per_band"] for r in v["runs"])
            if all("cpu_seconds_per_bake" in r for r in v["runs"]):
                cpu = sum(r["cpu_seconds_per_bake"] for r in v["runs"])  # this variant's own
            else:  # a bench before per-bake CPU times: the whole process's, over its seeds
                cpu = number(os.path.join(out, "bake-%s.cpu" % who)) / j["seeds"]
            target = v["photons_per_band_for_target"]
            runs[who].append((v["estimator"], target, cpu / photons * target))
    (nb, pb, cb), rows = runs["before"][0], []
    for na, pa, ca in runs["after"]:
        rows.append(("fiber bake, photons per band to 1 %% (%s → %s)" % (nb, na), pb, pa, pb / pa))
        rows.append(("fiber bake, CPU-s to 1 %% (%s → %s)" % (nb, na), cb, ca, cb / ca))
    return rows


def render(out):
    """The median over the runs of each program of its ratio_replay per scene, with the range."""
    ratios = {}
    for who in ("before", "after"):
        runs = sorted(glob.glob(os.path.join(out, "render-%s-*.out" % who)))
        for path in runs:
            for s in read_json(path)["scenes"]:
                ratios.setdefault((who, s["name"]), []).append(s["ratio_replay"])
    rows = []
    names = [name for who, name in ratios if who == "after"]
    for name in names:
        b, a = ratios[("before", name)], ratios[("after", name)]
        mb, ma = statistics.median(b), statistics.median(a)
        rows.append(("path tracer / bare Embree, %s (median of %d runs in turns; before %.2f–%.2f, "
                     "after %.2f–%.2f)" % (name, len(a), min(b), max(b), min(a), max(a)),
                     mb, ma, ma / mb))
    return rows


def backlit(out):
    """Red noise at equal time of the fiber-level renders: noise^2 x CPU seconds (the variance a
    CPU-second leaves), from fiber-render-noise.sh's lines
    'back default 16spp cpu_s 9.9 10.1  noise 2.72 46.9 2.84  means ...'."""
    figures = {}
    for who in ("before", "after"):
        with open(os.path.join(out, "backlit-%s.out" % who)) as f:
            for line in f:
                words = line.split()
                if len(words) < 10 or words[3] != "cpu_s":
                    continue
                cpu = (float(words[4]) + float(words[5])) / 2
                red = float(words[words.index("noise") + 1])
                figures[(words[0], who)] = red * red * cpu
    rows = []
    for light, label in (("back", "lit from behind"), ("front", "lit in front")):
        b, a = figures[(light, "before")], figures[(light, "after")]
        rows.append(("fiber-level render %s, red noise² × CPU-s" % label, b, a, b / a))
    return rows


def fit(out):
    rows = []
    for who in ("before", "after"):
        if not have(out, "fit-" + who):
            continue
        wall = number(os.path.join(out, "fit-%s.wall" % who))
        m = read_json(os.path.join(out, "fit-%s" % who, "fit", "metrics.json"))
        # evaluations: every seed's fit and the judging of their optima (verify --fit-seeds)
        conv = ", ".join("%s %s in %d (%d seed fits)" % (
            k, "converged" if f["converged"] else "not converged", f["evaluations"],
            max(1, len(f.get("seeds", [])))) for k, f in m.get("fit", {}).items())
        rows.append(("verify --quality default --fit (%s), wall s; %s" % (who, conv), wall, None, None))
    return rows


def printed_seconds(text):
    """The wall-clock estimate verify prints before its work ("about 3 min on 2 cores"), seconds:
    format_seconds (core/src/run_limits.cpp) rounds up to whole seconds or minutes."""
    m = re.search(r"about ([0-9.]+) (s|min|h|days) on", text)
    if not m:
        return None
    return float(m.group(1)) * {"s": 1, "min": 60, "h": 3600, "days": 86400}[m.group(2)]


def verify(out):
    """weft verify --quality default, cold and warm: wall, CPU and the printed estimate; this
    tree's stages to verify-stages.md."""
    rows, stages = [], {}
    for cache in ("cold", "warm"):
        walls, cpus, estimates = {}, {}, {}
        for who in ("before", "after"):
            name = "verify-%s-%s" % (cache, who)
            if not have(out, name):
                continue
            walls[who] = number(os.path.join(out, name + ".wall"))
            cpus[who] = number(os.path.join(out, name + ".cpu"))
            with open(os.path.join(out, name + ".err"), errors="replace") as f:
                estimates[who] = printed_seconds(f.read())
            metrics = os.path.join(out, name, "report", "metrics.json")
            if who == "after" and os.path.exists(metrics):
                stages[cache] = read_json(metrics).get("seconds", {})
        if not walls:
            continue
        b, a = walls.get("before"), walls.get("after")
        rows.append(("verify --quality default, %s cache, wall s" % cache, b, a,
                     b / a if a and b else None))
        b, a = cpus.get("before"), cpus.get("after")
        rows.append(("verify --quality default, %s cache, CPU s" % cache, b, a,
                     b / a if a and b else None))
        b, a = estimates.get("before"), estimates.get("after")
        rows.append(("verify --quality default, %s cache, wall s printed before the work" % cache,
                     b, a, None))
    if stages:
        keys = sorted(set(stages.get("cold", {})) | set(stages.get("warm", {})),
                      key=lambda k: -stages.get("cold", {}).get(k, 0))
        with open(os.path.join(out, "verify-stages.md"), "w") as f:
            f.write("| stage (metrics.json seconds) | cold, s | warm, s |\n| --- | --- | --- |\n")
            for k in keys:
                f.write("| %s | %s | %s |\n" % (k, fmt(stages.get("cold", {}).get(k)),
                                                fmt(stages.get("warm", {}).get(k))))
    return rows


def fmt(x):
    if x is None:
        return "–"
    return "%.3g" % x


def main():
    out, rev, seeds = sys.argv[1], sys.argv[2], int(sys.argv[3])
    rows = []
    if have(out, "raytrace-after-1"):
        rows += raytrace(out, seeds)
    if have(out, "bake-after"):
        rows += bake(out)
    if have(out, "render-after-1"):
        rows += render(out)
    if have_backlit(out):
        rows += backlit(out)
    rows += fit(out)
    rows += verify(out)
    with open(os.path.join(out, "goals.json"), "w") as f:
        json.dump([{"figure": r[0], "before": r[1], "after": r[2], "gain": r[3]} for r in rows], f,
                  indent=2)
    with open(os.path.join(out, "goals.md"), "w") as f:
        f.write("| figure | before (%s) | after | gain |\n| --- | --- | --- | --- |\n" % rev)
        for r in rows:
            f.write("| %s | %s | %s | %s |\n" % (r[0], fmt(r[1]), fmt(r[2]),
                                                 "–" if r[3] is None else "%.2f×" % r[3]))


if __name__ == "__main__":
    main()
