"""poolsim: exact, event-driven simulation of pool balls and hard disks, with numpy arrays.

The package runs the poolsim library (Rust) in the calling process, with Python's lock
released while an engine runs, and returns its results as numpy arrays::

    import poolsim
    r = poolsim.run("gas", until=4)
    r["final_state_digest"]          # the command line's summary, as a dict
    r.events                         # structured array: t, kind, a, b
    r.final.position                 # (N, 2) array of the balls at the end

Scenarios are the command line's: a built-in name (``poolsim.builtins()``), the path of a TOML
file, TOML text, or a :class:`Scenario` made from arrays. Bad input raises ``ValueError`` with
the command line's one-line message.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Iterator, Sequence

import numpy as np

from . import _native

__all__ = [
    "EVENT_DTYPE",
    "Sample",
    "Table",
    "EVENT_KINDS",
    "EventStream",
    "Result",
    "Scenario",
    "State",
    "Packing",
    "builtins",
    "compress",
    "experiment",
    "phold",
    "run",
    "stream",
    "read_xyz",
    "to_gsd",
    "write_xyz",
]

#: Names of the event kinds, indexed by the ``kind`` field of an event array.
EVENT_KINDS: tuple[str, ...] = tuple(_native.event_kinds())

#: The dtype of an event array: time, kind (an index into :data:`EVENT_KINDS`), the ball, and
#: the other object's index within its kind (a ball, cushion, pocket or corner, from 0).
EVENT_DTYPE = np.dtype([("t", "<f8"), ("kind", "u1"), ("a", "<u4"), ("b", "<u4")])


@dataclass(frozen=True)
class State:
    """Every ball at one time.

    ``position`` and ``velocity`` are ``(N, 2)`` float arrays; ``radius`` and ``mass`` have one
    entry per ball; ``pocket`` is the pocket (from 0) a ball dropped into, -1 for a ball still
    on the table (whose position is where its centre crossed the pocket line). In a periodic
    box, a sample's ``image`` is an ``(N, 2)`` int array: the whole sides from each position (in
    the box) to the ball's unwrapped position; ``None`` elsewhere.
    """

    t: float
    position: np.ndarray
    velocity: np.ndarray
    radius: np.ndarray
    mass: np.ndarray
    pocket: np.ndarray
    image: np.ndarray | None = None

    @classmethod
    def _of(cls, d: dict[str, Any]) -> State:
        return cls(d["t"], d["position"], d["velocity"], d["radius"], d["mass"], d["pocket"],
                   d.get("image"))


@dataclass(frozen=True)
class Table:
    """A table's geometry: ``cushions`` and ``pockets`` as ``(M, 2, 2)`` arrays of segment ends,
    and the corners ``lo`` and ``hi`` of its bounding box; ``periodic`` when it is a periodic box
    (no cushions, and ``lo``, ``hi`` the box)."""

    cushions: np.ndarray
    pockets: np.ndarray
    lo: tuple[float, float]
    hi: tuple[float, float]
    periodic: bool = False

    @classmethod
    def _of(cls, d: dict[str, Any]) -> Table:
        return cls(d["cushions"].reshape(-1, 2, 2), d["pockets"].reshape(-1, 2, 2), d["lo"], d["hi"],
                   bool(d.get("periodic", False)))


@dataclass(frozen=True)
class Sample:
    """One frame read from extended XYZ: the balls on the table (``id`` is each one's number,
    ``Ball-id``), the lattice's ``origin`` and ``size``; in a periodic box (``periodic``) each
    ball's ``image`` (whole sides to its unwrapped position; zeros otherwise)."""

    t: float
    origin: tuple[float, float]
    size: tuple[float, float]
    periodic: bool
    id: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    radius: np.ndarray
    mass: np.ndarray
    image: np.ndarray


def _events(columns: dict[str, np.ndarray] | None) -> np.ndarray | None:
    if columns is None:
        return None
    out = np.empty(len(columns["t"]), dtype=EVENT_DTYPE)
    for name in EVENT_DTYPE.names:
        out[name] = columns[name]
    return out


