"""The ``auto`` engine (issues 40, 49): the compiled kernel where numba's cache holds it, small work
in NumPy, where loading the kernel, or its first compile, costs more than it saves; decided once
per request (foldopt.engine.choice, foldopt.studies.request)."""

from __future__ import annotations

import datetime as dt
import json
import os
import pickle
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

import foldopt
from foldopt.engine import choice
from foldopt.engine.choice import engine_for
from foldopt.names import (
    AUTO_CACHED_NUMPY_ROW_STEPS,
    AUTO_NUMPY_ROW_STEPS,
    DEFAULT_ENGINE,
    ENGINES,
)
from foldopt.studies.request import make_request, request_engine

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(params=[False, True], ids=["not-compiled", "cached"])
def cached(request, monkeypatch):
    """The kernel's compile cache empty, then holding it."""
    monkeypatch.setattr(choice, "kernel_cached", lambda: request.param)
    return request.param


def test_auto_takes_numpy_up_to_its_bound_and_the_kernel_above(cached):
    assert DEFAULT_ENGINE == "auto" and set(ENGINES) == {"auto", "numba", "numpy"}
    bound = AUTO_CACHED_NUMPY_ROW_STEPS if cached else AUTO_NUMPY_ROW_STEPS
    assert AUTO_CACHED_NUMPY_ROW_STEPS < AUTO_NUMPY_ROW_STEPS
    assert engine_for("auto", bound) == "numpy"
    assert engine_for("auto", bound + 1) == "numba"
    for named in ("numba", "numpy"):  # a named engine is taken whatever the size
        assert engine_for(named, 1) == engine_for(named, 10 * AUTO_NUMPY_ROW_STEPS) == named
    with pytest.raises(ValueError, match="auto, numba, numpy; got 'fast'"):
        engine_for("fast", 1)


def test_a_request_decides_by_its_days_angles_and_steps(cached):
    study = foldopt.default_study()
    angles, steps = study.fold_angles.count(), round(24 * 60 / study.step_min)
    assert request_engine("auto", study) == "numpy"  # one day: 181 x 1,440, cached or not
    # As many one-day cases as fit under the bound, and one more.
    fit = (AUTO_CACHED_NUMPY_ROW_STEPS if cached else AUTO_NUMPY_ROW_STEPS) // (angles * steps)
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


#: A module of one cached compiled function, and a process that, for each line ``load`` on its
#: stdin, executes the module anew (a new dispatcher, which knows nothing the last one compiled, as
#: in a new process), says whether foldopt.engine.choice.in_cache finds it cached, then calls it and
#: says whether numba loaded it from its cache (numba's own count of cache hits). A line
#: ``cache FOLDER`` sets ``NUMBA_CACHE_DIR`` as a new process would find it: in the environment,
#: which foldopt.engine.choice reads, and in numba's configuration, read again from it (numba reads
#: it once, as it is imported, and a dispatcher's cache takes it from there as it is made).
_MODULE = "from numba import njit\n\n\n@njit(cache=True)\ndef twice(x):\n    return 2.0 * x\n"
_PROCESS = textwrap.dedent(
    """
    import importlib.util, json, os, sys
    from pathlib import Path
    from numba.core import config
    from foldopt.engine.choice import _numba_version, in_cache
    for line in sys.stdin:
        if line.startswith("cache "):
            os.environ["NUMBA_CACHE_DIR"] = line.split(" ", 1)[1].strip()
            config.reload_config()
            continue
        spec = importlib.util.spec_from_file_location("tiny", Path(sys.argv[1]) / "tiny.py")
        tiny = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(tiny)
        said = in_cache(Path(tiny.__file__), "twice", _numba_version())
        tiny.twice(1.0)
        print(json.dumps([said, sum(tiny.twice.stats.cache_hits.values()) > 0]), flush=True)
    """
)


def test_the_cache_is_found_held_exactly_where_numba_loads_from_it(tmp_path):
    """foldopt.engine.choice's reading of numba's cache, held to numba's own behaviour: in each
    state of the cache (empty, filled, the source edited, the index of another numba, in the
    source's __pycache__ or NUMBA_CACHE_DIR), it finds the function cached exactly where numba
    then loads it from the cache rather than compiling it. One process, the module loaded anew in
    it for each state, NUMBA_CACHE_DIR set in it for the last two."""
    source = tmp_path / "tiny.py"
    source.write_text(_MODULE)

    def process() -> subprocess.Popen:
        return subprocess.Popen(
            [sys.executable, "-c", _PROCESS, str(tmp_path)],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
            # numba's cache where each state puts it: not the one this suite may run with.
            env={**{k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}, "PYTHONPATH": str(ROOT)},
        )

    def loaded(running: subprocess.Popen) -> bool:
        running.stdin.write("load\n")
        running.stdin.flush()
        line = running.stdout.readline()
        assert line, f"the process ended, exit {running.wait(timeout=60)}"
        said, hit = json.loads(line)
        assert said == hit
        return said

    def ended(running: subprocess.Popen) -> None:
        running.stdin.close()
        assert running.wait(timeout=300) == 0

    here = process()
    try:
        assert loaded(here) is False  # compiled, and written to tiny's __pycache__
        assert loaded(here) is True
        source.write_text(_MODULE + "# edited\n")
        assert loaded(here) is False
        assert loaded(here) is True
        (index,) = (tmp_path / "__pycache__").glob("tiny.twice-*.nbi")
        with open(index, "rb") as file:
            pickle.load(file)  # numba's version, then the stamp and the compiles
            rest = file.read()
        index.write_bytes(pickle.dumps("0.0.1") + rest)
        assert loaded(here) is False  # another numba's index
        here.stdin.write(f"cache {tmp_path / 'numba-cache'}\n")
        assert loaded(here) is False
        assert loaded(here) is True
        assert list((tmp_path / "numba-cache").rglob("tiny.twice-*.nbi"))
        ended(here)
    finally:
        here.kill()


def test_the_kernels_cache_is_looked_for_where_numba_keeps_it():
    """Each of the kernel's entry points is a cached compiled function whose cache folder and
    index name numba's own locator gives as foldopt.engine.choice looks for them."""
    import importlib
    from fnmatch import fnmatch

    python = f"py{sys.version_info[0]}{sys.version_info[1]}{getattr(sys, 'abiflags', '')}"
    for module, function in choice.KERNEL_FUNCTIONS:
        dispatcher = getattr(importlib.import_module(f"foldopt.engine.{module}"), function)
        source = Path(choice.__file__).with_name(f"{module}.py")
        assert dispatcher.py_func.__qualname__ == function
        assert Path(dispatcher.py_func.__code__.co_filename).resolve() == source.resolve()
        cache = dispatcher._cache  # numba's FunctionCache (a NullCache without cache=True)
        assert Path(cache.cache_path) == choice._cache_folder(source)
        assert fnmatch(cache._cache_file._index_name, f"{module}.{function}-*.{python}.nbi")


def test_looking_for_the_kernel_imports_neither_numba_nor_numpy():
    code = (
        "import sys; from foldopt.engine.choice import kernel_cached; kernel_cached(); "
        "print(sorted({'numba', 'numpy', 'foldopt.engine.kernel'} & set(sys.modules)))"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=60,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
    )
    assert done.returncode == 0 and done.stdout.strip() == "[]", done.stderr


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
