"""The equation of state of hard disks, measured in a walled box with error bars.

    python3 python/examples/eos.py [--balls 1024] [--until 80] [OUT.png]

For each area fraction the gas settles for 20 time units, then the compressibility factor
Z = P A / (N kT) from the collision virial is averaged over blocks of 6 time units
(``observe_every``; the error bars are the blocks' standard errors) and set beside Henderson's
equation of state for the fluid, (1 + eta^2 / 8) / (1 - eta)^2 (Mol. Phys. 30, 971, 1975), and
Liu's values at 0.3 and 0.5 (2.0637 and 4.1052; arXiv 2010.10624, 2020). A walled box is not
the bulk fluid: disks crowd against the cushions, which raises Z by about 1 % at 1,024 disks.
The example asserts agreement within 3 standard errors plus 2 % for that, and prints both.
"""

import argparse

import numpy as np

import poolsim

LIU = {0.3: 2.0637, 0.5: 4.1052}

p = argparse.ArgumentParser()
p.add_argument("--balls", type=int, default=1024)
p.add_argument("--until", type=float, default=80.0)
p.add_argument("out", nargs="?")
a = p.parse_args()

rows = []
for phi in [0.1, 0.2, 0.3, 0.4, 0.5]:
    r = poolsim.run("gas", balls=a.balls, area_fraction=phi, seed=2, until=a.until,
                    observe_every=6.0, observe_from=20.0, events=False)
    o = r["observables"]
    z, dz = o["z"]["mean"], o["z"]["error"]
    henderson = (1 + phi**2 / 8) / (1 - phi) ** 2
    rows.append((phi, z, dz, henderson))
    liu = f", Liu {LIU[phi]}" if phi in LIU else ""
    print(f"area fraction {phi}: Z = {z:.4f} +- {dz:.4f} over {o['blocks']} blocks "
          f"({o['collision_rate']['mean']:.3f} collisions per disk and unit time), "
          f"Henderson {henderson:.4f}{liu}")
    assert abs(z - henderson) < 3 * dz + 0.02 * henderson, (phi, z, dz, henderson)

if a.out:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    phi, z, dz, h = map(np.array, zip(*rows))
    fine = np.linspace(0, 0.55, 100)
    fig, ax = plt.subplots()
    ax.plot(fine, (1 + fine**2 / 8) / (1 - fine) ** 2, label="Henderson 1975")
    ax.plot(list(LIU), list(LIU.values()), "s", mfc="none", label="Liu 2020")
    ax.errorbar(phi, z, yerr=dz, fmt="o", label=f"poolsim, {a.balls} disks, walled box")
    ax.set_xlabel("area fraction")
    ax.set_ylabel("Z = P A / (N kT)")
    ax.legend()
    fig.savefig(a.out, dpi=120)