@dataclass(frozen=True)
class Result:
    """What a run produced.

    ``summary`` is the command line's ``--json`` summary (a dict); ``result[key]`` reads it.
    ``events`` is a structured array of :data:`EVENT_DTYPE` in the order the events happened
    (``None`` when the run was asked for none), ``final`` the balls at the end, ``samples`` the
    balls at each multiple of ``sample_every``, ``table`` the table they ran on.
    """

    summary: dict[str, Any]
    events: np.ndarray | None
    final: State
    samples: list[State]
    table: Table

    def __getitem__(self, key: str) -> Any:
        return self.summary[key]

    @property
    def digest(self) -> str:
        """The final state's digest: equal digests, bit-identical final states."""
        return self.summary["final_state_digest"]


@dataclass(frozen=True)
class Scenario:
    """A scenario as TOML text (the format of ``docs/formats.md``), to run with :func:`run`."""

    toml: str
    name: str = "scenario"

    @classmethod
    def from_file(cls, path: str | Path) -> Scenario:
        """The scenario in a TOML file (read now; errors name the file when it runs)."""
        p = Path(path)
        return cls(p.read_text(), str(p))

    @classmethod
    def from_arrays(
        cls,
        positions: Sequence[Sequence[float]] | np.ndarray,
        velocities: Sequence[Sequence[float]] | np.ndarray,
        cushions: Sequence[Sequence[Sequence[float]]] | np.ndarray,
        *,
        radius: float | Sequence[float] | np.ndarray = 1.0,
        mass: float | Sequence[float] | np.ndarray = 1.0,
        pockets: Sequence[Sequence[Sequence[float]]] | np.ndarray | None = None,
        elasticity: float | Sequence[float] | np.ndarray = 1.0,
        corner_elasticity: float | Sequence[float] | np.ndarray = 1.0,
        until: float = 10.0,
        name: str = "arrays",
    ) -> Scenario:
        """Balls on any table: ``positions`` and ``velocities`` ``(N, 2)``, ``radius`` and
        ``mass`` a number or one per ball; ``cushions`` and ``pockets`` ``(M, 2, 2)`` segments
        (from, to) wound with the table on their right, each with its ``elasticity`` (the
        pockets' for their corners), as the TOML format has them (``docs/formats.md``). Every
        number is written so that it reads back to the same bits; the library checks the
        table when the scenario runs, and names the field it refuses."""
        pos = np.asarray(positions, dtype=float)
        vel = np.asarray(velocities, dtype=float)
        if pos.ndim != 2 or pos.shape[1] != 2 or vel.shape != pos.shape:
            raise ValueError(
                f"positions, velocities: must both be (N, 2), got {pos.shape} and {vel.shape}"
            )
        n = len(pos)
        rad = np.broadcast_to(np.asarray(radius, dtype=float), (n,))
        mas = np.broadcast_to(np.asarray(mass, dtype=float), (n,))
        num = _toml_float
        lines = ["[run]", f"until = {num(until)}", ""]
        for k in range(n):
            lines += [
                "[[ball]]",
                f"position = [{num(pos[k, 0])}, {num(pos[k, 1])}]",
                f"velocity = [{num(vel[k, 0])}, {num(vel[k, 1])}]",
                f"radius = {num(rad[k])}",
                f"mass = {num(mas[k])}",
            ]
        for table, segments, e in [("cushion", cushions, elasticity),
                                   ("pocket", pockets, corner_elasticity)]:
            seg = np.asarray([] if segments is None else segments, dtype=float).reshape(-1, 2, 2)
            el = np.broadcast_to(np.asarray(e, dtype=float), (len(seg),))
            for (a, b), k in zip(seg, el):
                lines += [f"[[{table}]]", f"from = [{num(a[0])}, {num(a[1])}]",
                          f"to = [{num(b[0])}, {num(b[1])}]", f"elasticity = {num(k)}"]
        return cls("\n".join(lines) + "\n", name)

    @classmethod
    def box(
        cls,
        width: float,
        height: float,
        positions: Sequence[Sequence[float]] | np.ndarray,
        velocities: Sequence[Sequence[float]] | np.ndarray,
        radius: float | Sequence[float] | np.ndarray = 1.0,
        mass: float | Sequence[float] | np.ndarray = 1.0,
        until: float = 10.0,
        periodic: bool = False,
    ) -> Scenario:
        """Balls in a ``width`` x ``height`` box of elastic cushions with its corner at the
        origin (:meth:`from_arrays` with the box's four sides), or, if ``periodic``, in a
        periodic box (positions outside it are taken into it)."""
        w, h = float(width), float(height)
        if periodic:
            s = cls.from_arrays(positions, velocities, [], radius=radius, mass=mass, until=until,
                                name="box")
            box = f'[box]\nsize = [{_toml_float(w)}, {_toml_float(h)}]\nboundary = "periodic"\n'
            return cls(s.toml + box, "box")
        sides = [[(0.0, 0.0), (0.0, h)], [(0.0, h), (w, h)], [(w, h), (w, 0.0)],
                 [(w, 0.0), (0.0, 0.0)]]
        return cls.from_arrays(positions, velocities, sides, radius=radius, mass=mass,
                               until=until, name="box")


