# Yade (2023.02a, Debian 12) FlowEngine on a benchmark packing (data/peers/README.md), timed
# the way `rocklab bench --flow` times rocklab's pore network: one steady Darcy solve along z
# (inlet 10 kPa at z max, outlet 0 at z min, no flow through the sides, CHOLMOD), then the
# network on the particles moved by an axial strain of STRAIN (every centre scaled towards
# the box's mid-height), solved again.
#
# usage: yade -n -x data/peers/yade/flow.py PACKING [STRAIN]
# Prints one line: "yade flow: N spheres, C cells, first T1 s, repeat T2 s, reuse T3 s, k K m2"
# - first: triangulation, conductances, factorisation and solve on a new engine;
# - repeat: after the move, triangulated anew (Yade measures the conductances on a new mesh
#   only) and solved;
# - reuse: one more call on the same particles without a new mesh (the factor is reused).
import sys
import time

from yade import utils

args = [a for a in sys.argv[1:] if not a.endswith("flow.py")]
packing = args[0]
strain = float(args[1]) if len(args) > 1 else 1e-4

rows = [l.split() for l in open(packing) if l.strip() and not l.startswith("#")]
n = int(rows[0][0])
box = [float(v) for v in rows[1]]
spheres = [[float(v) for v in r] for r in rows[2:2 + n]]
assert len(spheres) == n, "the packing lists fewer spheres than its count"

# The six boundaries first: FlowEngine's wallIds default to bodies 0..5 (x-, x+, y-, y+, z-, z+).
lo, hi = Vector3(box[0], box[2], box[4]), Vector3(box[1], box[3], box[5])
O.bodies.append(utils.aabbWalls([lo, hi], thickness=0))
ids = [O.bodies.append(utils.sphere((x, y, z), r)) for x, y, z, r in spheres]

VISCOSITY, DROP = 1e-3, 1e4
flow = FlowEngine(useSolver=3, viscosity=VISCOSITY, permeabilityFactor=1.0,
                  bndCondIsPressure=[0, 0, 0, 0, 1, 1], bndCondValue=[0, 0, 0, 0, 0, DROP],
                  boundaryUseMaxMin=[0, 0, 0, 0, 0, 0], meshUpdateInterval=10**9)
O.engines = [flow]
O.dt = 1e-7


def call():
    t = time.time()
    flow.emulateAction()
    return time.time() - t


first = call()
mid = 0.5 * (box[4] + box[5])
for i in ids:
    p = O.bodies[i].state.pos
    O.bodies[i].state.pos = Vector3(p[0], p[1], mid + (p[2] - mid) * (1.0 - strain))
flow.updateTriangulation = True
repeat = call()
reuse = call()
q = abs(flow.getBoundaryFlux(5))
area = (box[1] - box[0]) * (box[3] - box[2])
length = (box[5] - box[4]) * (1.0 - strain)
k = VISCOSITY * q * length / (area * DROP)
print("yade flow: %d spheres, %d cells, first %.4f s, repeat %.4f s, reuse %.4f s, k %.6g m2"
      % (n, flow.nCells(), first, repeat, reuse, k))
