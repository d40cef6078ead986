"""Each compiled entry point is called with one type of each argument, whatever form the caller's
arrays take (a value shared by every series or one a series, a broadcast or a copy, constant loads
or a load profile): numba compiles a function again for every new combination of argument types
(a read-only array is another type than a writable one), and each compile of these costs seconds
(``docs/performance.rst``). The types are numba's own (:func:`numba.typeof`), recorded where the
engine calls the compiled function, which is not run."""

from __future__ import annotations

import numpy as np
import pytest

numba = pytest.importorskip("numba")


def _recorded(monkeypatch, module, name):
    """Replace the compiled ``module.name`` by a recorder of its argument types (a set)."""
    seen = set()
    monkeypatch.setattr(module, name, lambda *args: seen.add(tuple(numba.typeof(a) for a in args)))
    return seen


def test_given_curves_compile_once_for_constant_loads_and_profiles(monkeypatch):
    from foldopt.engine import curve_reduction
    from foldopt.engine import evaluation as engine

    seen = _recorded(monkeypatch, curve_reduction, "_chunk_curves")
    power = np.ones((3, 48))
    for shape in (None, np.ones(power.shape), np.ones(48), np.ones((1, 48)), np.ones(power.shape)[:, ::1]):
        for contiguous in (False, True):
            engine.curve_metrics(power, [0.5, 1.0], 0.5, contiguous=contiguous, engine="numba",
                                 load_shape=shape)
    assert len(seen) == 1, seen


def test_the_buffer_compiles_once_for_shared_and_per_series_parameters(monkeypatch):
    from foldopt.engine import storage_kernel
    from foldopt.engine.storage import Buffer, simulate

    seen = _recorded(monkeypatch, storage_kernel, "simulate_series")
    for series, buffer in ((1, Buffer(1.0)), (2, Buffer(1.0)), (1, Buffer(np.array([1.0, 2.0]))),
                           (2, Buffer(np.array([1.0, 2.0]), min_soc=np.array([0.1, 0.2]))),
                           (1, Buffer(2.0, initial_soc=0.5, max_charge_w=3.0))):
        simulate(np.ones((series, 24)), 0.5, buffer, 1.0, engine="numba")
    assert len(seen) == 1, seen


def test_the_clear_sky_compiles_once_whatever_its_inputs_broadcast(monkeypatch):
    from foldopt.physics import clearsky

    seen = _recorded(monkeypatch, clearsky, "_ineichen_terms")
    zenith = np.full((2, 5), 40.0)
    for dni_extra, turbidity, altitude in ((1360.0, 3.0, 0.0), (np.full((2, 5), 1360.0), np.full((2, 5), 3.0),
                                                                 np.zeros(2)),
                                           (np.full((1, 5), 1360.0), np.full((2, 1), 3.0), [0.0])):
        for given in (zenith, np.broadcast_to(zenith, zenith.shape)):
            clearsky.ineichen_terms(given, dni_extra, turbidity, altitude)
    assert len(seen) == 1, seen


def test_a_trackers_irradiance_compiles_once_for_one_block_or_several(monkeypatch):
    import datetime as dt

    from foldopt.api import load_study
    from foldopt.engine import incidence
    from foldopt.engine.sky import build_sky
    from foldopt.inputs.study_file import default_study_path
    from foldopt.studies.designs import sky_tracker_orientation, sky_tracker_poa
    from foldopt.studies.engine_options import engine_options

    seen = _recorded(monkeypatch, incidence, "turning_poa")
    for model in ("dual-axis", "single-axis"):  # the sun's vector as the normal, and another's
        study = load_study(default_study_path()).variant(mode="exact", step_min=60, tracker={"model": model})
        for blocks in (1, 3):
            dates = [dt.date(2025, 3, 1) + dt.timedelta(days=30 * k) for k in range(blocks)]
            sky = build_sky(engine_options(study).sky, [study.site] * blocks, dates)
            sky_tracker_poa(sky, sky_tracker_orientation(sky, study), "numba")
    assert len(seen) == 1, seen
