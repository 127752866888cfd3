#!/usr/bin/env python3
"""Velocity drops of Figure 18's four waves from the bonds broken by orientation.

The contact (Voigt) estimate of an isotropic pack's stiffness,
C_ijkl = (1/V) sum [kn n_i n_j n_k n_l + kt (delta_ik n_j n_l - n_i n_j n_k n_l)]
(symmetrised in ij and kl), over contact normals n spread uniformly on the sphere. A
broken bond removes its share; v ~ sqrt(C), so each wave's velocity falls by
1 - sqrt(C_left / C_intact): vp_z from C_zzzz, vp_x from C_xxxx, vs_zx from C_xzxz,
vs_xy from C_xyxy. The broken fractions are given per class of the bond's angle to the
axis z, as the ultrasonic rig records them (stage.broken_fraction_axial_bonds: within 30
degrees of the axis; _inclined_bonds: 30-60 degrees; _lateral_bonds: within 30 degrees of
the plane normal to it).

  tests/contact_estimate.py AXIAL INCLINED LATERAL [--kt-over-kn R]

README, "Waves": with the full uniaxial-strain sample's 0.17 0.43 0.65 it gives
vp_z -20%, vp_x -35%, vs_zx -27%, vs_xy -35%.
"""
import argparse
import math
import random


def normals(count, seed=1):
    rng = random.Random(seed)
    for _ in range(count):
        z = rng.uniform(-1.0, 1.0)
        a = rng.uniform(0.0, 2.0 * math.pi)
        r = math.sqrt(1.0 - z * z)
        yield (r * math.cos(a), r * math.sin(a), z)


def stiffness(n, kn, kt, i, j, k, l):
    d = lambda a, b: 1.0 if a == b else 0.0
    sym = 0.25 * (d(i, k) * n[j] * n[l] + d(i, l) * n[j] * n[k] + d(j, k) * n[i] * n[l] +
                  d(j, l) * n[i] * n[k])
    return kn * n[i] * n[j] * n[k] * n[l] + kt * (sym - n[i] * n[j] * n[k] * n[l])


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("axial", type=float)
    p.add_argument("inclined", type=float)
    p.add_argument("lateral", type=float)
    p.add_argument("--kt-over-kn", type=float, default=1.0,
                   help="the bonds' ks / kn (the ultrasonic protocols: 1)")
    p.add_argument("--normals", type=int, default=100000)
    a = p.parse_args()
    cos30 = math.cos(math.pi / 6)

    def broken(n):
        c = abs(n[2])
        return a.axial if c >= cos30 else a.lateral if c <= 0.5 else a.inclined

    waves = {"vp_z": (2, 2, 2, 2), "vp_x": (0, 0, 0, 0), "vs_zx": (0, 2, 0, 2),
             "vs_xy": (0, 1, 0, 1)}
    ns = list(normals(a.normals))
    for name, idx in waves.items():
        intact = sum(stiffness(n, 1.0, a.kt_over_kn, *idx) for n in ns)
        left = sum(stiffness(n, 1.0, a.kt_over_kn, *idx) * (1.0 - broken(n)) for n in ns)
        print(f"{name}: {-100.0 * (1.0 - math.sqrt(left / intact)):+.1f}%")


if __name__ == "__main__":
    main()
