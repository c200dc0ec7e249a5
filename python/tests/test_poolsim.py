"""The Python package against the command line: same digests, arrays of the right shapes and
types, errors as ValueError, streams in bounded memory, threads side by side."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest

import poolsim

ROOT = Path(__file__).resolve().parents[2]
BINARY = Path(os.environ.get("POOLSIM_BIN", ROOT / "target" / "release" / "poolsim"))


def cli_json(*args: str) -> dict:
    """The command line's --json output (the binary built by `cargo build --release`)."""
    assert BINARY.exists(), f"build the command first (cargo build --release): {BINARY}"
    out = subprocess.run([str(BINARY), *args, "--json"], check=True, capture_output=True, text=True)
    return json.loads(out.stdout)


def test_the_readme_line_gives_the_command_lines_digest():
    r = poolsim.run("gas", until=4)
    assert r["final_state_digest"] == cli_json("run", "gas", "--until", "4")["final_state_digest"]
    assert r.digest == r["final_state_digest"]


@pytest.mark.parametrize(
    "engine, extra",
    [
        ("event-list", {}),
        ("objects", {}),
        ("objects", {"sectors": "auto"}),
        ("objects", {"sectors": (2, 3)}),
        ("time-warp", {"workers": 2}),
        ("time-warp", {"workers": 3, "sectors": "auto"}),
        ("regions", {"workers": 1}),
        ("regions", {"workers": 2}),
    ],
)
def test_every_engine_ends_in_the_event_lists_state(engine, extra):
    reference = poolsim.run("gas", balls=100, seed=3, until=3)
    r = poolsim.run("gas", balls=100, seed=3, until=3, engine=engine, **extra)
    assert r.digest == reference.digest
    assert np.array_equal(r.events, reference.events)


def test_events_are_a_structured_array_in_time_order():
    r = poolsim.run("gas", balls=400, until=5)
    ev = r.events
    assert ev.dtype == poolsim.EVENT_DTYPE
    assert len(ev) == r["events"]["total"] > 1000
    assert np.all(np.diff(ev["t"]) >= 0)
    for k, name in enumerate(poolsim.EVENT_KINDS):
        assert np.count_nonzero(ev["kind"] == k) == r["events"][name]
    bb = ev[ev["kind"] == poolsim.EVENT_KINDS.index("ball-ball")]
    assert np.all(bb["a"] < bb["b"]) and np.all(bb["b"] < 400)
    cushions = ev[ev["kind"] == poolsim.EVENT_KINDS.index("ball-cushion")]
    assert np.all(cushions["b"] < 4)


def test_final_state_and_samples_have_their_shapes_and_times():
    r = poolsim.run("gas", balls=64, until=2, sample_every=0.5)
    f = r.final
    assert f.t == 2.0
    assert f.position.shape == (64, 2) and f.position.dtype == np.float64
    assert f.velocity.shape == (64, 2)
    assert f.radius.shape == (64,) and f.mass.shape == (64,)
    assert np.all(f.pocket == -1)
    assert [s.t for s in r.samples] == [0.0, 0.5, 1.0, 1.5, 2.0]
    assert np.array_equal(r.samples[-1].position, f.position)
    # kinetic energy is kept (elastic collisions)
    e = [float(np.sum(s.mass * np.sum(s.velocity**2, axis=1))) for s in r.samples]
    assert max(e) - min(e) <= 1e-9 * e[0]
    fixed = cli_json("run", "gas", "--balls", "64", "--until", "2")
    assert r.digest == fixed["final_state_digest"]


