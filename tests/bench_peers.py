#!/usr/bin/env python3
"""rocklab beside LIGGGHTS (and Yade) on the benchmark scene of data/peers/README.md.

Not part of `make test`: timings are not assertions. Runs rocklab and LIGGGHTS alternately
on the same packing, on one core and on two, at least three times each, and prints the
medians and their ratios (issue 27's targets: rocklab >= 2.5x LIGGGHTS on one core on the
10k and 50k packings, rocklab on two threads >= 1.85x its own one-core figure), the machine's
own ceiling for that figure (two one-thread runs at once against one alone: "2 runs/1"), and the
bonded variant of the scene against the unbonded one on one core (the bonded runs alternate
with the others, and the bonded scene's hash is checked once with the bonds one at a time,
`--scalar-bonds`).

usage: tests/bench_peers.py [--runs N] [--rocklab PATH] [--steps S] [--yade] [PACKING ...]
e.g.   tests/bench_peers.py                        (data/peers/packing_10k and _50k)
       tests/bench_peers.py --yade data/peers/packing_10k.txt.xz build/bench/packing_100k.txt

A packing ending in .xz (as shipped under data/peers) is decompressed into a temporary
folder first. LIGGGHTS and Yade come from Debian, installed here when missing, without their
recommended packages (ParaView conflicts with python3-vtk9, which libvtk9-dev needs). With
--yade, Yade's timing of the same scene (data/peers/yade/bench.py) runs alternately too.
"""
import argparse
import json
import lzma
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
PEERS = os.path.join(ROOT, "data", "peers")
YADE_LINE = re.compile(r"yade: (\d+) spheres, (\d+) steps, ([0-9.eE+-]+) s")
LOOP = re.compile(r"Loop time of ([0-9.eE+-]+) on (\d+) procs for (\d+) steps with (\d+) atoms")


def ensure(program, packages):
    if shutil.which(program):
        return
    sudo = [] if os.geteuid() == 0 else ["sudo"]
    print(f"installing {' '.join(packages)} (Debian, without recommends) ...", file=sys.stderr)
    subprocess.run(sudo + ["apt-get", "install", "-y", "-q", "--no-install-recommends",
                           *packages], check=True)


def check_runs_and_binary(a):
    """At least three runs (--runs) of a built rocklab (--rocklab)."""
    if a.runs < 3:
        sys.exit("--runs: at least 3 (medians of fewer say little on a shared machine)")
    if not os.access(a.rocklab, os.X_OK):
        sys.exit(a.rocklab + ": build rocklab first (make build)")


def plain(packing, tmp):
    """The packing file itself, or its decompressed copy in tmp when it ends in .xz."""
    if not packing.endswith(".xz"):
        return packing
    out = os.path.join(tmp, os.path.basename(packing)[:-3])
    with lzma.open(packing) as src, open(out, "wb") as dst:
        shutil.copyfileobj(src, dst)
    return out


def yade_rate(packing, threads, steps):
    out = subprocess.run(["yade", f"-j{threads}", "-n", "-x",
                          os.path.join(PEERS, "yade", "bench.py"), packing, str(steps)],
                         check=True, capture_output=True, text=True).stdout
    m = YADE_LINE.search(out)
    if not m:
        raise RuntimeError("no timing line in Yade's output:\n" + out[-2000:])
    return int(m.group(1)) * int(m.group(2)) / float(m.group(3))


def rocklab_rate(rocklab, packing, threads, steps, extra=()):
    out = subprocess.run([rocklab, "bench", "--packing", packing, "--threads", str(threads),
                          "--steps", str(steps), "--json", *extra],
                         check=True, capture_output=True, text=True).stdout
    run = json.loads(out)["runs"][0]
    return run["particle_steps_per_second"], run["state_hash"]


def rocklab_pair_rate(rocklab, packing, steps):
    """Two one-thread runs at once, their rates summed: what two cores of this machine give
    to two independent copies of the work (shared cache, memory bandwidth, the hypervisor's
    placement of the virtual cores), the most a second thread can add to one run."""
    cmd = [rocklab, "bench", "--packing", packing, "--threads", "1", "--steps", str(steps),
           "--json"]
    runs = [subprocess.Popen(cmd, stdout=subprocess.PIPE, text=True) for _ in range(2)]
    total = 0.0
    for p in runs:
        out, _ = p.communicate()
        if p.returncode != 0:
            raise RuntimeError(f"{' '.join(cmd)} failed ({p.returncode})")
        total += json.loads(out)["runs"][0]["particle_steps_per_second"]
    return total


