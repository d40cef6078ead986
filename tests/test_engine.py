"""The compiled kernel against the NumPy reference path, and the array program under it.

The reference (``engine="numpy"``) computes the plane-of-array irradiance, every connection's
power and the metrics of :mod:`foldopt.engine.metrics` on whole arrays; the kernel fuses them in one
pass. Stated agreement (issue 11): t_solar and its longest run within 1 s a day, energy and peak
within 1e-9 relative, on random sites, days, loads, fold angles and models.
"""

import contextlib
import datetime as dt
import os
from unittest import mock
from pathlib import Path

import numpy as np
import pvlib
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from foldopt.engine import evaluation as engine
from foldopt.inputs.sections import Site
from foldopt.inputs.study import make_study
from foldopt.engine.metrics import t_solar, t_solar_contiguous
from foldopt.engine.sky import build_sky
from foldopt.studies.engine_options import engine_options

SECOND = 1 / 3600  # [h]
TMY3 = Path(pvlib.__file__).parent / "data" / "723170TYA.CSV"


@st.composite
def cases(draw):
    """A study (model, sky, geometry...), 1-2 blocks (sites and dates), fold angles and loads."""
    mode = draw(st.sampled_from(["paper", "exact"]))
    sky = draw(st.sampled_from(["meinel", "hottel"] + (["ineichen", "simplified-solis"] if mode == "exact" else [])))
    diffuse = sky in ("ineichen", "simplified-solis") or (mode == "exact" and draw(st.booleans()))
    # The connection's own options only with it (a setting nothing uses is an error); the engine
    # evaluates every connection whatever the study's.
    connection = draw(st.sampled_from(["switching", "series", "independent"]))
    switch_series = connection == "switching" and draw(st.booleans())
    series_used = connection == "series" or switch_series
    study = make_study({
        "name": "kernel", "mode": mode, "sky": sky,
        "geometry": draw(st.sampled_from(["azimuth-split", "hinge"])),
        "transposition": draw(st.sampled_from(["isotropic", "haydavies", "perez"])) if diffuse else "none",
        "albedo": draw(st.floats(0, 0.5)) if diffuse else 0.2,
        "iam": draw(st.sampled_from(["none", "ashrae", "physical"])),
        "pv_model": draw(st.sampled_from(["ideal", "single-diode", "b-model", "pvwatts"])),
        "connection": connection, "switch_series": switch_series,
        "bypass_diodes": draw(st.booleans()) if series_used else True,
        "converter_efficiency": draw(st.floats(0.8, 1.0)) if connection == "independent" else 1.0,
        "site": {"latitude": 0.0, "longitude": 0.0},
        "date": "2025-01-01",
        "panel": {"area": draw(st.sampled_from([0.108, 0.2])), "efficiency": 0.19,
                  "tilt": draw(st.one_of(st.none(), st.floats(0, 90))),
                  "azimuth": draw(st.one_of(st.none(), st.floats(0, 359.9)))},
        "p_load": 1.0,
        "step_min": draw(st.sampled_from([5, 10, 15])),
    })
    n_blocks = draw(st.integers(1, 2))
    # Each site as a study decides it (its time zone the longitude's standard offset).
    sites = [study.variant(site={"latitude": draw(st.floats(-89, 89)), "longitude": draw(st.floats(-180, 180)),
                                 "altitude": draw(st.floats(0, 2000))}).site for _ in range(n_blocks)]
    dates = [dt.date(2025, 1, 1) + dt.timedelta(days=draw(st.integers(0, 364))) for _ in range(n_blocks)]
    angles = np.array(draw(st.lists(st.floats(1, 180), min_size=1, max_size=4)) + [180.0])
    loads = np.array(draw(st.lists(st.floats(0.01, 60), min_size=1, max_size=6)))
    return study, sites, dates, angles, loads


