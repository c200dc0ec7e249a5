"""Drawing a state with matplotlib (``python3 -m pip install matplotlib``): the table's
cushions and pockets, the balls as discs, optionally a sector grid and the balls' numbers."""

from __future__ import annotations

from typing import Any

import numpy as np

from . import State, Table


def draw(
    state: State,
    table: Table,
    ax: Any = None,
    *,
    sectors: tuple[int, int] | None = None,
    numbers: bool = False,
    title: str | None = None,
) -> Any:
    """Draws ``state`` on ``table`` into ``ax`` (a new figure's axes when ``None``) and returns
    the axes. Cushions are black lines, pockets red, balls on the table blue discs (balls in
    pockets are left out); ``sectors=(nx, ny)`` draws that grid over the table's box, grey and
    dashed; ``numbers`` writes each ball's number (``Ball-k`` is ``k``) on it."""
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection, PatchCollection
    from matplotlib.patches import Circle

    if ax is None:
        _, ax = plt.subplots()
    ax.add_collection(LineCollection(table.cushions, colors="black", linewidths=1.5))
    if len(table.pockets):
        ax.add_collection(LineCollection(table.pockets, colors="red", linewidths=3))
    on = np.flatnonzero(np.asarray(state.pocket) < 0)
    discs = [Circle(tuple(state.position[i]), state.radius[i]) for i in on]
    ax.add_collection(PatchCollection(discs, facecolor="tab:blue", edgecolor="navy", alpha=0.8))
    (x0, y0), (x1, y1) = table.lo, table.hi
    if sectors is not None:
        nx, ny = sectors
        for k in range(1, nx):
            ax.axvline(x0 + (x1 - x0) * k / nx, color="grey", linestyle="--", linewidth=0.8)
        for k in range(1, ny):
            ax.axhline(y0 + (y1 - y0) * k / ny, color="grey", linestyle="--", linewidth=0.8)
    if numbers:
        for i in on:
            ax.annotate(str(i + 1), tuple(state.position[i]), ha="center", va="center", fontsize=7)
    pad = 0.02 * max(x1 - x0, y1 - y0)
    ax.set_xlim(x0 - pad, x1 + pad)
    ax.set_ylim(y0 - pad, y1 + pad)
    ax.set_aspect("equal")
    ax.set_title(title if title is not None else f"t = {state.t:g}")
    return ax
