"""A racked break drawn: the built-in `pool` scenario at its start and its end, side by side.

    python3 python/examples/pool_break.py [OUT.png]

Needs matplotlib. Checks that the balls the picture leaves out are the ones the summary counts
as pocketed.
"""

import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import poolsim  # noqa: E402
from poolsim.plot import draw  # noqa: E402

out = sys.argv[1] if len(sys.argv) > 1 else "poolsim-break.png"
r = poolsim.run("pool", sample_every=5.0)
start, end = r.samples[0], r.final
pocketed = int(np.count_nonzero(end.pocket >= 0))
assert pocketed == r["events"]["ball-pocket"] > 0, (pocketed, r["events"])
fig, axes = plt.subplots(1, 2, figsize=(12, 3.6))
draw(start, r.table, axes[0], numbers=True, title="the break, t = 0")
draw(end, r.table, axes[1], numbers=True, title=f"t = {end.t:g}: {pocketed} balls pocketed")
fig.tight_layout()
fig.savefig(out, dpi=120)
print(f"{out}: {r['events']['total']} events, {pocketed} balls pocketed, digest {r.digest}")
