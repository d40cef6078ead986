"""One name per quantity: every column foldopt writes is in the registry (foldopt.output.columns)
and follows its grammar, ``<quantity>[_<design>][_<statistic>]_<unit>``, or is a name pvlib gives
the quantity, or a label; the manual's table is the registry's.

The columns checked are those of every CSV under results/examples/ (what the README and the docs
show) and of every CSV each command writes for a small request, with the rows and the tables of
its ``--format json`` document. The names the issue found disagreeing (``p10_t_solar_h`` beside
``t_solar_p10_h``, ``soc_flat``, ``poa_kwh_m2``...) are refused by the grammar itself."""

from __future__ import annotations

import contextlib
import inspect
import itertools
import json
import re
from pathlib import Path

import pandas as pd
import pytest
from typer.testing import CliRunner

from foldopt.cli.app import app
from foldopt.output.columns import (
    COLUMNS,
    PVGIS_NAMES,
    PVLIB_NAMES,
    ROW_UNIT,
    WORDS,
    describe,
    parse,
    rst_table,
)
from foldopt.studies.reproduce import REPRODUCTIONS

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "results" / "examples"
CONFIGS = ROOT / "configs"
#: A small request of each kind a command answers, together writing every kind of CSV (the map's
#: are the committed examples'): a day, a day with a buffer sized for a target, a measured month
#: with a buffer and re-fold schedules, a cloud ensemble, a panel sizing, a buffer sizing, the
#: reproduction, a joint optimisation and a sweep of latitudes. Each as small as writes its CSVs and
#: their columns whole (30 deg between angles, 15-min steps, two days: the same names as at 10 deg,
#: 5 min and four days).
COMMANDS = {
    "day": ["run"],
    "buffer": ["run", CONFIGS / "camera-buffer.yaml", "--set", "fold_angles.step=30", "--set", "step_min=15"],
    "annual": ["run", CONFIGS / "measured-minutes.yaml", "--set", "storage.capacity_wh=10", "--set",
               "objective.visits=2", "--set", "fold_angles.step=30", "--set", "p_load=2", "--set", "pv_model=ideal"],
    "ensemble": ["run", CONFIGS / "cloud-ensemble.yaml", "--set", "weather.members=3", "--set", "pv_model=ideal",
                 "--set", "fold_angles.step=30", "--set", "date='1:4:3'"],
    "size": ["size", "--cost-per-m2", "164", "--areas", "0.02:0.3:0.05"],
    "size-storage": ["size", CONFIGS / "measured-minutes.yaml", "--storage", "--target-h", "24", "--set",
                     "storage.target.days_pct=60", "--set", "p_load=0.5", "--set", "fold_angles.step=30", "--set",
                     "pv_model=ideal", "--set", "costs.panel_usd_per_m2=150", "--set", "costs.buffer_usd_per_wh=0.5"],
    "reproduce": ["reproduce"],
    "optimize": ["run", CONFIGS / "optimize.yaml", "--set", "date='1:365:120'", "--set",
                 "optimize.tilt={min: 0, max: 90, step: 10}", "--set",
                 "optimize.azimuth={min: 120, max: 240, step: 20}"],
    "sweep": ["sweep", "latitude", "--lat", "0:40:20"],
}  # fmt: skip


def expand(name: str) -> list[str]:
    """Every column a registry name stands for (``t_solar_{design}_h``: one per design)."""
    keys = re.findall(r"\{(\w+)\}", name)
    return [
        name.format(**dict(zip(keys, values, strict=True)))
        for values in itertools.product(*(WORDS[key] for key in keys))
    ]


def problem(column: str) -> str | None:
    """What is wrong with a column's name, or None."""
    entry = describe(column)
    if entry is None:
        return "not in the registry"
    _, unit, meaning = entry
    if meaning == "a swept study field, by its path":
        return None  # a study file's own name for the field
    if column in PVLIB_NAMES:
        return None if PVLIB_NAMES[column] == unit else f"pvlib's unit is {PVLIB_NAMES[column]}"
    if column in PVGIS_NAMES:
        return None if PVGIS_NAMES[column] == unit else f"PVGIS's unit is {PVGIS_NAMES[column]}"
    parts = parse(column)
    if unit in ("", ROW_UNIT):
        return None if parts is None else "a label named as a quantity"
    if parts is None:
        return "not <quantity>[_<design>][_<statistic>]_<unit>"
    return None if parts["unit"] == unit else f"ends in _{parts['unit']}, its unit is {unit}"


def _problems(name: str, columns) -> list[tuple[str, str, str]]:
    return [(name, column, problem(column)) for column in columns if problem(column)]


def test_the_manual_is_the_registry():
    # python -m foldopt.output.columns > docs/columns.rst
    assert (ROOT / "docs" / "columns.rst").read_text() == rst_table()


