#!/usr/bin/env python3
"""What each bond model reaches (issue 28): the report of the bond-model-reach campaigns.

The campaigns (protocols/campaigns/bond-model-reach-*.toml) run the UCS test, direct tension
and the triaxial cell on the same 3D bonded sphere pack: a seed forms the same sample in each, since their
sample, material, bond and formation sections are one. This script pairs their
runs by material (the bond keys the campaigns sweep, read from each run's parameters) and seed,
and writes for every material the UCS, the tensile strength, the ratio UCS / sigma_t taken
seed by seed, Young's modulus, Poisson's ratio, and the friction angle where a campaign of the
envelope rig ran on the same material, each as the mean with its 95% interval over the seeds
(Student's t).

    make bond-model-reach    (the campaigns into build/bond-model-reach.sqlite, then this)
    tests/bond_model_reach.py --lab build/bond-model-reach.sqlite --out build/bond-model-reach

Writes OUT/index.html and OUT/reach.csv, and prints the table.
"""

import argparse
import csv
import html
import math
import os
import sqlite3
import statistics
import sys

# The bond keys that make a material here: what the campaigns sweep.
MATERIAL_KEYS = [
    "bonds.model",
    "bonds.tensile_strength_mean_MPa",
    "bonds.shear_strength_mean_MPa",
    "bonds.flat_joint_slit_fraction",
]

# A key's default where a run's parameters lack it (a run of a build older than the key).
DEFAULTS = {"bonds.flat_joint_slit_fraction": "0"}

# t(0.975, n - 1) for n = 2..11.
T975 = [12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228]


def interval(values):
    """Mean and the half width of its 95% interval (NaN for one value)."""
    values = [v for v in values if v is not None and not math.isnan(v)]
    if not values:
        return math.nan, math.nan, 0
    mean = statistics.fmean(values)
    if len(values) < 2:
        return mean, math.nan, 1
    t = T975[min(len(values), len(T975) + 1) - 2]
    return mean, t * statistics.stdev(values) / math.sqrt(len(values)), len(values)


def runs_by_material(db):
    """{(material, seed): {rig: {result: value}}} over the completed runs of the campaigns."""
    rows = db.execute(
        """SELECT r.id, r.rig, r.seed, r.wall_seconds FROM campaign_points p
           JOIN campaigns c ON c.id = p.campaign_id JOIN runs r ON r.id = p.run_id
           WHERE c.name LIKE 'bond-model-reach-%' AND r.status = 'completed'"""
    ).fetchall()
    out = {}
    for run_id, rig, seed, wall in rows:
        params = dict(db.execute("SELECT key, value FROM params WHERE run_id = ?", (run_id,)))
        material = tuple(params.get(k, DEFAULTS.get(k, "")).strip('"') for k in MATERIAL_KEYS)
        results = dict(db.execute("SELECT name, value FROM results WHERE run_id = ?", (run_id,)))
        results["wall_seconds"] = wall
        out.setdefault((material, seed), {})[rig] = results
    return out


def table(runs):
    materials = sorted({m for m, _ in runs})
    rows = []
    for m in materials:
        seeds = sorted(s for mm, s in runs if mm == m)
        per = [runs[(m, s)] for s in seeds]

        def pick(rig, name):
            return [r[rig][name] for r in per if rig in r and name in r[rig]]

        ratio = [r["ucs"]["ucs_MPa"] / r["direct_tension"]["tensile_strength_MPa"] for r in per
                 if "ucs" in r and "direct_tension" in r]
        row = dict(zip(["model", "tensile_MPa", "shear_MPa", "slit_fraction"], m))
        for label, values in [
            ("ucs_MPa", pick("ucs", "ucs_MPa")),
            ("tensile_strength_MPa", pick("direct_tension", "tensile_strength_MPa")),
            ("ucs_over_tensile", ratio),
            ("young_modulus_MPa", pick("ucs", "young_modulus_tangent_50_MPa")),
            ("poisson_ratio", pick("ucs", "poisson_ratio_tangent_50")),
            ("crack_damage_ratio", pick("ucs", "crack_damage_ratio")),
            ("friction_angle_deg", pick("envelope", "friction_angle_deg")),
            ("ucs_wall_s", pick("ucs", "wall_seconds")),
            ("tension_wall_s", pick("direct_tension", "wall_seconds")),
        ]:
            row[label] = interval(values)
        rows.append(row)
    return rows


