"""Study files, sweeps, sizing and script output through the command line."""

import contextlib
import json
import struct
import sys
from pathlib import Path

import pandas as pd
import pytest
from typer.testing import CliRunner

from foldopt.cli.app import app
from foldopt.output import figures
from foldopt.studies.request import make_request
from test_cli import assert_one_line_error

runner = CliRunner()
#: Shipped studies a test of their own runs as a user does (and checks the same folder of): each
#: run once in the suite.
RUN_ELSEWHERE = {"camera-winter": "test_camera_winter.py", "pvgis-offgrid": "test_pvgis_offgrid.py"}
if sys.platform == "linux":  # where test_figure_pool.py's commands run (they set their cores)
    RUN_ELSEWHERE |= {name: "test_figure_pool.py" for name in ("shin2015", "camera-buffer")}
CONFIGS = sorted(
    path
    for path in Path(__file__).resolve().parent.parent.joinpath("configs").glob("*.yaml")
    if path.stem not in RUN_ELSEWHERE
)
SMALL = ["--lon", "0", "--timezone", "UTC", "--area", "0.1", "--step-min", "15", "--angle-step", "10"]


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args])


def one_line_error(result, *words):
    assert result.exit_code == 2, result.output
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), result.stderr
    assert all(word in lines[0] for word in words), lines[0]


#: Shipped studies run smaller than they ship (fewer days, members, latitudes, loads or angles):
#: the folder holds the same files and figures as at full size (annual's and camera-profile's
#: series still above foldopt.studies.series.PARQUET_ROWS), for a fraction of the work; the study
#: as shipped is still made a request whole (validated, within the size limits).
SMALLER = {
    "annual": ["--set", "date=1:365:14", "--set", "fold_angles.step=10"],  # 27 of 53 days, 18 angles
    "annual-weather": ["--set", "date=1:365:30"],  # 13 of the file's 365 days
    "camera-profile": ["--set", "date=1:365:14", "--set", "fold_angles.step=30"],
    "cloud-ensemble": ["--set", "weather.members=2", "--set", "date=1:365:30"],
    "design-map": ["--set", "site.latitude=-60:60:30", "--set", "p_load='1:19:6'"],
    "load-sweep": ["--set", "p_load='1:19:6'"],  # 4 of 38 loads
}


#: The figures of a weather year (the year's, the days', the weather's) that test_camera_winter.py's
#: shipped study draws whole, and checks it does: of the studies here, drawn without their pixels
#: (every artist drawn, nothing laid out or rasterised), as most of their folders' drawing.
WHOLE_IN_CAMERA_WINTER = frozenset({
    "annual_t_solar.png", "annual_t_solar_vs_fold_angle.png", "daily_t_solar_distribution.png",
    "day_hour_power.png", "day_hour_switch_state.png", "monthly_energy_t_solar.png", "weather_minutes.png",
})  # fmt: skip
#: Figures a shipped study here draws whole, and checks it does, for the others here that draw them
#: (drawn there without their pixels): the study -> the files.
WHOLE_HERE = {
    "shin2015-single-diode": frozenset({
        "comparison.png", "power_curves.png", "switching.png", "t_solar_vs_fold_angle.png", "tracker_standby.png",
    }),
}  # fmt: skip


def assert_drawn_whole(png: Path) -> None:
    """A figure's file is drawn whole: a PNG of more than 100 pixels each way (not conftest's PNG
    of one pixel)."""
    data = png.read_bytes()
    assert data[12:16] == b"IHDR" and min(struct.unpack(">II", data[16:24])) > 100, png.name


@contextlib.contextmanager
def pixels_but_for(files, without_pixels):
    """Within the block, a results folder's figures are drawn whole but those named in ``files``,
    drawn without pixels (conftest's ``without_pixels``)."""
    whole = figures.figure_bytes

    def figure_bytes(file, args, kwargs):
        with without_pixels() if file in files else contextlib.nullcontext():
            return whole(file, args, kwargs)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(figures, "figure_bytes", figure_bytes)
        yield


#: Every shipped study's folder as a user gets it, its figures drawn whole (but those another
#: study draws whole: :data:`WHOLE_IN_CAMERA_WINTER`, :data:`WHOLE_HERE`).
@pytest.mark.figure_pixels
@pytest.mark.parametrize("config", CONFIGS, ids=[c.stem for c in CONFIGS])
def test_every_shipped_config_runs(tmp_path, config, without_pixels):
    if config.stem in SMALLER:
        make_request("run", config)  # the study as shipped: valid, within the limits
    out = tmp_path / config.stem
    whole = WHOLE_HERE.get(config.stem, frozenset())
    with pixels_but_for(WHOLE_IN_CAMERA_WINTER.union(*WHOLE_HERE.values()) - whole, without_pixels):
        result = invoke("run", config, *SMALLER.get(config.stem, []), "--out", out, "--quiet")
    assert result.exit_code == 0, result.output
    assert_a_users_folder(out)
    for name in whole:
        assert_drawn_whole(out / name)