def _toml_float(x: float) -> str:
    x = float(x)
    if not math.isfinite(x):
        raise ValueError(f"not a finite number: {x}")
    return repr(x)


def _whole(name: str, value: Any, least: int) -> None:
    """Refuses a value that is not a whole number of at least ``least`` (``None`` passes)."""
    if value is None:
        return
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < least:
        raise ValueError(f"{name}: must be a whole number of at least {least}, got {value!r}")


def builtins() -> dict[str, str]:
    """The built-in scenarios: name to description."""
    return dict(_native.builtins())


def _ask(
    scenario: str | Path | Scenario,
    until: float | None,
    engine: str,
    dt: float | None,
    workers: int | None,
    sectors: str | tuple[int, int] | None,
    check: bool,
    sample_every: float | None,
    events: bool,
    params: dict[str, Any],
    observe: tuple[float | None, float | None] = (None, None),
) -> tuple[str, dict[str, Any]]:
    for name, value, least in [("balls", params.get("balls"), 1), ("seed", params.get("seed"), 0),
                               ("workers", workers, 1)]:
        _whole(name, value, least)
    if isinstance(scenario, Scenario):
        spec, text = scenario.name, scenario.toml
    else:
        spec, text = str(scenario), None
    if sectors not in (None, "auto") and not (
        isinstance(sectors, tuple) and len(sectors) == 2
    ):
        raise ValueError(f"sectors: None, 'auto' or (nx, ny), got {sectors!r}")
    ask = {
        "toml": text,
        "until": until,
        "engine": engine,
        "dt": dt,
        "workers": workers,
        "sectors": sectors if isinstance(sectors, tuple) else None,
        "auto_sectors": sectors == "auto",
        "check": check,
        "sample_every": sample_every,
        "observe_every": observe[0],
        "observe_from": observe[1],
        "events": events,
        "balls": params.get("balls"),
        "seed": params.get("seed"),
        "area_fraction": params.get("area_fraction"),
        "radius": params.get("radius"),
        "speed_max": params.get("speed_max"),
        "lattice": params.get("lattice"),
        "temperature": params.get("temperature"),
        "mixture": params.get("mixture"),
        "boundary": params.get("boundary"),
        "thermostat": params.get("thermostat"),
        "thermostat_rate": params.get("thermostat_rate"),
        "thermostat_seed": params.get("thermostat_seed"),
    }
    return spec, ask


