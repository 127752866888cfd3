# Yade (2023.02a, Debian 12) input for the benchmark scene of data/peers/README.md: the same
# packing, Hertz-Mindlin with Tsuji-type damping from restitution 0.5, six frictionless
# walls moving in at a strain rate of 1 /s, dt 1.9e-7 s, 100 untimed and STEPS timed steps.
#
# usage: yade -n -x data/peers/yade/bench.py PACKING [STEPS] [SKIN_M]
#        yade -j2 -n -x ...            (two OpenMP threads)
# Prints one line: "yade: N spheres, S steps, T s, R particle-steps/s, Z0 Z1 p0 p1" with the
# coordination number and mean wall stress (Pa) at the start and end of the timed phase.
import math
import sys
import time

from yade import utils

RHO, E, NU, MU, EN = 2650.0, 70e9, 0.25, 0.5, 0.5
STRAIN_RATE, DT, WARM = 1.0, 1.9e-7, 100

args = [a for a in sys.argv[1:] if not a.endswith("bench.py")]
packing = args[0]
steps = int(args[1]) if len(args) > 1 else 2000
skin = float(args[2]) if len(args) > 2 else 2e-4

rows = [l.split() for l in open(packing) if l.strip() and not l.startswith("#")]
n = int(rows[0][0])
box = [float(v) for v in rows[1]]
spheres = [[float(v) for v in r] for r in rows[2:2 + n]]
assert len(spheres) == n, "the packing lists fewer spheres than its count"

grain = O.materials.append(FrictMat(young=E, poisson=NU, frictionAngle=math.atan(MU),
                                    density=RHO))
wall = O.materials.append(FrictMat(young=E, poisson=NU, frictionAngle=0.0, density=RHO))
for x, y, z, r in spheres:
    O.bodies.append(utils.sphere((x, y, z), r, material=grain))
# Planar walls at the inner faces, moving inward at edot * L / 2 (kinematic: fixed bodies
# move with their velocity).
walls = []
for axis in range(3):
    lo, hi = box[2 * axis], box[2 * axis + 1]
    v = STRAIN_RATE * (hi - lo) / 2.0
    for pos, sense, speed in ((lo, 1, v), (hi, -1, -v)):
        w = utils.wall(pos, axis=axis, sense=sense, material=wall)
        vel = Vector3(0, 0, 0)
        vel[axis] = speed
        w.state.vel = vel
        walls.append((O.bodies.append(w), axis))

O.engines = [
    ForceResetter(),
    InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Wall_Aabb()], verletDist=skin),
    InteractionLoop(
        [Ig2_Sphere_Sphere_ScGeom(), Ig2_Wall_Sphere_ScGeom()],
        [Ip2_FrictMat_FrictMat_MindlinPhys(en=EN, es=EN)],
        [Law2_ScGeom_MindlinPhys_Mindlin()]),
    NewtonIntegrator(damping=0.0),
]
O.dt = DT


def coordination():
    c = 0
    for i in O.interactions:
        if not i.isReal:
            continue
        if isinstance(O.bodies[i.id1].shape, Sphere) and isinstance(O.bodies[i.id2].shape, Sphere):
            c += i.geom.penetrationDepth > 0
    return 2.0 * c / n


def wall_stress():
    lengths = [box[2 * a + 1] - box[2 * a] - 2 * STRAIN_RATE * (box[2 * a + 1] - box[2 * a]) / 2
               * O.time for a in range(3)]
    s = 0.0
    for wid, axis in walls:
        others = [lengths[a] for a in range(3) if a != axis]
        s += abs(O.forces.f(wid, sync=True)[axis]) / (others[0] * others[1])
    return s / 6.0


O.run(WARM, True)
z0, p0 = coordination(), wall_stress()
t = time.time()
O.run(steps, True)
seconds = time.time() - t
z1, p1 = coordination(), wall_stress()
print("yade: %d spheres, %d steps, %.4f s, %.6g particle-steps/s, Z %.4f %.4f, p %.6g %.6g"
      % (n, steps, seconds, n * steps / seconds, z0, z1, p0, p1))
