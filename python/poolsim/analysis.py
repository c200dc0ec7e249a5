"""Structure and transport from a run's states, with numpy: the pair correlation function g(r)
and the hexatic order psi6 of one state, and the mean squared displacement and the velocity
autocorrelation over samples.

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


def hexatic_order(state: State, table: Table, chunk: int = 2048) -> tuple[np.ndarray, float]:
    """The bond-orientational order psi6 of the disks on the table in ``state``: for each disk
    ``psi6_j = (1/6) sum_k exp(6 i theta_jk)`` over its six nearest neighbours (the nearest images
    in a periodic box), ``theta_jk`` the angle of the bond from j to k; returns every disk's
    complex psi6 and the magnitude of their mean (1 on a perfect triangular lattice, near 0 in a
    fluid). The neighbours are found by brute force, ``chunk`` disks at a time: O(N^2) work, about
    a second for 10^4 disks."""
    on = np.asarray(state.pocket) < 0
    pos = np.asarray(state.position, dtype=float)[on]
    if len(pos) < 7:
        raise ValueError("state: psi6 needs at least 7 disks on the table")
    size = np.asarray(table.hi, dtype=float) - np.asarray(table.lo, dtype=float)
    psi = np.empty(len(pos), dtype=complex)
    for start in range(0, len(pos), chunk):
        block = pos[start:start + chunk]
        sep = pos[None, :, :] - block[:, None, :]
        if table.periodic:
            sep -= size * np.round(sep / size)
        d2 = np.einsum("ijk,ijk->ij", sep, sep)
        d2[np.arange(len(block)), np.arange(start, start + len(block))] = np.inf
        nearest = np.argpartition(d2, 6, axis=1)[:, :6]
        bonds = np.take_along_axis(sep, nearest[:, :, None], axis=1)
        theta = np.arctan2(bonds[:, :, 1], bonds[:, :, 0])
        psi[start:start + len(block)] = np.exp(6j * theta).mean(axis=1)
    return psi, float(abs(psi.mean()))


def velocity_autocorrelation(samples: Sequence[State]) -> tuple[np.ndarray, np.ndarray]:
    """The normalised velocity autocorrelation ``C(t) = <v(s) . v(s + t)> / <v(s) . v(s)>`` over
    the disks on the table in every sample and every pair of samples ``t`` apart (the samples
    evenly spaced, as ``sample_every`` gives them): returns the lags and C. Disks in a pocket by
    the last sample are left out."""
    if len(samples) < 2:
        raise ValueError("samples: at least two states are needed")
    keep = np.asarray(samples[-1].pocket) < 0
    v = np.stack([np.asarray(s.velocity, dtype=float)[keep] for s in samples])
    dt = samples[1].t - samples[0].t
    norm = np.mean(np.sum(v * v, axis=2))
    c = np.array([np.mean(np.sum(v[: len(v) - k] * v[k:], axis=2)) / norm
                  for k in range(len(v))])
    return dt * np.arange(len(v)), c