def run(
    scenario: str | Path | Scenario = "gas",
    *,
    until: float | None = None,
    engine: str = "event-list",
    dt: float | None = None,
    workers: int | None = None,
    sectors: str | tuple[int, int] | None = None,
    check: bool = False,
    sample_every: float | None = None,
    observe_every: float | None = None,
    observe_from: float | None = None,
    events: bool = True,
    balls: int | None = None,
    seed: int | None = None,
    area_fraction: float | None = None,
    radius: float | None = None,
    speed_max: float | None = None,
    lattice: str | None = None,
    temperature: float | None = None,
    mixture: tuple[float, float] | None = None,
    boundary: str | None = None,
    thermostat: float | None = None,
    thermostat_rate: float | None = None,
    thermostat_seed: int | None = None,
) -> Result:
    """Runs a scenario to ``until`` (default: the scenario's own end) and returns its results.

    ``engine`` is ``"event-list"`` (the reference), ``"time-step"`` (needs ``dt``),
    ``"objects"``, ``"time-warp"`` (``workers`` threads) or ``"regions"`` (the event list cut
    into one strip per worker; one worker runs them in turn); ``sectors`` (``"auto"`` or
    ``(nx, ny)``) runs the objects on a sectored table. ``check`` checks invariants at every
    event. ``balls``, ``seed``, ``area_fraction``, ``radius``, ``speed_max``, ``lattice``
    (``"triangular"`` or ``"square"``), ``temperature``, ``mixture`` (``(F, Q)``: a fraction F
    of the disks Q times as wide) and ``boundary`` (``"walled"`` or ``"periodic"``) are the
    built-in generators' parameters (``builtins()`` says which each takes). ``observe_every`` (from ``observe_from``) adds the
    pressure, the compressibility factor ``z``, the temperature ``kt`` and the collision rate,
    each a block mean with its standard error, to ``summary["observables"]``. ``thermostat``
    (a kT) adds Andersen's thermostat on the event list: ``thermostat_rate`` kicks per disk and
    unit time (default 0.1) from the seed ``thermostat_seed`` (default 1). The engine runs
    with Python's lock released, so threads can run simulations side by side.
    """
    spec, ask = _ask(scenario, until, engine, dt, workers, sectors, check, sample_every, events,
                     dict(balls=balls, seed=seed, area_fraction=area_fraction, radius=radius,
                          speed_max=speed_max, lattice=lattice, temperature=temperature,
                          mixture=mixture, boundary=boundary, thermostat=thermostat,
                          thermostat_rate=thermostat_rate, thermostat_seed=thermostat_seed),
                     (observe_every, observe_from))
    d = _native.run(spec, ask)
    return Result(
        summary=json.loads(d["summary"]),
        events=_events(d["events"]),
        final=State._of(d["final"]),
        samples=[State._of(s) for s in d["samples"]],
        table=Table._of(d["table"]),
    )


@dataclass(frozen=True)
class Packing:
    """What :func:`compress` produced: why it ended (``ending``: ``"target"`` or
    ``"jammed"``), the compression's duration ``t``, the packing ``final`` (a :class:`State` at
    t = 0, velocities at kT = 1) in its periodic ``table``, and ``cycles``, a dict of arrays with
    one entry per cycle: ``t`` (its end), ``area_fraction``, ``z`` (its reduced pressure),
    ``kt`` (its mean temperature before the thermostat) and ``collisions``."""

    ending: str
    t: float
    final: State
    table: Table
    cycles: dict[str, np.ndarray]

    @property
    def area_fraction(self) -> float:
        """The fraction of the box the disks cover."""
        (x0, y0), (x1, y1) = self.table.lo, self.table.hi
        return float(np.pi * np.sum(self.final.radius ** 2) / ((x1 - x0) * (y1 - y0)))

    @property
    def z(self) -> float:
        """The last cycle's reduced pressure P A / (N kT)."""
        return float(self.cycles["z"][-1]) if len(self.cycles["z"]) else float("nan")

    def scenario(self, until: float = 10.0) -> Scenario:
        """The packing as a scenario in its periodic box, to :func:`run` on to ``until``."""
        (x0, y0), (x1, y1) = self.table.lo, self.table.hi
        return Scenario.box(x1 - x0, y1 - y0, self.final.position - np.array([x0, y0]),
                            self.final.velocity, radius=self.final.radius,
                            mass=self.final.mass, until=until, periodic=True)


def compress(
    scenario: str | Path | Scenario = "disks",
    *,
    rate: float = 0.01,
    target: float | None = None,
    max_pressure: float = 1e12,
    cycle_collisions: float = 2.0,
    check: bool = False,
    balls: int | None = None,
    seed: int | None = None,
    area_fraction: float | None = None,
    radius: float | None = None,
    lattice: str | None = None,
    temperature: float | None = None,
    mixture: tuple[float, float] | None = None,
    boundary: str | None = None,
) -> Packing:
    """Grows the disks of a periodic box (Lubachevsky-Stillinger, ``poolsim compress``) at
    ``rate`` (the smallest diameter gained per unit time, kT = m = 1) to the area fraction
    ``target``, or until a cycle's reduced pressure passes ``max_pressure`` (jammed), rescaling
    the velocities to kT = 1 every ``cycle_collisions`` collisions per disk. The ``disks``
    start is by default random (``lattice="random"``), periodic, at area fraction 0.2; the
    other keywords are :func:`run`'s. Runs with Python's lock released."""
    if scenario == "disks":
        boundary = boundary or "periodic"
        lattice = lattice or "random"
        area_fraction = area_fraction if area_fraction is not None else 0.2
    spec, ask = _ask(scenario, None, "event-list", None, None, None, check, None, False,
                     dict(balls=balls, seed=seed, area_fraction=area_fraction, radius=radius,
                          lattice=lattice, temperature=temperature, mixture=mixture,
                          boundary=boundary))
    d = _native.compress(spec, ask, rate, target, max_pressure, cycle_collisions)
    return Packing(ending=d["ending"], t=d["t"], final=State._of(d["final"]),
                   table=Table._of(d["table"]), cycles=dict(d["cycles"]))