def liggghts_rate(lig_dir, procs, steps):
    cmd = ["liggghts", "-in", os.path.join(PEERS, "liggghts", "in.bench"), "-var", "dir", lig_dir,
           "-var", "steps", str(steps), "-var", "warm", "100", "-var", "skin", "0.0002",
           "-log", "none"]
    if procs > 1:
        cmd = ["mpirun", "--allow-run-as-root", "--oversubscribe", "-np", str(procs)] + cmd
    out = subprocess.run(cmd, check=True, capture_output=True, text=True,
                         env=dict(os.environ, OMP_NUM_THREADS="1")).stdout
    loops = LOOP.findall(out)
    if not loops:
        raise RuntimeError("no 'Loop time' line in LIGGGHTS' output:\n" + out[-2000:])
    seconds, _, nsteps, atoms = loops[-1]
    return int(atoms) * int(nsteps) / float(seconds)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("packings", nargs="*", default=[
        os.path.join(PEERS, "packing_10k.txt.xz"), os.path.join(PEERS, "packing_50k.txt.xz")])
    ap.add_argument("--yade", action="store_true", help="time Yade too (slow: about 10x)")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--steps", type=int, default=2000)
    ap.add_argument("--rocklab", default=os.path.join(ROOT, "build", "release", "rocklab"))
    a = ap.parse_args()
    check_runs_and_binary(a)
    ensure("liggghts", ["liggghts", "openmpi-bin"])
    if a.yade:
        ensure("yade", ["yade"])
    rows = []
    for source in a.packings:
        with tempfile.TemporaryDirectory() as tmp:
            packing = plain(source, tmp)
            lig_dir = os.path.join(tmp, "lig")
            subprocess.run([sys.executable,
                            os.path.join(PEERS, "liggghts", "make_liggghts_input.py"), packing,
                            lig_dir], check=True, capture_output=True)
            r1, r2, rp, l1, l2, rb, y1 = [], [], [], [], [], [], []
            hashes, bonded_hashes = set(), set()
            for k in range(a.runs):
                # Alternate the codes so a slow spell of the machine hits both.
                l1.append(liggghts_rate(lig_dir, 1, a.steps))
                rate, h = rocklab_rate(a.rocklab, packing, 1, a.steps)
                r1.append(rate)
                hashes.add(h)
                l2.append(liggghts_rate(lig_dir, 2, a.steps))
                rate, h = rocklab_rate(a.rocklab, packing, 2, a.steps)
                r2.append(rate)
                hashes.add(h)
                rp.append(rocklab_pair_rate(a.rocklab, packing, a.steps))
                rate, h = rocklab_rate(a.rocklab, packing, 1, a.steps, ["--bonded"])
                rb.append(rate)
                bonded_hashes.add(h)
                if a.yade:
                    y1.append(yade_rate(packing, 1, a.steps))
                print(f"{os.path.basename(packing)} run {k + 1}: LIGGGHTS {l1[-1]:.3e} / "
                      f"{l2[-1]:.3e}, rocklab {r1[-1]:.3e} / {r2[-1]:.3e} (1 / 2 cores), "
                      f"two 1-thread runs at once {rp[-1]:.3e}, "
                      f"bonded {rb[-1]:.3e} (1 core)", file=sys.stderr)
            bonded_hashes.add(rocklab_rate(a.rocklab, packing, 1, a.steps,
                                           ["--bonded", "--scalar-bonds"])[1])
            med = {n: statistics.median(v) for n, v in
                   (("l1", l1), ("l2", l2), ("r1", r1), ("r2", r2), ("rp", rp), ("rb", rb),
                    ("y1", y1)) if v}
            same = len(hashes) == 1 and len(bonded_hashes) == 1
            rows.append((os.path.basename(packing), med, same))
    print(f"medians of {a.runs} alternating runs, particle-steps/s ({a.steps} timed steps)")
    print(f"{'packing':<18}{'LIGGGHTS 1':>12}{'rocklab 1':>12}{'ratio':>7}"
          f"{'LIGGGHTS 2':>12}{'rocklab 2':>12}{'ratio':>7}{'rocklab 2/1':>13}{'2 runs/1':>10}"
          f"{'bonded 1':>12}{'bonded/1':>10}  same hash")
    for name, m, same in rows:
        print(f"{name:<18}{m['l1']:>12.3e}{m['r1']:>12.3e}{m['r1'] / m['l1']:>7.2f}"
              f"{m['l2']:>12.3e}{m['r2']:>12.3e}{m['r2'] / m['l2']:>7.2f}"
              f"{m['r2'] / m['r1']:>13.2f}{m['rp'] / m['r1']:>10.2f}"
              f"{m['rb']:>12.3e}{m['rb'] / m['r1']:>10.2f}"
              f"  {'yes' if same else 'NO'}"
              + (f"   Yade 1 core {m['y1']:.3e}, rocklab / Yade {m['r1'] / m['y1']:.1f}"
                 if "y1" in m else ""))


if __name__ == "__main__":
    main()