def test_a_scenario_from_arrays_runs_as_its_physics_says():
    sc = poolsim.Scenario.box(
        100.0, 100.0, [[20.0, 50.0], [60.0, 50.0]], [[1.0, 0.0], [-1.0, 0.0]], radius=5.0, until=20
    )
    r = poolsim.run(sc)
    first = r.events[0]
    assert poolsim.EVENT_KINDS[first["kind"]] == "ball-ball"
    assert first["t"] == 15.0
    # head on, equal masses: the velocities swap
    assert np.array_equal(r.final.velocity, np.array([[-1.0, 0.0], [1.0, 0.0]]))
    with pytest.raises(ValueError, match="positions, velocities"):
        poolsim.Scenario.box(10, 10, [[1, 2, 3]], [[1, 2, 3]])


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: poolsim.run("no-such-scenario"), "not a built-in scenario"),
        (lambda: poolsim.run("gas", balls=-3), "balls: must be a whole number"),
        (lambda: poolsim.run("gas", until=-1.0), "until: must be a finite number"),
        (lambda: poolsim.run("gas", engine="warp"), "engine: one of"),
        (lambda: poolsim.run("gas", engine="time-step"), "dt: the time-step engine needs"),
        (lambda: poolsim.run("gas", workers=2), "workers: the event-list engine does not"),
        (lambda: poolsim.run(poolsim.Scenario("[[ball]]\nposition = [1.0]\n", "bad.toml")),
         "bad.toml:2"),
        (lambda: poolsim.phold(engine="conservative", lookahead=0.0), "positive lookahead"),
        (lambda: poolsim.phold(remote=2.0), "remote: must lie in"),
    ],
)
def test_bad_input_raises_value_error_with_one_line(call, message):
    with pytest.raises(ValueError, match=message) as e:
        call()
    assert "\n" not in str(e.value)


def test_a_stream_gives_the_runs_events_in_chunks():
    whole = poolsim.run("gas", balls=400, until=5)
    s = poolsim.stream("gas", balls=400, until=5, chunk=1000)
    chunks = list(s)
    assert all(0 < len(c) <= 1000 for c in chunks)
    assert np.array_equal(np.concatenate(chunks), whole.events)
    assert s.summary["final_state_digest"] == whole.digest


def test_a_stream_closed_early_stops_its_run():
    with poolsim.stream("gas", balls=2000, until=1e6, chunk=500) as s:
        first = next(iter(s))
        assert len(first) == 500
    assert s.summary is None


def test_a_long_stream_stays_in_bounded_memory():
    # a fresh interpreter, so that its peak is this stream's: 2.4 M events would take 41 MB as
    # arrays; chunks of 10,000 keep at most three
    script = """
import resource, poolsim
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
n = sum(len(c) for c in poolsim.stream("gas", balls=10000, until=320, chunk=10000))
after = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
print(n, (after - before) / 1024)
"""
    out = subprocess.run([sys.executable, "-c", script], check=True, capture_output=True, text=True)
    events, grown_mib = out.stdout.split()
    assert int(events) > 2_000_000
    assert float(grown_mib) < 40, f"{grown_mib} MiB grown over {events} events"


def test_threads_run_side_by_side_with_the_same_answers():
    seeds = [1, 2, 3, 4]
    alone = {s: poolsim.run("gas", balls=900, seed=s, until=4).digest for s in seeds}
    got: dict[int, str] = {}

    def one(seed: int) -> None:
        got[seed] = poolsim.run("gas", balls=900, seed=seed, until=4).digest

    threads = [threading.Thread(target=one, args=(s,)) for s in seeds]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert got == alone


def test_phold_on_every_executor_gives_the_sequential_digest():
    seq = poolsim.phold(objects=256, end=10, partitions=2)
    assert seq["engine"] == "objects" and seq["committed"] > 0
    for engine in ["time-warp", "conservative"]:
        r = poolsim.phold(objects=256, end=10, partitions=2, engine=engine, workers=2)
        assert r["engine"] == engine
        assert r["final_state_digest"] == seq["final_state_digest"]
    cli = cli_json("phold", "--objects", "256", "--end", "10", "--partitions", "2")
    assert cli["final_state_digest"] == seq["final_state_digest"]


def test_builtins_are_listed_with_descriptions():
    b = poolsim.builtins()
    assert {"gas", "plate1", "implosion"} <= set(b)
    assert all(isinstance(v, str) and v for v in b.values())


