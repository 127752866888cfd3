#!/usr/bin/env python3
"""What a campaign costs besides its runs, and what the local pool gains (issue 26).

  tests/bench_campaign.py [--rocklab build/release/rocklab] [--out build/bench-campaign]
                          [--repeat 3] [--protocol protocols/hydrostatic-quick.toml]

1. Speed-up: eight one-thread runs of the protocol (seeds 1 to 8), one
   after another with `rocklab run`, against the same eight as `campaign run --jobs 2`;
   the two alternate, `--repeat` times each, and the medians are compared.
2. Overhead per run (start, shard, merge): a `campaign run --jobs 1` of the eight, its wall
   time less the runs' own (runs.wall_seconds), over the eight.
3. The merge of 100 shards: 100 copies of one run's notebook, each its run's uuid drawn anew,
   merged by one `rocklab notebook merge`.

A benchmark, not a test: it prints what it measured and asserts nothing.
"""
import argparse
import os
import shutil
import sqlite3
import statistics
import subprocess
import time
import uuid

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.dirname(HERE)


def run(args):
    t0 = time.monotonic()
    subprocess.run(args, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.monotonic() - t0


def fresh(path):
    for p in [path, path + "-wal", path + "-shm"]:
        if os.path.exists(p):
            os.remove(p)
    for d in [path + ".files", path + ".campaigns"]:
        shutil.rmtree(d, ignore_errors=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rocklab", default=os.path.join(SOURCE, "build", "release", "rocklab"))
    ap.add_argument("--out", default=os.path.join(SOURCE, "build", "bench-campaign"))
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--protocol", default=os.path.join(SOURCE, "protocols", "hydrostatic-quick.toml"),
                    help="a quick protocol: the shorter its runs, the more the overhead weighs")
    a = ap.parse_args()
    protocol = os.path.abspath(a.protocol)
    os.makedirs(a.out, exist_ok=True)
    rl = a.rocklab
    campaign = os.path.join(a.out, "eight.toml")
    with open(campaign, "w") as f:
        f.write('[campaign]\nname = "eight"\nprotocol = "%s"\nseeds = [1, 2, 3, 4, 5, 6, 7, 8]\n'
                'threads = 1\n' % protocol)
    lab = os.path.join(a.out, "lab.sqlite")

    sequential, pooled = [], []
    for _ in range(a.repeat):
        fresh(lab)
        t = 0.0
        for seed in range(1, 9):
            t += run([rl, "run", protocol, "--quiet", "--threads", "1", "--set",
                      "protocol.seed=%d" % seed, "--lab", lab])
        sequential.append(t)
        fresh(lab)
        pooled.append(run([rl, "campaign", "run", campaign, "--jobs", "2", "--quiet", "--lab",
                           lab]))
    s, p = statistics.median(sequential), statistics.median(pooled)
    print("eight one-thread runs: one after another %.1f s, campaign --jobs 2 %.1f s "
          "(medians of %d): %.2fx" % (s, p, a.repeat, s / p))

    fresh(lab)
    wall = run([rl, "campaign", "run", campaign, "--jobs", "1", "--quiet", "--lab", lab])
    own = sqlite3.connect(lab).execute("SELECT sum(wall_seconds) FROM runs").fetchone()[0]
    print("campaign --jobs 1: %.2f s for runs of %.2f s: %.3f s per run besides the run "
          "(start, shard, merge)" % (wall, own, (wall - own) / 8))

    one = os.path.join(a.out, "one.sqlite")
    fresh(one)
    run([rl, "run", os.path.join(SOURCE, "protocols", "hydrostatic-quick.toml"), "--quiet",
         "--set", "sample.count=300", "--lab", one])
    shards = []
    for k in range(100):
        s = os.path.join(a.out, "shard-%03d.sqlite" % k)
        fresh(s)
        shutil.copy(one, s)
        if os.path.isdir(one + ".files"):
            shutil.copytree(one + ".files", s + ".files")
        c = sqlite3.connect(s)
        c.execute("UPDATE runs SET uuid = ?", (uuid.uuid4().hex,))
        c.commit()
        c.close()
        shards.append(s)
    merged = os.path.join(a.out, "merged.sqlite")
    fresh(merged)
    t = run([rl, "notebook", "merge"] + shards + ["--lab", merged])
    n = sqlite3.connect(merged).execute("SELECT count(*) FROM runs").fetchone()[0]
    print("merge of 100 shards: %.2f s (%d runs in the lab, %.1f ms a shard)" % (t, n, t * 10))


if __name__ == "__main__":
    main()