class EventStream:
    """A run's events in chunks (structured arrays of :data:`EVENT_DTYPE`), as it goes.

    At most two chunks wait at any time, so memory stays bounded however long the run. After
    the last chunk, ``summary`` holds the run summary. ``close()`` (or leaving a ``with``
    block) stops a run that still goes on.
    """

    def __init__(self, native: Any) -> None:
        self._native = native

    def __iter__(self) -> Iterator[np.ndarray]:
        for columns in self._native:
            yield _events(columns)

    @property
    def summary(self) -> dict[str, Any] | None:
        """The run summary, once every chunk has been read."""
        s = self._native.summary
        return None if s is None else json.loads(s)

    def close(self) -> None:
        """Stops the run and waits for it."""
        self._native.close()

    def __enter__(self) -> EventStream:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def stream(
    scenario: str | Path | Scenario = "gas",
    *,
    chunk: int = 65536,
    until: float | None = None,
    engine: str = "event-list",
    dt: float | None = None,
    workers: int | None = None,
    sectors: str | tuple[int, int] | None = None,
    check: bool = False,
    balls: int | None = None,
    seed: int | None = None,
    area_fraction: float | None = None,
    radius: float | None = None,
    speed_max: float | None = None,
    lattice: str | None = None,
    temperature: float | None = None,
    mixture: tuple[float, float] | None = None,
    boundary: str | None = None,
) -> EventStream:
    """Starts a run in the background and returns its events in chunks of at most ``chunk``.

    Takes :func:`run`'s arguments (but samples and observables); bad input raises ``ValueError`` here, an error
    of the run itself when the chunk it stopped at is read.
    """
    spec, ask = _ask(scenario, until, engine, dt, workers, sectors, check, None, True,
                     dict(balls=balls, seed=seed, area_fraction=area_fraction, radius=radius,
                          speed_max=speed_max, lattice=lattice, temperature=temperature,
                          mixture=mixture, boundary=boundary))
    return EventStream(_native.stream(spec, ask, chunk))


def phold(
    *,
    objects: int = 1024,
    events_per_object: int = 16,
    remote: float = 0.1,
    lookahead: float = 0.1,
    mean: float = 1.0,
    seed: int = 1,
    end: float = 100.0,
    engine: str = "objects",
    workers: int | None = None,
    partitions: int | None = None,
) -> dict[str, Any]:
    """Runs PHOLD, the standard benchmark of parallel discrete-event simulators, on the
    sequential kernel (``"objects"``), Time Warp (``"time-warp"``) or the conservative
    executor (``"conservative"``, needs ``lookahead > 0``); returns ``poolsim phold --json``'s
    report as a dict. ``partitions`` defaults to the workers (2 on the sequential kernel).
    """
    for name, value, least in [("objects", objects, 1), ("events_per_object", events_per_object, 1),
                               ("seed", seed, 0), ("workers", workers, 1),
                               ("partitions", partitions, 1)]:
        _whole(name, value, least)
    return json.loads(
        _native.phold(
            objects=objects,
            events_per_object=events_per_object,
            remote=remote,
            lookahead=lookahead,
            mean=mean,
            seed=seed,
            end=end,
            engine=engine,
            workers=workers,
            partitions=partitions,
        )
    )


def _frames(states: State | Sequence[State]) -> list[State]:
    return [states] if isinstance(states, State) else list(states)