def test_samples_written_from_python_are_the_command_lines_byte_for_byte(tmp_path):
    r = poolsim.run("pool", sample_every=0.5)
    mine = tmp_path / "mine.xyz"
    poolsim.write_xyz(mine, r.samples, r.table)
    theirs = tmp_path / "theirs.xyz"
    subprocess.run(
        [str(BINARY), "run", "pool", "--samples", str(theirs), "--sample-every", "0.5", "--quiet"],
        check=True,
    )
    assert mine.read_bytes() == theirs.read_bytes()
    back = poolsim.read_xyz(mine)
    assert [s.t for s in back] == [s.t for s in r.samples]
    last, on = back[-1], r.final.pocket < 0
    assert np.array_equal(last.id, np.flatnonzero(on) + 1)
    assert np.array_equal(last.position, r.final.position[on])
    assert np.array_equal(last.velocity, r.final.velocity[on])
    assert last.origin == r.table.lo


def test_a_bad_xyz_file_names_its_line(tmp_path):
    bad = tmp_path / "bad.xyz"
    bad.write_text("2\nTime=0.0\nX 1 2\n")
    with pytest.raises(ValueError, match="bad.xyz:"):
        poolsim.read_xyz(bad)


def test_gsd_holds_the_states_in_single_precision(tmp_path):
    import gsd.hoomd as gsd_hoomd

    r = poolsim.run("gas", balls=64, until=2, sample_every=1.0)
    path = tmp_path / "run.gsd"
    poolsim.to_gsd(path, r.samples, r.table)
    centre = (np.asarray(r.table.lo) + np.asarray(r.table.hi)) / 2
    with gsd_hoomd.open(str(path)) as f:
        assert len(f) == 3
        for frame, s in zip(f, r.samples):
            assert frame.configuration.dimensions == 2
            assert frame.log["poolsim/t"][0] == s.t
            got = frame.particles.position[:, :2].astype(float) + centre
            assert np.allclose(got, s.position, rtol=0, atol=1e-4 * np.abs(s.position).max())
            assert np.allclose(frame.particles.diameter, 2 * s.radius)


def test_a_state_is_drawn_with_its_table_and_balls():
    import matplotlib

    matplotlib.use("Agg")
    from poolsim.plot import draw

    r = poolsim.run("pool")
    ax = draw(r.final, r.table, sectors=(2, 2), numbers=True)
    lines, pockets, discs = ax.collections
    assert len(lines.get_segments()) == len(r.table.cushions) == 6
    assert len(pockets.get_segments()) == len(r.table.pockets) == 6
    on_table = int(np.count_nonzero(r.final.pocket < 0))
    assert len(discs.get_paths()) == on_table
    assert len(ax.texts) == on_table


def test_observables_are_the_command_lines():
    r = poolsim.run("gas", balls=100, until=6, observe_every=2.0, observe_from=0.0)
    o = r["observables"]
    assert o["blocks"] == 3 and o["z"]["mean"] > 1.0
    cli = cli_json("run", "gas", "--balls", "100", "--until", "6", "--observe-every", "2")
    assert o == cli["observables"]
    with pytest.raises(ValueError, match="observe_from: needs observe_every"):
        poolsim.run("gas", observe_from=1.0)
    with pytest.raises(ValueError, match="observe_every: must be a positive number"):
        poolsim.run("gas", observe_every=-1.0)


def test_a_pool_table_from_arrays_runs_as_the_toml_one():
    # the built-in racked break, rebuilt from its own arrays
    r = poolsim.run("pool", until=0.0)
    start = r.final
    sc = poolsim.Scenario.from_arrays(
        start.position, start.velocity, r.table.cushions, radius=start.radius, mass=start.mass,
        pockets=r.table.pockets, until=5.0,
    )
    again = poolsim.run(sc)
    reference = poolsim.run("pool")
    assert np.array_equal(again.events, reference.events)
    assert np.array_equal(again.final.position, reference.final.position)
    bad = poolsim.Scenario.from_arrays([[1.0, 1.0]], [[0.0, 0.0]], [[[0, 0], [0, 0]]])
    with pytest.raises(ValueError, match=r"cushion\[1\]"):
        poolsim.run(bad)


def test_the_thesis_experiment_runs_from_python(tmp_path):
    results = poolsim.experiment("thesis", tmp_path / "thesis", quick=True)
    assert (tmp_path / "thesis" / "report.md").exists()
    assert results["plan"]["balls"] == [4, 16]
    with pytest.raises(ValueError, match="which: thesis, reversal, eos or jamming"):
        poolsim.experiment("nope", tmp_path / "x")
    eos = poolsim.experiment("eos", tmp_path / "eos", quick=True)
    assert [p["area_fraction"] for p in eos["points"]] == [0.3, 0.5]
    assert (tmp_path / "eos" / "eos.svg").exists()


