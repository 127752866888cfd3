#!/usr/bin/env python3
"""rocklab's pore network beside Yade's FlowEngine on the same packings (issue 31).

Not part of `make test`: timings are not assertions. Runs `rocklab bench --flow` and Yade's
data/peers/yade/flow.py alternately on each packing, one thread each, at least three times,
and prints the medians and their ratios. Both codes make the same calls: a first one
(triangulation, network, factorisation, solve) and a repeat one after every centre moved by
the same axial strain (rocklab measures the moved network on its triangulation and solves
it, keeping its factor; Yade triangulates anew, the only way it measures moved particles).
Yade's third call, on the same particles without a new mesh, is printed too ("reuse"). The
targets: rocklab's first call at most half of Yade's, its repeat call at most a quarter.

usage: tests/bench_flow.py [--runs N] [--rocklab PATH] [--strain E] [PACKING ...]
e.g.   tests/bench_flow.py       (data/peers/packing_3k.txt and packing_20k.txt.xz)

Yade comes from Debian, installed here when missing, without its recommended packages.
"""
import argparse
import json
import os
import re
import statistics
import subprocess
import tempfile

from bench_peers import PEERS, ROOT, check_runs_and_binary, ensure, plain

YADE_LINE = re.compile(r"yade flow: (\d+) spheres, (\d+) cells, first ([0-9.eE+-]+) s, "
                       r"repeat ([0-9.eE+-]+) s, reuse ([0-9.eE+-]+) s, k ([0-9.eE+-]+) m2")
ONE_THREAD = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")


def rocklab_calls(binary, packing, strain):
    out = subprocess.run([binary, "bench", "--packing", packing, "--flow", "--json",
                          "--flow-strain", str(strain)], check=True, capture_output=True,
                         text=True, env=ONE_THREAD).stdout
    flow = json.loads(out)["flow"]
    total = lambda c: c["network_seconds"] + c["solve_seconds"]
    return total(flow["first"]), total(flow["repeat"]), flow


def yade_calls(packing, strain):
    out = subprocess.run(["yade", "-j1", "-n", "-x", os.path.join(PEERS, "yade", "flow.py"),
                          packing, str(strain)], check=True, capture_output=True, text=True,
                         env=ONE_THREAD).stdout
    m = YADE_LINE.search(out)
    if not m:
        raise RuntimeError("no timing line in Yade's output:\n" + out[-2000:])
    return float(m[3]), float(m[4]), float(m[5]), int(m[2])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("packings", nargs="*",
                    default=[os.path.join(PEERS, "packing_3k.txt"),
                             os.path.join(PEERS, "packing_20k.txt.xz")])
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--strain", type=float, default=1e-4)
    ap.add_argument("--rocklab", default=os.path.join(ROOT, "build", "release", "rocklab"))
    a = ap.parse_args()
    check_runs_and_binary(a)
    ensure("yade", ["yade"])
    for source in a.packings:
        with tempfile.TemporaryDirectory() as tmp:
            packing = plain(source, tmp)
            r_first, r_repeat, y_first, y_repeat, y_reuse = [], [], [], [], []
            for k in range(a.runs):
                order = ["rocklab", "yade"] if k % 2 == 0 else ["yade", "rocklab"]
                for code in order:
                    if code == "rocklab":
                        first, repeat, flow = rocklab_calls(a.rocklab, packing, a.strain)
                        r_first.append(first), r_repeat.append(repeat)
                    else:
                        first, repeat, reuse, cells = yade_calls(packing, a.strain)
                        y_first.append(first), y_repeat.append(repeat), y_reuse.append(reuse)
            m = {name: statistics.median(v) for name, v in
                 [("rf", r_first), ("rr", r_repeat), ("yf", y_first), ("yr", y_repeat),
                  ("yu", y_reuse)]}
            print(f"{os.path.basename(source)}: rocklab {flow['pores']} pores, Yade {cells} "
                  f"cells; medians of {a.runs}, one thread, strain {a.strain:g}")
            print(f"  first call:  rocklab {m['rf']:.3f} s, Yade {m['yf']:.3f} s: "
                  f"{m['rf'] / m['yf']:.2f} of Yade's (target at most 0.5)")
            print(f"  repeat call: rocklab {m['rr']:.3f} s ({flow['repeat']['path']}, "
                  f"{flow['repeat']['iterations']} iterations), Yade {m['yr']:.3f} s "
                  f"(new mesh): {m['rr'] / m['yr']:.2f} of Yade's (target at most 0.25); "
                  f"Yade on its kept mesh {m['yu']:.3f} s: {m['rr'] / m['yu']:.2f}")
            print(f"  rocklab's repeat against a fresh factorisation: largest pressure "
                  f"difference {flow['repeat_max_difference']:.2g} of the drop, inflow "
                  f"{flow['repeat_permeability_difference']:.2g} relative", flush=True)


if __name__ == "__main__":
    main()
