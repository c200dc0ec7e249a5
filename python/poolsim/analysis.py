"""Structure and transport from a run's states, with numpy: the pair correlation function g(r)
of one state and the mean squared displacement over samples.

On a walled table g(r) counts only reference disks at least ``r_max`` from the table's box, so
that every annulus around them lies inside it (no edge correction needed), and displacements
are those of the disks' centres, which a wall bounds, so the mean squared displacement levels
off at the box's size. In a periodic box every disk is a reference, distances are to the
nearest image (``r_max`` at most half the shorter side), and displacements are unwrapped with
the samples' images.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

from . import State, Table


def pair_correlation(
    state: State, table: Table, r_max: float, bins: int = 100
) -> tuple[np.ndarray, np.ndarray]:
    """g(r) of the disks on the table in ``state``: returns the bins' centres and g there.

    The density is that of the disks on the table over the table's box; reference disks are
    those at least ``r_max`` from every side of the box (every disk in a periodic box), each
    paired with every other disk. Raises ``ValueError`` when no disk is that far inside, or
    when ``r_max`` exceeds half a periodic box's shorter side.
    """
    on = np.asarray(state.pocket) < 0
    pos = np.asarray(state.position)[on]
    (x0, y0), (x1, y1) = table.lo, table.hi
    size = np.array([x1 - x0, y1 - y0])
    if not (r_max > 0 and bins > 0):
        raise ValueError(f"r_max, bins: must be positive, got {r_max}, {bins}")
    if table.periodic and r_max > size.min() / 2:
        raise ValueError(f"r_max: at most half the periodic box's shorter side, {size.min() / 2}")
    inside = ((pos[:, 0] - x0 >= r_max) & (x1 - pos[:, 0] >= r_max)
              & (pos[:, 1] - y0 >= r_max) & (y1 - pos[:, 1] >= r_max))
    refs = np.arange(len(pos)) if table.periodic else np.flatnonzero(inside)
    if len(refs) == 0:
        raise ValueError(f"r_max: no disk lies {r_max} inside the table's box")
    density = len(pos) / ((x1 - x0) * (y1 - y0))
    edges = np.linspace(0.0, r_max, bins + 1)
    counts = np.zeros(bins)
    for i in refs:
        sep = pos - pos[i]
        if table.periodic:
            sep -= size * np.round(sep / size)
        d = np.hypot(*sep.T)
        d = d[(d > 0) & (d < r_max)]
        counts += np.histogram(d, bins=edges)[0]
    shells = np.pi * (edges[1:] ** 2 - edges[:-1] ** 2)
    g = counts / (len(refs) * density * shells)
    return (edges[1:] + edges[:-1]) / 2, g


def mean_squared_displacement(
    samples: Sequence[State], table: Table | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """The mean over the disks of |r(t) - r(t0)|^2 for each sample, t0 the first sample's time:
    returns the times since t0 and the displacements. Disks in a pocket by the last sample are
    left out. In a periodic box (``table.periodic``) positions are unwrapped with each sample's
    ``image``."""
    if not samples:
        raise ValueError("samples: at least one state is needed")
    keep = np.asarray(samples[-1].pocket) < 0

    def unwrapped(s: State) -> np.ndarray:
        pos = np.asarray(s.position, dtype=float)
        if table is not None and table.periodic:
            if s.image is None:
                raise ValueError("samples: a periodic box's samples need their images")
            size = np.asarray(table.hi, dtype=float) - np.asarray(table.lo, dtype=float)
            pos = pos + np.asarray(s.image) * size
        return pos[keep]

    first = unwrapped(samples[0])
    t = np.array([s.t - samples[0].t for s in samples])
    msd = np.array([np.mean(np.sum((unwrapped(s) - first) ** 2, axis=1)) for s in samples])
    return t, msd
