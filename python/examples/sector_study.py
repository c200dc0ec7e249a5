"""Messages against sector size, the trend of the thesis' figure 18 (ch. 7): the sectored
objects engine on the 64-ball gas with k x k sectors, k = 1 .. 8.

    python3 python/examples/sector_study.py [OUT.png]

Few sectors mean many balls told of every change of course; many sectors mean many crossings.
The total is least between the two: here at 4 x 4 sectors, four balls per sector, where the
thesis' model of figure 18 puts the least near eight (`docs/experiment/report.md` compares the
model with these counts). Needs matplotlib for the plot; checks that the least lies inside the
range and that every k ends in the event list's final state.
"""

import sys

import poolsim

N, SIDES = 64, range(1, 9)
reference = poolsim.run("gas", balls=N, until=4, events=False).digest
totals = {}
for k in SIDES:
    r = poolsim.run("gas", balls=N, until=4, engine="objects", sectors=(k, k), events=False)
    assert r.digest == reference, k
    totals[k] = r["messages"]["total"]
    print(f"{k} x {k} sectors, {N / k**2:5.1f} balls per sector: {totals[k]:7d} messages")
best = min(totals, key=totals.get)
assert 1 < best < max(SIDES), totals
print(f"least at {best} x {best} sectors ({N / best**2:.1f} balls per sector)")

if len(sys.argv) > 1:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots()
    ax.plot([1 / k for k in SIDES], [totals[k] for k in SIDES], "o-")
    ax.set_xlabel("sector width s (table side 1)")
    ax.set_ylabel("messages to t = 4")
    ax.set_title(f"{N}-ball gas: messages against sector size")
    fig.savefig(sys.argv[1], dpi=120)