def test_every_registered_name_follows_the_grammar():
    names = [column for name, _, _ in COLUMNS for column in expand(name)]
    assert len(names) > 150 and not _problems("registry", names)
    # No two entries claim a column: each column is described by the entry it comes from.
    assert [describe(column)[0] for name, _, _ in COLUMNS for column in expand(name)] == [
        name for name, _, _ in COLUMNS for _ in expand(name)
    ]


@pytest.mark.parametrize(
    "old",
    ["p10_t_solar_h", "mean_t_solar_h", "mean_t_solar_flat_h", "objective_h", "objective_flat_h",
     "objective_p10_h", "month_01_mean_t_solar_h", "days_ge_10h", "soc_flat", "surface_tilt_flat",
     "poa_kwh_m2", "pct_of_tracker", "energy_pct_of_tracker", "flat_area_multiple", "days", "settings",
     "recommended_fold_angle_deg", "min_powered_h", "t_solar_mean_flat_h", "energy_kwh"],
)  # fmt: skip
def test_the_grammar_refuses_the_names_it_replaced(old):
    # The statistic first, no unit, a kilo-unit, or an unknown name: each is one the grammar or
    # the registry refuses, so none can be written again.
    assert problem(old) is not None


def test_a_pvlib_name_is_a_parameter_pvlib_takes():
    # The reference is pvlib itself: the parameter names of its own functions.
    import pvlib

    taken = set()
    for function in (
        pvlib.location.Location,
        pvlib.irradiance.get_total_irradiance,
        pvlib.temperature.sapm_cell,
        pvlib.clearsky.ineichen,  # apparent_zenith: the refracted zenith
        pvlib.irradiance.erbs,  # zenith: the geometric one
    ):
        taken |= set(inspect.signature(function).parameters)
    assert set(PVLIB_NAMES) <= taken
    # A pvlib word with foldopt's design or statistic is foldopt's name: it takes its unit.
    assert parse("poa_global_wh_m2")["quantity"] in taken
    assert parse("surface_tilt_flat_deg")["quantity"] in taken


def test_every_committed_example_follows_the_grammar():
    paths = sorted(EXAMPLES.rglob("*.csv"))
    assert len({path.parent for path in paths}) >= 15
    found = []
    for path in paths:
        table = pd.read_csv(path)
        found += _problems(str(path.relative_to(EXAMPLES)), table.columns)
        if "quantity" in table:  # the reproduction's quantities are named by the grammar too
            found += [(path.name, name, "not a quantity") for name in table["quantity"] if parse(name) is None]
    assert not found


@pytest.fixture(scope="module")
def written(tmp_path_factory, figures_drawn_elsewhere):
    """Each command of :data:`COMMANDS` run through the command line with ``--format json``: the
    CSV files' columns, by file name, and the JSON document's row and table columns. Their figures
    are not drawn (conftest's ``figures_drawn_elsewhere``): nothing here reads them, and each
    kind is drawn by the tests of the same studies (test_cli_studies.py, test_figure_pool.py,
    test_report_html.py)."""
    out = tmp_path_factory.mktemp("columns")
    runner = CliRunner(env={"COLUMNS": "200"})
    files, documents = {}, {}
    with contextlib.chdir(out), figures_drawn_elsewhere():
        for name, args in COMMANDS.items():
            done = runner.invoke(app, [*map(str, args), "--format", "json", "--out", name, "-q"])
            assert done.exit_code == 0, (name, done.output)
            documents[name] = json.loads(done.stdout)
            for path in (out / name).glob("*.csv"):
                files.setdefault(path.name, set()).update(pd.read_csv(path, nrows=0).columns)
    return files, documents


def test_every_command_writes_the_registry_s_names(written):
    files, documents = written
    found = [wrong for name, columns in files.items() for wrong in _problems(name, columns)]
    for name, document in documents.items():
        rows = {column for row in document.get("rows", []) for column in row}
        found += _problems(f"{name}: rows", rows)
        for table in ("designs", "near_optimal", "schedule"):
            shown = {column for row in document["answer"][table] for column in row}
            found += _problems(f"{name}: answer {table}", shown)
    assert not found


def test_every_kind_of_csv_a_command_writes_is_checked(written):
    # The names the results folders and a map write, read from their source: a new kind of CSV
    # fails here until a command above or a committed example writes it.
    source = "".join(
        (ROOT / "foldopt" / part).read_text() for part in ("output/folders.py", "studies/cluster.py")
    )
    promised = set(re.findall(r'"(\w+\.csv)"', source))
    promised |= {f"{stem}.csv" for stem in REPRODUCTIONS}
    checked = set(written[0]) | {path.name for path in EXAMPLES.rglob("*.csv")}
    assert len(promised) >= 20 and promised <= checked, promised - checked