def test_a_disk_fluid_starts_at_its_temperature_with_no_momentum():
    r = poolsim.run("disks", balls=500, area_fraction=0.5, temperature=2.0, mixture=(0.5, 1.4),
                    lattice="square", until=0.0)
    s = r.samples[0] if r.samples else r.final
    assert np.allclose(np.sum(s.velocity, axis=0), 0.0, atol=1e-9)
    assert np.isclose(0.5 * np.sum(s.mass * np.sum(s.velocity**2, axis=1)) / 500, 2.0)
    assert sorted(set(s.radius)) == [1.0, 1.4]
    assert np.count_nonzero(s.radius == 1.4) == 250
    cli = cli_json("run", "disks", "--balls", "500", "--area-fraction", "0.5", "--temperature",
                   "2", "--mixture", "0.5:1.4", "--lattice", "square", "--until", "0")
    assert r.digest == cli["final_state_digest"]
    with pytest.raises(ValueError, match="lattice: triangular, square or random"):
        poolsim.run("disks", lattice="hexagonal")
    with pytest.raises(ValueError, match="too dense"):
        poolsim.run("disks", area_fraction=0.95)


def test_pair_correlation_is_flat_for_random_points_and_zero_inside_a_disk():
    from poolsim.analysis import pair_correlation

    rng = np.random.default_rng(1)
    n, side = 4000, 100.0
    table = poolsim.Table(np.zeros((0, 2, 2)), np.zeros((0, 2, 2)), (0.0, 0.0), (side, side))
    points = poolsim.State(0.0, rng.uniform(0, side, (n, 2)), np.zeros((n, 2)), np.ones(n),
                           np.ones(n), -np.ones(n, dtype=np.int32))
    r, g = pair_correlation(points, table, r_max=10.0, bins=10)
    assert np.allclose(g, 1.0, atol=0.1), g
    # a melted fluid at 0.5: no two centres closer than a diameter, a contact peak above 1
    fluid = poolsim.run("disks", balls=900, area_fraction=0.5, until=20, events=False)
    r, g = pair_correlation(fluid.final, fluid.table, r_max=6.0, bins=60)
    assert np.all(g[r < 1.95] == 0.0)
    assert g[(r > 2.0) & (r < 2.2)].max() > 2.0
    assert abs(g[r > 5.0].mean() - 1.0) < 0.2
    with pytest.raises(ValueError, match="r_max"):
        pair_correlation(fluid.final, fluid.table, r_max=1e6)


def test_the_mean_squared_displacement_grows_from_zero_then_levels_off():
    from poolsim.analysis import mean_squared_displacement

    r = poolsim.run("disks", balls=100, area_fraction=0.3, until=400, sample_every=10.0,
                    events=False)
    t, msd = mean_squared_displacement(r.samples)
    assert t[0] == 0.0 and msd[0] == 0.0
    assert msd[1] > 0 and msd[3] > msd[1]
    (x0, _), (x1, _) = r.table.lo, r.table.hi
    # bounded by the box: two uniform points in a square of side L are L^2 / 3 apart on average
    assert msd[-10:].mean() < 0.5 * (x1 - x0) ** 2