def cell(v):
    mean, half, n = v
    if n == 0:
        return "—"
    if math.isnan(half):
        return f"{mean:.3g} (n 1)"
    return f"{mean:.3g} ± {half:.2g} (n {n})"


COLUMNS = [
    ("model", "bond model"),
    ("tensile_MPa", "cement tensile (MPa)"),
    ("shear_MPa", "cement shear (MPa)"),
    ("slit_fraction", "slit fraction"),
    ("ucs_MPa", "UCS (MPa)"),
    ("tensile_strength_MPa", "sigma_t direct (MPa)"),
    ("ucs_over_tensile", "UCS / sigma_t"),
    ("young_modulus_MPa", "E tangent 50% (MPa)"),
    ("poisson_ratio", "nu tangent 50%"),
    ("crack_damage_ratio", "sigma_cd / UCS"),
    ("friction_angle_deg", "friction angle (deg)"),
    ("ucs_wall_s", "UCS run (s)"),
    ("tension_wall_s", "tension run (s)"),
]


def write(rows, out):
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "reach.csv"), "w", newline="") as f:
        w = csv.writer(f)
        head = []
        for key, _ in COLUMNS:
            if isinstance(rows[0][key], tuple):
                head += [key + "_mean", key + "_ci95", key + "_n"]
            else:
                head.append(key)
        w.writerow(head)
        for r in rows:
            line = []
            for key, _ in COLUMNS:
                line += list(r[key]) if isinstance(r[key], tuple) else [r[key]]
            w.writerow(line)
    cells = lambda r: [r[k] if isinstance(r[k], str) else cell(r[k]) for k, _ in COLUMNS]
    with open(os.path.join(out, "index.html"), "w") as f:
        f.write("<!doctype html><meta charset=utf-8><title>What each bond model reaches</title>\n")
        f.write("<h1>What each bond model reaches</h1>\n<p>The same 3D bonded sphere pack "
                "(protocols/ucs-3d-quick.toml, direct-tension-3d-quick.toml, triaxial-spheres-3d-quick.toml) "
                "with each bond model and cement: mean ± 95% interval over the seeds (n); "
                "UCS / sigma_t taken seed by seed; the friction angle of the Mohr-Coulomb line "
                "through the peaks at 0 and 5 MPa. Rocks: UCS / sigma_t 8 to 20 (Potyondy 2012). "
                "Regenerated by tests/bond_model_reach.py.</p>\n<table border=1>")
        f.write("<tr>" + "".join(f"<th>{html.escape(h)}</th>" for _, h in COLUMNS) + "</tr>\n")
        for r in rows:
            f.write("<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in cells(r)) + "</tr>\n")
        f.write("</table>\n")
    print("| " + " | ".join(h for _, h in COLUMNS) + " |")
    print("|" + "---|" * len(COLUMNS))
    for r in rows:
        print("| " + " | ".join(cells(r)) + " |")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lab", required=True, help="the notebook the campaigns ran into")
    ap.add_argument("--out", default="build/bond-model-reach", help="the report's folder")
    a = ap.parse_args()
    db = sqlite3.connect(f"file:{a.lab}?mode=ro", uri=True)
    runs = runs_by_material(db)
    if not runs:
        sys.exit(f"{a.lab}: no completed run of a bond-model-reach campaign")
    write(table(runs), a.out)


if __name__ == "__main__":
    main()