def assert_a_users_folder(out: Path):
    """A shipped study's folder: its run.json with the input's hash, a table and a figure."""
    names = {p.name for p in out.iterdir()}
    assert "run.json" in names and ({"summary.csv"} <= names or {"results.csv"} <= names or {"optimum.csv"} <= names)
    assert any(name.endswith(".png") for name in names)
    assert len(json.loads((out / "run.json").read_text())["input_sha256"]) == 64


def test_sweep_latitude_makes_the_design_map(tmp_path, figures_drawn_elsewhere):
    out = tmp_path / "map"
    with figures_drawn_elsewhere():  # the maps' kinds: configs/design-map.yaml's, drawn whole above
        result = invoke("sweep", "latitude", "--lat", "-40:40:40", "--p-load", "1:9:4", "--days", "2025-03-20",
                        *SMALL, "--out", out)
    assert result.exit_code == 0, result.output
    table = pd.read_csv(out / "results.csv")
    assert len(table) == 3 * 3 * 4  # latitudes x loads x designs (flat, twofold, tracker gross and net)
    assert {"gain_map_latitude_load.png", "fold_angle_map_latitude_load.png"} <= {p.name for p in out.iterdir()}


def test_sweep_day_and_load_and_identical_reruns(tmp_path, figures_drawn_elsewhere):
    out = tmp_path / "days"
    args = ["sweep", "day", "--lat", "34", "--days", "1:365:120", "--p-load", "3", *SMALL, "--out", out]
    # The figures written, not drawn: a day sweep's are drawn whole by test_report_html.py's
    # (``annual``), the load sweep's by configs/load-sweep.yaml's above.
    with figures_drawn_elsewhere():
        assert invoke(*args).exit_code == 0
        first = (out / "results.csv").read_bytes()
        assert (out / "annual_t_solar.png").exists()
        assert invoke(*args, "--overwrite").exit_code == 0
        assert (out / "results.csv").read_bytes() == first
        out = tmp_path / "loads"
        result = invoke("sweep", "load", "--lat", "34", "--days", "2025-06-21", "--p-load", "1:10:3", *SMALL,
                        "--out", out)
    assert result.exit_code == 0, result.output
    assert (out / "t_solar_vs_load.png").exists()


def test_json_output_is_parseable_and_quiet_is_silent(tmp_path):
    result = invoke("sweep", "load", "--lat", "34", "--days", "2025-06-21", "--p-load", "1:3:1", *SMALL,
                    "--out", tmp_path / "j", "--format", "json", "--quiet")
    assert result.exit_code == 0, result.output
    payload = json.loads(result.stdout)
    assert len(payload["rows"]) == 12 and {"design", "t_solar_h"} <= set(payload["rows"][0])
    assert result.stderr == ""


def test_size_finds_the_net_benefit_optimum(tmp_path):
    out = tmp_path / "size"
    result = invoke("size", "--cost-per-m2", "400", "--areas", "0.02:0.3:0.01", "--out", out)
    assert result.exit_code == 0, result.output
    best = pd.read_csv(out / "sizing_best.csv").set_index("design")
    table = pd.read_csv(out / "sizing.csv")
    for design in ("flat", "twofold"):
        rows = table[table.design == design]
        assert best.loc[design, "net_benefit_usd"] == pytest.approx(rows["net_benefit_usd"].max())
        # Shin et al. Eq. 7 over 20 years of 365 days at 0.22 $/kWh.
        row = rows.iloc[5]
        assert row["benefit_usd"] == pytest.approx(0.22 * row["t_solar_h"] * 4.398 / 1000 * 365 * 20)
    assert (out / "net_benefit_vs_area.png").exists()


@pytest.mark.parametrize(
    "args,words",
    [
        (["sweep", "latitude", "--lat", "10:0:5", "--p-load", "2", "--days", "2025-03-20"], ["--lat", "empty range"]),
        (["sweep", "latitude", "--lat", "-95:0:5", "--p-load", "2", "--days", "2025-03-20"], ["--lat[0]", "[-90, 90]"]),
        (["sweep", "load", "--lat", "10", "--p-load", "-2:4:1", "--days", "2025-03-20"],
         ["--p-load[0,1,2] = -2.0, -1.0, 0.0", "(0, 1e+06]"]),
        (["sweep", "load", "--lat", "10", "--p-load", "3", "--days", "2025-03-20"], ["--p-load", "range"]),
        (["sweep", "day", "--lat", "10", "--p-load", "2", "--days", "300:20:7"], ["--days/--date", "empty range"]),
        (["sweep", "angle", "--lat", "10", "--p-load", "2", "--days", "2025-03-20", "--angle-step", "200"],
         ["--angle-step", "(0, 180]"]),
        (["sweep", "tilt", "--lat", "10"], ["No such command 'tilt'", "angle, latitude, day, load"]),
        (["size", "--cost-per-m2", "100", "--cost-per-w", "1"], ["--cost-per-m2 / --cost-per-w", "not both"]),
        (["size", "--cost-per-w", "-1"], ["--cost-per-w", "> 0"]),
        (["size", "--cost-per-m2", "100", "--areas", "0.5:0.1:0.1"], ["--areas", "empty range"]),
        (["run", "--format", "xml"], ["--format", "table, json"]),
        (["sweep", "day", "--lat", "36", "--p-load", "2", "--days", "year", "--weather", "nope.csv"],
         ["weather", "file not found"]),
        (["sweep", "day", "--lat", "36", "--p-load", "2", "--days", "year", "--objective", "best"],
         ["--objective", "pNN"]),
        (["sweep", "day", "--lat", "36", "--p-load", "2", "--mode", "paper", "--transposition", "perez"],
         ["paper mode is beam-only"]),
        (["size", "no-such-study.yaml", "--cost-per-m2", "100"], ["config", "not found"]),
        (["run", "configs/design-map.yaml", "--format", "json", "--p-load", "2"], ["No such option"]),
    ],
)
def test_bad_input_one_line_exit_2_nothing_written(tmp_path, args, words):
    out = tmp_path / "out"
    extra = [] if args[0] in ("run", "size") or args[1] == "tilt" else SMALL
    if "--angle-step" in args:  # each option once: the case's own value, not SMALL's
        extra = extra[:-2]
    one_line_error(invoke(*args[:2], *extra, *args[2:], "--out", out), *words)
    assert not out.exists()


