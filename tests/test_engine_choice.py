"""The ``auto`` engine (issue 40): small work in NumPy, where the kernel's first compile costs more
than it saves, decided once per request (foldopt.engine.choice, foldopt.studies.request)."""

from __future__ import annotations

import datetime as dt
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

import foldopt
from foldopt.engine.choice import engine_for
from foldopt.names import AUTO_NUMPY_ROW_STEPS, DEFAULT_ENGINE, ENGINES
from foldopt.studies.request import make_request, request_engine

ROOT = Path(__file__).resolve().parents[1]


def test_auto_takes_numpy_up_to_its_bound_and_the_kernel_above():
    assert DEFAULT_ENGINE == "auto" and set(ENGINES) == {"auto", "numba", "numpy"}
    assert engine_for("auto", AUTO_NUMPY_ROW_STEPS) == "numpy"
    assert engine_for("auto", AUTO_NUMPY_ROW_STEPS + 1) == "numba"
    for named in ("numba", "numpy"):  # a named engine is taken whatever the size
        assert engine_for(named, 1) == engine_for(named, 10 * AUTO_NUMPY_ROW_STEPS) == named
    with pytest.raises(ValueError, match="auto, numba, numpy; got 'fast'"):
        engine_for("fast", 1)


def test_a_request_decides_by_its_days_angles_and_steps():
    study = foldopt.default_study()
    angles, steps = study.fold_angles.count(), round(24 * 60 / study.step_min)
    assert request_engine("auto", study) == "numpy"  # one day: 181 x 1,440
    # As many one-day cases as fit under the bound, and one more.
    fit = AUTO_NUMPY_ROW_STEPS // (angles * steps)
    dates = [(dt.date(2025, 1, 1) + dt.timedelta(days=day)).isoformat() for day in range(fit)]
    assert request_engine("auto", make_request("run", study, fields={"date": dates}).plan) == "numpy"
    more = [*dates, "2025-12-31"]
    assert request_engine("auto", make_request("run", study, fields={"date": more}).plan) == "numba"
    # A joint search over the tilt or the azimuth evaluates some 10^4 designs: the kernel; a
    # search of the fold angle alone is the day's grid.
    joint = study.variant(optimize={"vary": ["fold_angle", "tilt"]})
    assert request_engine("auto", joint) == "numba"
    fold_only = study.variant(optimize={"vary": ["fold_angle"]})
    assert request_engine("auto", fold_only) == "numpy"
    # A weather file's days are not known before it is read: the kernel; a map too.
    year = foldopt.load_study(ROOT / "configs" / "annual-weather.yaml")
    assert request_engine("auto", year) == "numba" and request_engine("auto", None) == "numba"
    assert request_engine("numpy", year) == "numpy" and request_engine("numba", study) == "numba"


def test_the_first_run_after_an_install_compiles_nothing(tmp_path):
    """The README's first command's study with empty compile and table caches (a fresh install):
    no function is compiled (numba writes each to the cache), the kernel is not even imported,
    and the answer says which engine it took."""
    code = (
        "import sys, foldopt; result = foldopt.run(foldopt.default_study()); "
        "print(result.engine, 'foldopt.engine.kernel' in sys.modules)"
    )
    environment = {
        **os.environ,
        "NUMBA_CACHE_DIR": str(tmp_path / "numba"),
        "FOLDOPT_CACHE_DIR": str(tmp_path / "foldopt"),
    }
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=environment, timeout=120
    )
    assert done.stdout.strip() == "numpy False", done.stderr
    compiled = list((tmp_path / "numba").rglob("*.nbi")) if (tmp_path / "numba").exists() else []
    assert compiled == []


def test_the_command_line_records_the_engine_its_request_took(tmp_path):
    from typer.testing import CliRunner

    from foldopt.cli.app import app

    out = tmp_path / "day"
    done = CliRunner().invoke(app, ["run", "--out", str(out), "-q"])
    assert done.exit_code == 0, done.output
    assert json.loads((out / "run.json").read_text())["engine"] == "numpy"
    assert foldopt.run(foldopt.default_study()).engine == "numpy"