def test_in_a_periodic_box_displacements_grow_without_bound_and_samples_keep_images(tmp_path):
    from poolsim.analysis import mean_squared_displacement, pair_correlation

    r = poolsim.run("disks", balls=100, area_fraction=0.3, until=400, sample_every=10.0,
                    events=False, boundary="periodic")
    assert r.table.periodic and len(r.table.cushions) == 0
    (x0, y0), (x1, y1) = r.table.lo, r.table.hi
    for s in r.samples:
        assert np.all((s.position >= (x0, y0)) & (s.position < (x1, y1)))
    t, msd = mean_squared_displacement(r.samples, r.table)
    # diffusive, past the box's size: no wall stops it
    assert msd[-1] > 1.2 * (x1 - x0) ** 2
    assert msd[-1] > 5.0 * msd[len(msd) // 5]
    with pytest.raises(ValueError, match="images"):
        mean_squared_displacement([r.final], r.table)
    # the samples' images survive extended XYZ, and g(r) counts pairs across the sides
    path = tmp_path / "periodic.xyz"
    poolsim.write_xyz(path, r.samples, r.table)
    back = poolsim.read_xyz(path)
    assert back[-1].periodic and np.array_equal(back[-1].image, r.samples[-1].image)
    rg, g = pair_correlation(r.samples[-1], r.table, r_max=(x1 - x0) / 2, bins=40)
    assert np.all(g[rg < 1.5] == 0.0) and abs(g[rg > 6.0].mean() - 1.0) < 0.25
    with pytest.raises(ValueError, match="half"):
        pair_correlation(r.samples[-1], r.table, r_max=x1 - x0)
    boxed = poolsim.Scenario.box(10.0, 10.0, [[5.0, 1.0], [12.0, 1.0]], [[1.0, 0.0], [0.0, 0.0]],
                                 periodic=True, until=20.0)
    # Ball-2 is taken in to x = 2; Ball-1 leaves through the right side and meets it from its
    # left when it reaches x = 10, the box's x = 0
    ev = poolsim.run(boxed).events
    assert len(ev) >= 1 and abs(ev["t"][0] - 5.0) < 1e-12


def test_hexatic_order_tells_a_lattice_from_a_fluid_and_velocities_decorrelate():
    from poolsim.analysis import hexatic_order, velocity_autocorrelation

    lattice = poolsim.run("disks", balls=900, area_fraction=0.6, until=0.0, events=False,
                          boundary="periodic")
    psi, order = hexatic_order(lattice.final, lattice.table)
    assert psi.shape == (900,) and order > 0.9, order
    fluid = poolsim.run("disks", balls=900, area_fraction=0.4, until=40, events=False,
                        boundary="periodic", sample_every=0.25)
    _, melted = hexatic_order(fluid.final, fluid.table)
    assert melted < 0.2, melted
    t, c = velocity_autocorrelation(fluid.samples[40:])
    assert t[0] == 0.0 and abs(c[0] - 1.0) < 1e-12
    # a few mean free times on, the velocities have forgotten where they started
    assert c[1] < 0.9 and abs(c[-20:]).max() < 0.1, c[:5]


def test_a_compression_jams_a_mixture_and_its_packing_runs_on():
    p = poolsim.compress(balls=150, mixture=(0.5, 1.4), rate=0.1, check=True)
    assert p.ending == "jammed"
    assert 0.80 < p.area_fraction < 0.86
    assert p.z >= 1e12
    assert np.all(np.diff(p.cycles["area_fraction"]) > 0)
    assert np.isclose(np.mean(0.5 * p.final.mass * np.sum(p.final.velocity ** 2, axis=1)), 1.0)
    q = poolsim.compress(balls=150, mixture=(0.5, 1.4), rate=0.1, target=0.7)
    assert q.ending == "target" and abs(q.area_fraction - 0.7) < 1e-9
    r = poolsim.run(q.scenario(until=2.0), check=True)
    assert r["events"]["ball-ball"] > 100
    with pytest.raises(ValueError, match="periodic box"):
        poolsim.compress(boundary="walled")
    with pytest.raises(ValueError, match="--target"):
        poolsim.compress(target=0.1)


def test_a_thermostat_brings_a_hot_gas_to_its_temperature():
    r = poolsim.run("disks", balls=400, area_fraction=0.3, boundary="periodic", temperature=20.0,
                    until=60.0, thermostat=1.0, thermostat_rate=0.5, observe_every=5.0,
                    observe_from=20.0, check=True)
    kt = r["observables"]["kt"]
    assert abs(kt["mean"] - 1.0) < 3 * kt["error"] + 0.02
    same = poolsim.run("disks", balls=400, area_fraction=0.3, boundary="periodic",
                       temperature=20.0, until=60.0, thermostat=1.0, thermostat_rate=0.5)
    assert same.digest == r.digest
    with pytest.raises(ValueError, match="thermostat: the temperature"):
        poolsim.run("disks", thermostat=-1.0)
    with pytest.raises(ValueError, match="event-list engine only"):
        poolsim.run("gas", thermostat=1.0, engine="objects")
