"""The public Python API: what `import foldopt` offers, that it is documented, and that it gives the
command line's numbers as pandas objects in pvlib's conventions. What it imports, in fresh
processes, is tests/test_imports.py's."""

from __future__ import annotations

import doctest
import inspect
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pandas as pd  # noqa: E402
import pytest  # noqa: E402

import foldopt  # noqa: E402
from foldopt.inputs.plan import make_plan  # noqa: E402
from foldopt.studies.sweeps import run_plan  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent


@pytest.mark.parametrize("name", [name for name in foldopt.__all__ if name != "__version__"])
def test_every_public_name_resolves_and_is_documented(name):
    value = getattr(foldopt, name)
    doc = inspect.getdoc(value) or ""
    assert len(doc) > 40, name
    if inspect.isfunction(value) and name.startswith(("run", "sweep", "load", "default", "write", "evaluate")):
        assert "Returns" in doc and ("Parameters" in doc or not inspect.signature(value).parameters), name


@pytest.fixture(scope="module")
def embedded():
    """``foldopt.run(foldopt.default_study())``, run once for the tests that read, draw or write it
    (none changes it)."""
    return foldopt.run(foldopt.default_study())


def test_docstring_examples_run():
    from foldopt import api

    failures, tried = doctest.testmod(api, optionflags=doctest.ELLIPSIS)
    assert tried >= 4 and failures == 0


def test_run_gives_a_tz_aware_time_series_and_the_papers_numbers(embedded):
    result = embedded
    index = result.timeseries.index
    assert isinstance(index, pd.DatetimeIndex) and str(index.tz) == "America/Los_Angeles"
    assert index[0] == pd.Timestamp("2014-09-23 00:00:30", tz="America/Los_Angeles")
    # The paper's 7.73 h; the study's load is the inferred 4.3979 W rounded to 4.398 W (0.2 s less).
    assert result.summary.set_index("design").loc["flat", "t_solar_h"] == pytest.approx(7.73, abs=1e-4)
    # A YAML path gives the same result.
    again = foldopt.run(ROOT / "configs" / "shin2015.yaml")
    pd.testing.assert_frame_equal(again.summary, result.summary)


def test_sweep_is_the_plan_the_yaml_would_make():
    study = foldopt.default_study().variant(mode="exact", geometry=None, step_min=30,
                                            fold_angles={"start": 30, "stop": 180, "step": 30})
    result = foldopt.sweep(study, latitude=[0, 30], p_load="2:4:2", axes={"tracker.standby_w": [0.0, 1.0]})
    data = study.model_dump(mode="json", exclude_none=True)
    data["site"]["latitude"], data["p_load"], data["tracker"]["standby_w"] = [0, 30], "2:4:2", [0.0, 1.0]
    # A new latitude tilts the panel at |latitude| toward the equator (foldopt.inputs.policy).
    del data["panel"]["tilt"], data["panel"]["azimuth"]
    data["year"] = 2014
    expected = run_plan(make_plan(data)).table
    pd.testing.assert_frame_equal(result.table, expected)
    assert len(result.table) == 2 * 2 * 2 * 4  # tidy: one row per case x design
    with pytest.raises(foldopt.ConfigError, match="name at least one field"):
        foldopt.sweep(study)


def test_plots_return_axes_and_draw_into_the_given_one(embedded):
    result = embedded
    fig, axes = plt.subplots(1, 2)
    assert foldopt.plot_power_curves(result, ax=axes[0]) is axes[0]
    assert foldopt.plot_comparison(result, ax=axes[1]) is axes[1]
    assert axes[0].lines and axes[1].patches
    own = foldopt.plot_standby(result)
    assert isinstance(own, matplotlib.axes.Axes) and own.figure is not fig
    plt.close("all")


def test_write_makes_the_command_lines_folder(tmp_path, embedded):
    result = embedded
    out = foldopt.write(result, tmp_path / "study")
    assert {"summary.csv", "sweep.csv", "timeseries.csv", "run.json", "report.html"} <= {p.name for p in out.iterdir()}


def test_a_tracker_option_its_model_does_not_read_is_refused():
    study = foldopt.default_study()  # a dual-axis tracker
    with pytest.raises(foldopt.ConfigError, match=r"tracker.gcr = 0.9: is only used by tracker.model single-axis"):
        study.variant(tracker={"gcr": 0.9})
    with pytest.raises(foldopt.ConfigError, match=r"tracker.backtrack = True: is only used by tracker.model"):
        foldopt.sweep(study, axes={"tracker.backtrack": [True, False]})
    single = study.variant(tracker={"model": "single-axis", "gcr": 0.9, "backtrack": True})
    assert (single.tracker.gcr, single.tracker.backtrack) == (0.9, True)
    with pytest.raises(foldopt.ConfigError, match=r"tracker.steps = 10: is only used by tracker.model dual-axis-steps"):
        single.variant(tracker={"steps": 10})


def test_a_study_built_in_python_has_its_files_read_by_the_api():
    """The models open no files: a weather file's site is read where the API runs the study."""
    weather = str(ROOT / "configs" / "weather" / "723170TYA.CSV")
    fields = {"name": "g", "weather": weather, "date": "2025-06-21", "p_load": 2.0, "panel": {"area": 0.108},
              "step_min": 60, "fold_angles": {"start": 30, "stop": 180, "step": 30}}
    study = foldopt.Study(**fields)
    assert study.site is None  # the file's site, unread
    with pytest.raises(foldopt.ConfigError, match="weather: the file is not read yet"):
        study.require_files()
    result = foldopt.run(study)
    assert (result.study.site.name, result.study.site.latitude) == ("GREENSBORO PIEDMONT TRIAD INT", 36.1)
    far = foldopt.Study(**fields, site={"latitude": 0.0, "longitude": 0.0})
    with pytest.raises(foldopt.ConfigError, match="km from the weather file's site GREENSBORO"):
        foldopt.run(far)


def test_a_study_files_plan_is_swept_and_optimised_as_its_study(tmp_path):
    """load_study gives a Plan for a file with a range of days: sweep and optimize take it as run
    does (they raised a TypeError), its days the search's, and give run's numbers."""
    text = ("name: days\nmode: exact\nsite: {latitude: 34.05, longitude: -118.25, timezone: America/Los_Angeles}\n"
            "date: \"170:172:1\"\np_load: 2.0\npanel: {area: 0.108}\nstep_min: 30\n"
            "fold_angles: {start: 30, stop: 180, step: 30}\n")
    (tmp_path / "days.yaml").write_text(text)
    (tmp_path / "days-optimize.yaml").write_text(text + "optimize: {vary: [fold_angle]}\n")
    plan = foldopt.load_study(tmp_path / "days.yaml")
    assert isinstance(plan, foldopt.Plan)
    swept = foldopt.sweep(plan, p_load=[2.0, 4.0]).table
    assert swept["dayofyear"].nunique() == 3 and swept["p_load_w"].nunique() == 2
    searched = foldopt.optimize(plan, vary="fold_angle").table.set_index("design")
    ran = foldopt.run(tmp_path / "days-optimize.yaml").table.set_index("design")
    pd.testing.assert_series_equal(searched.loc["twofold"], ran.loc["twofold"])