def _rows(study, sites, angles):
    resolved = [study.variant(site=site.model_dump()).panel for site in sites]
    orientation = engine.fold_orientations(study.geometry, [p.tilt for p in resolved], [p.azimuth for p in resolved],
                                           angles)
    return engine.PanelRows(np.repeat(np.arange(len(sites)), angles.size), orientation.reshape(-1, 4))


def _sky(study, sites, dates):
    return build_sky(engine_options(study).sky, sites, dates)


def assert_engines_agree(compiled, reference):
    np.testing.assert_allclose(compiled.t_solar, reference.t_solar, rtol=0, atol=SECOND)
    np.testing.assert_allclose(compiled.t_solar_contiguous, reference.t_solar_contiguous, rtol=0, atol=SECOND)
    np.testing.assert_allclose(compiled.energy, reference.energy, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(compiled.peak, reference.peak, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(compiled.irradiation, reference.irradiation, rtol=1e-9, atol=1e-9)


#: The thread counts the kernel is compared on: one, as a pytest-xdist worker runs it
#: (tests/conftest.py), and two, where its rows go to threads in chunks.
THREADS = (1, 2)


@contextlib.contextmanager
def _engine_threads(threads):
    """The engine on ``threads`` threads. Its passes take as many of the process's Python threads
    (:func:`foldopt.engine.records.in_chunks`, :mod:`foldopt.threads`) as ``numba.get_num_threads()``
    says, which they read at each call; none runs on numba's own threads (no ``prange``). numba
    launches those once, as it is imported, and ``numba.set_num_threads`` can then ask fewer but
    never more: where it launched fewer (a pytest-xdist worker launched one, tests/conftest.py),
    the count is given to the engine here instead."""
    import numba

    if threads <= numba.config.NUMBA_NUM_THREADS:
        before = numba.get_num_threads()
        numba.set_num_threads(threads)
        try:
            yield
        finally:
            numba.set_num_threads(before)
        return
    with mock.patch.object(numba, "get_num_threads", lambda: threads):
        yield


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(case=cases())
def kernel_equals_the_reference_path(case):
    """The kernel on each of :data:`THREADS` against one reference path's run of the case."""
    import numba

    study, sites, dates, angles, loads = case
    sky, rows, electrical = _sky(study, sites, dates), _rows(study, sites, angles), engine_options(study).electrical
    peak = engine.row_metrics(sky, rows=rows, loads=[1.0], electrical=electrical, outputs=("independent",),
                              engine="numpy").peak
    loads = loads / 60 * max(peak.max(), 1e-3)  # from a sliver of the peak to above it

    def metrics(name):
        return engine.row_metrics(sky, rows=rows, loads=loads, electrical=electrical, outputs=engine.OUTPUTS,
                                  contiguous=True, engine=name)

    reference = metrics("numpy")
    for threads in THREADS:
        with _engine_threads(threads):
            assert numba.get_num_threads() == threads
            assert_engines_agree(metrics("numba"), reference)


def test_the_kernel_on_two_threads():
    """The kernel equals the reference path on one thread and on two (the comparison's examples
    run the reference once and the kernel on each): its rows go to threads in chunks, each with
    its own scratch (arrays zero-filled inside a prange body have given wrong sums)."""
    kernel_equals_the_reference_path()


def test_the_chunks_of_two_threads_run_on_two_threads():
    """Where the engine is given two threads (:func:`_engine_threads`), a pass's chunks run on two
    threads at once: the calling thread and one of the process's pool."""
    import threading

    from foldopt.engine import records

    seen, both = set(), threading.Barrier(2, timeout=60)

    def body(start, stop):
        seen.add(threading.get_ident())
        both.wait()  # each of two chunks waits for the other: they run at once, or time out

    with _engine_threads(2):
        records.in_chunks(body, 2, None, n_chunks=2)
    assert len(seen) == 2 and threading.get_ident() in seen


def test_kernel_threads():
    """How many threads numba launched: those the environment asks (one in a pytest-xdist
    worker, tests/conftest.py), or numba's default."""
    import numba

    assert numba.get_num_threads() == int(os.environ.get("NUMBA_NUM_THREADS", numba.config.NUMBA_DEFAULT_NUM_THREADS))


@pytest.mark.parametrize("pv_model,outputs", [("single-diode", engine.OUTPUTS), ("ideal", engine.OUTPUTS),
                                              ("b-model", ("switching", "panel")), ("pvwatts", engine.OUTPUTS)])
def test_kernel_equals_the_reference_on_a_weather_year_slice(pv_model, outputs):
    # Real weather: Perez diffuse light, cells at each day's air temperature (several tables).
    study = make_study({"name": "w", "mode": "exact", "site": {"latitude": 36.1, "longitude": -79.95,
                        "altitude": 273, "timezone": "UTC-05:00"}, "weather": str(TMY3), "date": "2025-01-01",
                        "panel": {"area": 0.108}, "p_load": 2.0, "pv_model": pv_model, "iam": "physical"})
    dates = [dt.date(2025, 1, 1) + dt.timedelta(days=d) for d in range(0, 365, 45)]
    sky = _sky(study, [study.site] * len(dates), dates)
    assert np.unique(sky.temp_air).size > 2
    rows = _rows(study, [study.site] * len(dates), np.array([30.0, 90.0, 150.0]))
    electrical = engine_options(study).electrical
    results = {name: engine.row_metrics(sky, rows=rows, loads=[0.5, 2.0, 4.4], electrical=electrical, outputs=outputs,
                                        contiguous=True, engine=name) for name in ("numba", "numpy")}
    assert_engines_agree(results["numba"], results["numpy"])


@settings(max_examples=150, deadline=None)
# A curve a hair below the load, plateaus on a load, and a near-flat segment around a load.
@example(curves=np.r_[np.full((2, 40), 4.0), np.full((1, 40), np.nextafter(4.0, 0))], loads=np.ones(7))
@example(curves=np.r_[np.full((1, 40), 0.01), np.full((2, 40), 0.01) + np.r_[0.0, 1e-9, np.zeros(38)]],
         loads=np.full(7, 0.01))
@given(curves=arrays(np.float64, (3, 40), elements=st.floats(0, 20)),
       loads=arrays(np.float64, 7, elements=st.floats(0.01, 25)))
def test_many_loads_in_one_pass_equal_one_pass_per_load(curves, loads):
    curves[1] = np.round(curves[1])  # plateaus and exact ties with the loads
    loads[0] = curves[1, 5]
    loads[3] = loads[2]  # a repeated load; the loads are not sorted either
    direct = t_solar(curves[:, None, :], loads[None, :], 0.5)
    runs = t_solar_contiguous(curves[:, None, :], loads[None, :], 0.5)
    for name in ("numba", "numpy"):
        result = engine.curve_metrics(curves, loads, 0.5, contiguous=True, engine=name)
        np.testing.assert_allclose(result.t_solar[:, 0], direct, atol=1e-12)
        np.testing.assert_allclose(result.t_solar_contiguous[:, 0], runs, atol=1e-12)
        np.testing.assert_allclose(result.energy[:, 0], curves.sum(axis=1) * 0.5, rtol=1e-12)


def test_curves_sharing_a_chunk_each_get_their_own_metrics():
    """More curves than the parallel loop has chunks, so that a chunk's scratch serves many rows
    and must be cleared for each (the compiled engine's records once lost what the loop's body
    wrote through them: every row's hours added to the last's)."""
    rng = np.random.default_rng(7)
    curves = rng.uniform(0, 20, (300, 48)) * np.sin(np.linspace(0, np.pi, 48))
    loads = np.linspace(0.5, 15, 9)
    for contiguous in (False, True):
        kernel, reference = (engine.curve_metrics(curves, loads, 0.5, contiguous=contiguous, engine=name)
                             for name in ("numba", "numpy"))
        np.testing.assert_allclose(kernel.t_solar, reference.t_solar, rtol=0, atol=SECOND)
        np.testing.assert_allclose(kernel.energy, reference.energy, rtol=1e-12)
        np.testing.assert_allclose(kernel.peak, reference.peak, rtol=1e-12)
        if contiguous:
            np.testing.assert_allclose(kernel.t_solar_contiguous, reference.t_solar_contiguous, rtol=0, atol=SECOND)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(case=cases())
def test_t_solar_never_rises_when_the_load_rises(case):
    study, sites, dates, angles, _ = case
    hours = engine.row_metrics(_sky(study, sites, dates), rows=_rows(study, sites, angles),
                               loads=np.linspace(0.01, 30, 50), electrical=engine_options(study).electrical,
                               outputs=engine.OUTPUTS).t_solar
    assert np.all(np.diff(hours, axis=-1) <= 1e-12)
    assert np.all((hours >= 0) & (hours <= 24 + 1e-9))


def test_loads_of_each_row_and_unknown_names():
    study = make_study({"name": "k", "site": {"latitude": 34.05, "longitude": -118.25}, "date": "2025-06-21",
                        "panel": {"area": 0.108}, "p_load": 4.0, "pv_model": "single-diode"})
    sky, electrical = _sky(study, [study.site], [study.date]), engine_options(study).electrical
    rows = _rows(study, [study.site], np.array([40.0, 120.0]))
    sets = np.array([[9.0, 2.0], [2.0, 9.0]])
    one = engine.row_metrics(sky, rows=rows._replace(loadset=[0, 1]), loads=sets, electrical=electrical).t_solar[:, 0]
    both = engine.row_metrics(sky, rows=rows, loads=[2.0, 9.0], electrical=electrical).t_solar[:, 0]
    np.testing.assert_array_equal(one[0], both[0, ::-1])
    np.testing.assert_array_equal(one[1], both[1])
    with pytest.raises(ValueError, match="numba, numpy"):
        engine.row_metrics(sky, rows=rows, loads=[2.0], electrical=electrical, engine="fortran")
    with pytest.raises(ValueError, match="outputs must be among"):
        engine.row_metrics(sky, rows=rows, loads=[2.0], electrical=electrical, outputs=("diagonal",))
    with pytest.raises(ValueError, match="1 orientations for 2 rows"):
        engine.row_metrics(sky, rows=rows._replace(orientation_of=[0]), loads=[2.0], electrical=electrical)


@pytest.mark.parametrize("model", ["ashrae", "physical"])
def test_kernel_incidence_angle_modifier_is_pvlibs(model):
    from foldopt.engine.incidence import iam_factor

    aoi = np.linspace(0.0, 100.0, 1001)
    code, params = engine._iam_code(model)
    compiled = np.array([iam_factor(np.cos(np.radians(a)), code, params) for a in aoi])
    expected = pvlib.iam.ashrae(aoi) if model == "ashrae" else pvlib.iam.physical(aoi)
    np.testing.assert_allclose(compiled, np.nan_to_num(expected), rtol=1e-12, atol=1e-12)


def test_blocks_of_many_sites_and_time_zones_equal_their_own_skies():
    study = make_study({"name": "s", "mode": "exact", "sky": "ineichen", "site": {"latitude": 0, "longitude": 0},
                        "date": "2025-01-01", "panel": {"area": 0.1}, "p_load": 1.0, "step_min": 10})
    sites = [Site(latitude=-33.9, longitude=151.2, timezone="Australia/Sydney"),
             Site(latitude=52.5, longitude=13.4, timezone="UTC+01:00"),
             Site(latitude=34.05, longitude=-118.25, timezone="America/Los_Angeles"),
             Site(latitude=-33.9, longitude=151.2, timezone="Australia/Sydney")]
    dates = [dt.date(2025, 3, 9), dt.date(2025, 6, 21), dt.date(2025, 11, 2), dt.date(2025, 12, 21)]
    together = _sky(study, sites, dates)
    for index, (site, date) in enumerate(zip(sites, dates, strict=True)):
        alone = _sky(study, [site], [date])
        for name in ("solar_zenith", "solar_azimuth", "hour_angle", "dni", "terms"):
            np.testing.assert_allclose(getattr(together, name)[index], getattr(alone, name)[0], rtol=1e-12, atol=1e-9)
        assert together.grid.times(index).equals(alone.grid.times(0))


def test_run_plan_is_the_same_on_both_engines():
    from foldopt.inputs.plan import make_plan
    from foldopt.studies.sweeps import run_plan

    plan = make_plan({"name": "t", "mode": "exact", "site": {"latitude": [-20.0, 45.0], "longitude": 10.0},
                      "date": ["2025-03-20", "2025-12-21"], "panel": {"area": 0.108}, "p_load": [1.0, 4.4, 40.0],
                      "pv_model": "single-diode", "fold_angles": {"start": 5, "stop": 180, "step": 5},
                      "step_min": 10})
    tables = {name: run_plan(plan, engine=name).table for name in ("numba", "numpy")}
    numbers = tables["numba"].select_dtypes("number").columns
    np.testing.assert_allclose(tables["numba"][numbers], tables["numpy"][numbers], rtol=1e-9, atol=SECOND)
    assert tables["numba"]["note"].equals(tables["numpy"]["note"])
    # No design carries 40 W: every angle ties at zero and the flat panel is reported.
    high = tables["numba"][(tables["numba"].p_load_w == 40.0) & (tables["numba"].design == "twofold")]
    assert (high["fold_angle_deg"] == 180.0).all() and (high["t_solar_h"] == 0).all()


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(case=cases(), tie=st.integers(0, 10**6))
def test_each_output_alone_has_its_bits_among_all(case, tie):
    """The kernel's loops for one output (switching from one table set a block; its walk over
    the loads by blocks of steps, without the longest runs; the common case's chunk loop,
    ``_chunk_switching``) do the general loops' operations in their order: an output asked
    alone, with or without its longest runs, has the bits it has among every output. Some loads
    are the curve's own samples, so that the power ties a load."""
    study, sites, dates, angles, loads = case
    sky, rows, electrical = _sky(study, sites, dates), _rows(study, sites, angles), engine_options(study).electrical
    every = engine.row_metrics(sky, rows=rows, loads=[1.0], electrical=electrical, outputs=engine.OUTPUTS,
                               contiguous=True, engine="numba", curves=[0])
    curve = every.power[0].ravel()
    loads = np.r_[loads / 60 * max(every.peak.max(), 1e-3), curve[tie % curve.size], every.peak[0, -2]]
    every = engine.row_metrics(sky, rows=rows, loads=loads, electrical=electrical, outputs=engine.OUTPUTS,
                               contiguous=True, engine="numba")
    for index, name in enumerate(engine.OUTPUTS):
        for contiguous in (False, True):
            alone = engine.row_metrics(sky, rows=rows, loads=loads, electrical=electrical, outputs=(name,),
                                       contiguous=contiguous, engine="numba")
            for field in ("t_solar", "energy", "peak"):
                np.testing.assert_array_equal(getattr(alone, field)[:, 0], getattr(every, field)[:, index])
            np.testing.assert_array_equal(alone.irradiation, every.irradiation)


@pytest.mark.parametrize("sky", ["meinel", "ineichen"])
def test_the_common_cases_loop_has_the_general_loops_bits(sky):
    """Switching alone from one table set a block, the exact incidence without the modifier and
    constant loads (W1-W3's case) run in a chunk loop of their own (``_chunk_switching``, its
    square roots in the incidence's loop): every metric and every kept curve has the bits of the
    general loop, which takes switching beside another output. Loads include a curve's own
    sample and its peak, so that the power ties them."""
    from foldopt.engine import kernel

    study = make_study({"name": "common", "mode": "exact", "sky": sky, "pv_model": "single-diode",
                        "connection": "switching", "site": {"latitude": 34.05, "longitude": -118.25},
                        "date": "2025-01-01", "panel": {"area": 0.108, "efficiency": 0.19}, "p_load": 1.0,
                        "step_min": 5})
    dates = [dt.date(2025, 1, 1) + dt.timedelta(days=d) for d in (0, 95, 172, 300)]
    sites = [study.site] * len(dates)
    sky_, rows = _sky(study, sites, dates), _rows(study, sites, np.array([1.0, 37.0, 90.0, 145.0, 180.0]))
    electrical = engine_options(study).electrical
    general = engine.row_metrics(sky_, rows=rows, loads=[1.0], electrical=electrical, outputs=("switching", "east"),
                                 engine="numba", curves=np.arange(rows.block.size))
    loads = np.r_[0.05, general.power[3, 0, 150], general.peak[7, 0], 3.0]
    general = engine.row_metrics(sky_, rows=rows, loads=loads, electrical=electrical, outputs=("switching", "east"),
                                 engine="numba", curves=np.arange(rows.block.size))
    common = engine.row_metrics(sky_, rows=rows, loads=loads, electrical=electrical, outputs=("switching",),
                                engine="numba", curves=np.arange(rows.block.size))
    assert kernel._chunk_switching.signatures  # the common case's loop ran
    for field in ("t_solar", "energy", "peak", "power"):
        np.testing.assert_array_equal(getattr(common, field)[:, 0], getattr(general, field)[:, 0])
    np.testing.assert_array_equal(common.irradiation, general.irradiation)


def test_the_kernels_loops_count_no_references():
    """The chunk loops and the functions they call rather than inline are compiled without numba's
    reference counting: a count of each array they hand on is an atomic operation at every row
    or step (``foldopt.engine.kernel``). The machine code of one of them that numba keeps in its
    cache (which this process runs, loaded or compiled here) calls neither NRT_incref nor
    NRT_decref; compiled with the counts, it calls both. Read from the cache rather than compiled
    afresh for its IR (numba's cache keeps none), which cost a worker the function's compile."""
    from foldopt.engine import curve_reduction, kernel

    called = (
        kernel._chunk_switching,
        kernel._chunk_rows,
        kernel._built_row,
        kernel._keep_curves,
        kernel._table_row,
        kernel._switching_call,
        kernel._linear,
        kernel._bilinear,
        kernel._between,
        kernel._delivered,
        kernel._connection_power,
        kernel._built_power,
        curve_reduction.blocked_day,
        curve_reduction._runs,
        curve_reduction._gather,
        curve_reduction._per_load,
        curve_reduction._chunk_curves,
    )
    assert [f.py_func.__name__ for f in called if f.targetoptions.get("_nrt") is not False] == []
    power, loads, held = np.linspace(0.0, 5.0, 48), np.array([1.0, 2.0]), np.arange(49) * 0.5
    t_out = np.zeros(2)
    extremes, scratch = (np.zeros(2), np.full(2, 5.0)), (np.zeros(2), np.zeros(3))
    curve_reduction.blocked_day(power, (1, 40), loads, 0.5, held, extremes, scratch, t_out)
    # numba's cache file of each compile: its library first, kept as machine code and bitcode.
    cache = curve_reduction.blocked_day._cache._cache_file
    libraries = [cache._load_data(name)[0] for name in cache._load_index().values()]
    assert libraries and {kind for _, kind, _ in libraries} == {"object"}
    for _, _, (machine_code, _) in libraries:
        assert b"NRT_incref" not in machine_code and b"NRT_decref" not in machine_code


@pytest.mark.parametrize("name", ["numba", "numpy"])
def test_a_dark_sub_panel_adds_nothing_to_switching(name):
    """Where one sub-panel gets no light (the sun behind it, a beam-only sky), switching's power
    is the other's alone, to the bit: a parallel pair with a dark member gives at most the lit
    one's power. The kernel's common loop skips the pair table there (``_switching_power``); the
    reference path looks it up. The curves of switching alone and of each sub-panel, kept."""
    study = make_study({"name": "dark", "mode": "exact", "sky": "meinel", "pv_model": "single-diode",
                        "connection": "switching", "site": {"latitude": 34.05, "longitude": -118.25},
                        "date": "2025-01-01", "panel": {"area": 0.108, "efficiency": 0.19}, "p_load": 1.0,
                        "step_min": 5})
    dates = [dt.date(2025, 1, 1) + dt.timedelta(days=d) for d in (0, 172)]
    sky, rows = _sky(study, [study.site] * 2, dates), _rows(study, [study.site] * 2, np.array([20.0, 90.0, 160.0]))
    every = np.arange(rows.block.size)
    electrical = engine_options(study).electrical
    switching = engine.row_metrics(sky, rows=rows, loads=[1.0], electrical=electrical, outputs=("switching",),
                                   engine=name, curves=every).power[:, 0]
    east, west = engine.row_metrics(sky, rows=rows, loads=[1.0], electrical=electrical, outputs=("east", "west"),
                                    engine=name, curves=every).power.transpose(1, 0, 2)
    dark_west, dark_east = (west == 0) & (east > 0), (east == 0) & (west > 0)
    assert dark_west.sum() > 100 and dark_east.sum() > 100  # the sun behind each side for hours
    np.testing.assert_array_equal(switching[dark_west], east[dark_west])
    np.testing.assert_array_equal(switching[dark_east], west[dark_east])
    both = (east > 0) & (west > 0)
    assert (switching[both] >= np.maximum(east, west)[both]).all()


def test_chunks_are_each_taken_once_and_their_errors_raised():
    """:func:`foldopt.engine.records.in_chunks` hands every row to one chunk call on numba's
    threads, each chunk with its own scratch, and raises a chunk's error."""
    import threading

    import numba

    from foldopt.engine.records import allocate, in_chunks

    before = numba.get_num_threads()
    numba.set_num_threads(min(2, numba.config.NUMBA_NUM_THREADS))
    try:
        _, scratch = allocate(1000, 1, 1, 10, False)
        seen, lock = np.zeros(1000, dtype=int), threading.Lock()

        def body(start, stop, work):
            with lock:
                seen[start:stop] += 1
            work.east[:] = start  # each chunk its own scratch

        in_chunks(body, 1000, scratch)
        np.testing.assert_array_equal(seen, 1)
        assert len(set(scratch.east[:, 0])) == scratch.east.shape[0]

        def failing(start, stop, work):
            if start > 0:
                raise ValueError(f"chunk at {start}")

        with pytest.raises(ValueError, match="chunk at"):
            in_chunks(failing, 1000, scratch)
    finally:
        numba.set_num_threads(before)


def test_a_chunk_error_is_raised_after_every_chunk_ended(monkeypatch):
    """A chunk's scratch is the calling thread's workspace, which its next call takes again: the
    error of one chunk reaches the caller only once the others have ended. The chunks run on
    foldopt's pool of two Python threads whatever numba's thread count (one in a suite's worker),
    which ``in_chunks`` reads from numba."""
    import threading
    import time

    import numba

    from foldopt.engine.records import allocate, in_chunks

    monkeypatch.setattr(numba, "get_num_threads", lambda: 2)
    _, scratch = allocate(1000, 1, 1, 10, False)
    ended, lock = [], threading.Lock()

    def body(start, stop, work):
        if start == 0:
            raise ValueError("the first chunk")
        time.sleep(0.02)
        with lock:
            ended.append(start)

    assert scratch.east.shape[0] > 2  # chunks left waiting when the first one fails
    with pytest.raises(ValueError, match="the first chunk"):
        in_chunks(body, 1000, scratch)
    assert len(ended) == scratch.east.shape[0] - 1


def test_an_interrupt_in_a_chunk_stops_the_pass_once_the_running_chunks_ended(monkeypatch):
    """An interrupt (``KeyboardInterrupt``) in one chunk: no chunk is taken after it, the chunks
    running on other threads end, and the interrupt reaches the caller, not a pass to its end."""
    import threading
    import time

    import numba

    from foldopt.engine.records import allocate, in_chunks

    monkeypatch.setattr(numba, "get_num_threads", lambda: 2)
    _, scratch = allocate(1000, 1, 1, 10, False)
    started, ended, lock = [], [], threading.Lock()

    def body(start, stop, work):
        with lock:
            started.append(start)
        if start == 0:
            raise KeyboardInterrupt
        time.sleep(0.02)
        with lock:
            ended.append(start)

    with pytest.raises(KeyboardInterrupt):
        in_chunks(body, 1000, scratch)
    assert sorted(ended) == sorted(set(started) - {0})  # every chunk taken ended
    assert len(started) <= 3  # the interrupted chunk and those running beside it, no more


def _poison_workspaces():
    """Every byte of this thread's workspace set to 0xff (a NaN in each float, the largest
    integer): what a call left there must not reach the next call's answer."""
    from foldopt import threads

    buffer = getattr(threads._local, "buffer", None)
    if buffer is not None:
        buffer[:] = 0xFF


@pytest.mark.parametrize("common", [True, False])
def test_a_reused_scratch_changes_no_answer_and_no_earlier_result(common):
    """The kernel's scratch lives in the calling thread's workspace, reused by its next call: the
    same rows give the same bits whatever the workspace held (each call after it was filled
    with NaNs), a result stays as it was after later calls over other rows, and curves given to
    :func:`curve_metrics` (the same scratch's other layout) too. Both the common case's loop and
    the general one (all outputs, the longest runs, kept curves)."""
    study = make_study({"name": "reuse", "mode": "exact", "sky": "meinel", "pv_model": "single-diode",
                        "site": {"latitude": 40.0, "longitude": 10.0}, "date": "2025-06-01",
                        "panel": {"area": 0.108, "efficiency": 0.19}, "p_load": 1.0, "step_min": 5})
    dates = [dt.date(2025, 1, 1) + dt.timedelta(days=d) for d in (0, 90, 180, 270)]
    sky = _sky(study, [study.site] * 4, dates)
    rows = _rows(study, [study.site] * 4, np.arange(10.0, 181.0, 10.0))
    electrical = engine_options(study).electrical
    ask = dict(outputs=("switching",)) if common else dict(outputs=engine.OUTPUTS, contiguous=True, curves=[0, 5])
    loads = np.array([0.5, 2.0, 8.0])

    def run(which):
        picked = engine.PanelRows(rows.block[which], rows.orientation[which])
        return engine.row_metrics(sky, rows=picked, loads=loads, electrical=electrical, engine="numba", **ask)

    fields = ("t_solar", "t_solar_contiguous", "energy", "peak", "irradiation", "power")

    def arrays(result):
        return [getattr(result, name) for name in fields]

    everything = np.arange(rows.block.size)
    first = arrays(run(everything))
    kept = [None if a is None else a.copy() for a in first]
    _poison_workspaces()
    again = arrays(run(everything))
    run(everything[::-1])  # other rows, the same shapes
    run(everything[:7])  # fewer rows
    for value, copy, repeated in zip(first, kept, again, strict=True):
        if value is not None:
            np.testing.assert_array_equal(value, copy)  # untouched by the later calls
            np.testing.assert_array_equal(repeated, copy)  # the same bits from a poisoned workspace
    power = np.abs(np.sin(np.linspace(0, 3 * np.pi, 4 * 288))).reshape(4, 288) * 5.0
    curves = arrays(engine.curve_metrics(power, loads, 1 / 12, contiguous=not common))
    curves_kept = [None if a is None else a.copy() for a in curves]
    _poison_workspaces()
    again = arrays(engine.curve_metrics(power, loads, 1 / 12, contiguous=not common))
    run(everything)
    for value, copy, repeated in zip(curves, curves_kept, again, strict=True):
        if value is not None:
            np.testing.assert_array_equal(value, copy)
            np.testing.assert_array_equal(repeated, copy)