def write_xyz(path: str | Path, states: State | Sequence[State], table: Table) -> None:
    """Writes states as extended XYZ, the command line's ``--samples`` format (OVITO and ASE read
    it): one frame per state, the balls on the table, the lattice the table's bounding box."""
    frames = [
        (float(s.t), np.ascontiguousarray(s.position, dtype=float),
         np.ascontiguousarray(s.velocity, dtype=float), np.ascontiguousarray(s.radius, dtype=float),
         np.ascontiguousarray(s.mass, dtype=float), np.ascontiguousarray(s.pocket, dtype=np.int32),
         None if s.image is None else np.ascontiguousarray(s.image, dtype=np.int64))
        for s in _frames(states)
    ]
    _native.write_xyz(str(path), frames, tuple(map(float, table.lo)), tuple(map(float, table.hi)),
                      table.periodic)


def read_xyz(path: str | Path) -> list[Sample]:
    """Every frame of an extended XYZ file written by poolsim (or in its columns)."""
    return [Sample(**d) for d in _native.read_xyz(str(path))]


def to_gsd(path: str | Path, states: State | Sequence[State], table: Table) -> None:
    """Writes states as a GSD trajectory (HOOMD's format; needs the ``gsd`` package): one frame
    per state, 2D, the box the table's bounding box with positions relative to its centre,
    ``diameter`` twice the radius, the time in the log as ``poolsim/t``. GSD stores positions
    and velocities in single precision."""
    try:
        import gsd.hoomd
    except ImportError as e:
        raise ImportError("to_gsd needs the gsd package: python3 -m pip install gsd") from e
    lo, hi = np.asarray(table.lo, dtype=float), np.asarray(table.hi, dtype=float)
    centre, size = (lo + hi) / 2, hi - lo
    with gsd.hoomd.open(name=str(path), mode="w") as f:
        for step, s in enumerate(_frames(states)):
            on = np.asarray(s.pocket) < 0
            n = int(np.count_nonzero(on))
            frame = gsd.hoomd.Frame()
            frame.configuration.step = step
            frame.configuration.dimensions = 2
            frame.configuration.box = [size[0], size[1], 0.0, 0.0, 0.0, 0.0]
            frame.particles.N = n
            frame.particles.types = ["X"]
            frame.particles.typeid = np.zeros(n, dtype=np.uint32)
            pos = np.zeros((n, 3), dtype=np.float32)
            pos[:, :2] = s.position[on] - centre
            vel = np.zeros((n, 3), dtype=np.float32)
            vel[:, :2] = s.velocity[on]
            frame.particles.position = pos
            frame.particles.velocity = vel
            frame.particles.diameter = (2 * s.radius[on]).astype(np.float32)
            frame.particles.mass = s.mass[on].astype(np.float32)
            frame.log["poolsim/t"] = np.array([s.t], dtype=np.float64)
            f.append(frame)


def experiment(
    which: str = "thesis",
    out: str | Path = "experiment",
    *,
    quick: bool = False,
    seeds: int | None = None,
    balls: Sequence[int] | None = None,
    font: str | Path | None = None,
) -> dict[str, Any]:
    """Runs ``poolsim experiment``: ``"thesis"`` (chapter 6's tables 5-10 and chapter 7's
    figures 17-18 beside the thesis' own numbers), ``"reversal"`` (the reversal error against
    the quitting time, 4.6-4.7), ``"eos"`` (the hard-disk fluid's equation of state in a
    periodic box beside the literature) or ``"jamming"`` (the jammed area fraction of a binary
    disk mixture against the compression rate), writing tables, figures and a report into
    ``out``. ``quick`` runs the reduced grid CI runs; ``seeds`` and ``balls`` (square numbers)
    set the thesis' grid (for ``"eos"`` and ``"jamming"``, ``balls`` is one number of disks).
    Returns the data the run wrote (``results.json``, ``reversal.json``, ``eos.json`` or
    ``jamming.json``)."""
    _whole("seeds", seeds, 1)
    for b in balls or []:
        _whole("balls", b, 1)
    _native.experiment(which, Path(out), quick=quick, seeds=seeds,
                       balls=None if balls is None else list(balls),
                       font=None if font is None else Path(font))
    name = {"thesis": "results.json", "reversal": "reversal.json", "eos": "eos.json",
            "jamming": "jamming.json"}.get(
        which, "results.json")
    return json.loads((Path(out) / name).read_text())