def test_a_weather_file_alone_runs_a_year(tmp_path, figures_drawn_elsewhere):
    import pvlib

    tmy3 = Path(pvlib.__file__).parent / "data" / "723170TYA.CSV"
    out = tmp_path / "year"
    # 15-min steps and 30 deg between fold angles: what is checked is the study the file completes and
    # the year's table, not the steps or the angles.
    # Its figures written, not drawn: a weather year's, drawn by configs/annual-weather.yaml's above.
    with figures_drawn_elsewhere():
        result = invoke("sweep", "angle", "--weather", tmy3, "--p-load", "2", "--area", "0.108", "--angle-step",
                        "30", "--step-min", "15", "--albedo", "0.3", "--iam", "ashrae", "--set",
                        "tracker.model=single-axis", "--out", out, "-q", "--format", "json")
    assert result.exit_code == 0, result.output
    meta = json.loads((out / "run.json").read_text())
    study = meta["study"]
    assert study["site"]["latitude"] == 36.1 and study["site"]["altitude"] == 273.0
    assert (study["albedo"], study["iam"], study["tracker"]["model"]) == (0.3, "ashrae", "single-axis")
    assert study["objective"]["statistic"] == "mean"
    summary = pd.read_csv(out / "annual_summary.csv")
    assert set(summary["design"]) == {"flat", "twofold", "tracker", "tracker-net"} and (summary["days_n"] == 365).all()
    for column in ("energy_harvested_wh", "poa_global_wh_m2", "energy_harvested_gain_vs_flat_pct",
                   "share_of_tracker_pct"):
        assert summary[column].notna().all(), column
    # A site far from the file's is refused with both sites named; --force-site keeps it.
    far = invoke("sweep", "angle", "--weather", tmy3, "--lat", "0", "--lon", "0", "--p-load", "2", "--area", "0.108",
                 "--out", tmp_path / "far")
    assert_one_line_error(far, "9,106 km", "GREENSBORO", "(0, 0)")
    assert not (tmp_path / "far").exists()
    bad = invoke("sweep", "angle", "--weather", tmy3, "--p-load", "2", "--area", "0.108", "--set", "albedo",
                 "--out", tmp_path / "bad")
    assert_one_line_error(bad, "--set", "KEY=VALUE")
    bad = invoke("sweep", "angle", "--weather", tmy3, "--p-load", "2", "--area", "0.108", "--set", "tracker.gcr=2",
                 "--out", tmp_path / "bad")
    assert_one_line_error(bad, "tracker.gcr", "(0, 1]")


def test_a_map_takes_the_load_range_of_its_study_file(tmp_path, scheduler, figures_drawn_elsewhere):
    """A study file's ``p_load`` range is the map's loads, checked like ``--p-load`` (it was an
    internal error); a load no site carries is said without a best site."""
    study = tmp_path / "ranged.yaml"
    shipped = Path(__file__).resolve().parent.parent / "configs" / "load-sweep.yaml"
    study.write_text(shipped.read_text().replace('p_load: "0.5:19:0.5"', 'p_load: "1:31:30"'))
    # On the in-process cluster (conftest.scheduler): what is tested is the map's loads, not its cluster.
    # Its maps written, not drawn: what is read is the answer (a map's are drawn by test_report_html.py).
    with figures_drawn_elsewhere():
        shown = invoke("map", "--config", study, "--lat", "0", "--lon", "0", "--step-min", "60", "--angle-step",
                       "90", "--scheduler", scheduler, "--out", tmp_path / "m", "--format", "json")
    assert shown.exit_code == 0, shown.output
    answer = json.loads(shown.stdout)["answer"]
    assert "P_load 2 loads, 1 to 31 W" in answer["defaults"]["taken"]
    unreachable = next(line for line in answer["lines"] if line.startswith("P_load 31 W"))
    assert "folding beats flat at 0 of 1 site;" in unreachable and " at )" not in unreachable
