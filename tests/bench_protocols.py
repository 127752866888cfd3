#!/usr/bin/env python3
"""Time to result: the quick protocols with an old and a new rocklab, alternating (issue 27).

  tests/bench_protocols.py --old OLD/rocklab [--old-source OLD] [--new build/release/rocklab]
                           [--protocols hydrostatic-quick,biaxial-ucs-quick,...]
                           [--repeat 3] [--threads 2] [--out build/bench-protocols]
                           [--stages flow]

Each protocol (default: every protocols/*-quick.toml) runs --repeat times with each binary,
the two alternating (old first, then new first, and so on, so that a drift of the machine
weighs on both), each run into a fresh notebook. The old binary runs the protocol file of --old-source (its
source tree) when given: a protocol whose defaults moved to new keys runs as it was, which
is what a user of the old binary waited for. Printed per protocol: the median wall time
of each binary (the process's, what a user waits for), their ratio old / new, and each key
result of the new binary's last run against the seed scatter of the protocol's regression
reference (tests/reference/<protocol>.toml holds its values at eight seeds or more): inside
when it lies in the 95% prediction interval of one more seed, mean +- t(0.975, n - 1) s
sqrt(1 + 1/n).
A result the reference does not guard is listed as such. With --stages PREFIX, also the
median seconds of each stage timing of the notebook whose name starts with PREFIX (for
example the permeameter's flow, flow_network and flow_solve), for each binary.

Build the old binary from the commit to compare with, for example
  git worktree add /tmp/old 7434d0b && cmake -S /tmp/old -B /tmp/old/build -G Ninja
  -DCMAKE_BUILD_TYPE=Release -DROCKLAB_TESTS=OFF && ninja -C /tmp/old/build rocklab
  tests/bench_protocols.py --old /tmp/old/build/rocklab --old-source /tmp/old
A benchmark, not a test: it asserts nothing. Do not load the machine while it runs.
"""
import argparse
import glob
import math
import os
import shutil
import sqlite3
import statistics
import subprocess
import time
import tomllib

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.dirname(HERE)

# t(0.975, df), df = 1..30 (Abramowitz & Stegun, table 26.10); beyond, df = 30's (wider).
T975 = [12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228,
        2.201, 2.179, 2.160, 2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086,
        2.080, 2.074, 2.069, 2.064, 2.060, 2.056, 2.052, 2.048, 2.045, 2.042]


def fresh(path):
    for p in [path, path + "-wal", path + "-shm"]:
        if os.path.exists(p):
            os.remove(p)
    shutil.rmtree(path + ".files", ignore_errors=True)


def timed_run(binary, protocol, threads, lab):
    fresh(lab)
    t0 = time.monotonic()
    done = subprocess.run([binary, "run", protocol, "--quiet", "--threads", str(threads),
                           "--lab", lab], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                          text=True)
    seconds = time.monotonic() - t0
    if done.returncode != 0:
        raise SystemExit("%s %s failed (%d):\n%s" % (binary, protocol, done.returncode,
                                                     done.stderr[-2000:]))
    return seconds


def stage_timings(lab, prefix):
    """Seconds of the stage timings of run 1 whose stage name starts with prefix."""
    with sqlite3.connect(lab) as db:
        rows = db.execute("SELECT stage, seconds FROM stage_timings WHERE run_id = 1 AND "
                          "substr(stage, 1, length(?)) = ?", (prefix, prefix)).fetchall()
    return dict(rows)


def key_results(binary, lab):
    """The key results of run 1 of a notebook, as `notebook show --csv` gives them."""
    out = subprocess.run([binary, "notebook", "show", "1", "--csv", "--lab", lab],
                         check=True, capture_output=True, text=True).stdout
    values, inside = {}, False
    for line in out.splitlines():
        if line.startswith("key_result,"):
            inside = True
            continue
        if inside:
            if not line or line.startswith("key,"):
                break
            name, value, _unit = line.split(",", 2)
            values[name] = float(value) if value not in ("", "nan") else None
    return values


def scatter_verdict(name, value, reference):
    entry = reference.get(name)
    if entry is None or "values" not in entry:
        return "not guarded by the reference"
    seeds = entry["values"]
    n = len(seeds)
    if value is None:
        return "not recorded"
    if n < 2:
        return "the reference has one seed"
    mean = statistics.fmean(seeds)
    half = T975[min(n - 1, len(T975)) - 1] * statistics.stdev(seeds) * math.sqrt(1 + 1 / n)
    where = "inside" if abs(value - mean) <= half else "OUTSIDE"
    return "%s the seed interval %.6g +- %.3g" % (where, mean, half)


def reference_of(protocol_name):
    path = os.path.join(HERE, "reference", protocol_name + ".toml")
    if not os.path.exists(path):
        return {}
    with open(path, "rb") as f:
        results = tomllib.load(f).get("results", {})
    # Prefixed names ("stage1.vp_z") are quoted keys; unquoted they nest: flatten both.
    flat = {}

    def walk(table, prefix):
        for key, v in table.items():
            if isinstance(v, dict) and "values" not in v:
                walk(v, prefix + key + ".")
            else:
                flat[prefix + key] = v

    walk(results, "")
    return flat


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--old", required=True, help="the rocklab binary to compare with")
    ap.add_argument("--old-source", default=SOURCE,
                    help="source tree whose protocols/ the old binary runs")
    ap.add_argument("--new", default=os.path.join(SOURCE, "build", "release", "rocklab"))
    ap.add_argument("--protocols", default="",
                    help="comma-separated protocol names (default: every quick protocol)")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--out", default=os.path.join(SOURCE, "build", "bench-protocols"))
    ap.add_argument("--stages", default="",
                    help="also the median stage timings whose names start with this")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    if a.protocols:
        names = a.protocols.split(",")
    else:
        names = sorted(os.path.basename(p)[:-5]
                       for p in glob.glob(os.path.join(SOURCE, "protocols", "*-quick.toml")))
    ratios = []
    for name in names:
        protocol = {"old": os.path.join(a.old_source, "protocols", name + ".toml"),
                    "new": os.path.join(SOURCE, "protocols", name + ".toml")}
        times = {"old": [], "new": []}
        stages = {"old": {}, "new": {}}
        for k in range(a.repeat):
            order = ["old", "new"] if k % 2 == 0 else ["new", "old"]
            for which in order:
                binary = a.old if which == "old" else a.new
                lab = os.path.join(a.out, "%s-%s.sqlite" % (name, which))
                times[which].append(timed_run(binary, protocol[which], a.threads, lab))
                if a.stages:
                    for stage, seconds in stage_timings(lab, a.stages).items():
                        stages[which].setdefault(stage, []).append(seconds)
        old, new = statistics.median(times["old"]), statistics.median(times["new"])
        ratios.append(old / new)
        print("%s: old %.1f s, new %.1f s (medians of %d, %d threads): %.2fx"
              % (name, old, new, a.repeat, a.threads, old / new), flush=True)
        for stage in sorted(set(stages["old"]) | set(stages["new"])):
            o, n = (statistics.median(stages[w][stage]) if stages[w].get(stage) else float("nan")
                    for w in ("old", "new"))
            print("  stage %s: old %.3f s, new %.3f s" % (stage, o, n))
        reference = reference_of(name)
        for key, value in key_results(a.new, os.path.join(a.out, name + "-new.sqlite")).items():
            shown = "not recorded" if value is None else "%.6g" % value
            print("  %s = %s: %s" % (key, shown, scatter_verdict(key, value, reference)))
    if ratios:
        print("geometric mean of the ratios: %.2fx over %d protocols"
              % (math.exp(statistics.fmean(math.log(r) for r in ratios)), len(ratios)))


if __name__ == "__main__":
    main()
