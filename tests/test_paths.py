"""One request, one answer, by every path (issue 47): a weather file alone, with its site given,
by a source's name and read back from ``weather path --out``; a YAML study, the command line's
options, ``--set`` and the API's keywords. What one path takes the others take: the numbers of
the answer are equal to the bit, and so is the site the answer ran at. A field given twice and a
boolean where a number is expected are refused in one line, by every path.
"""

from __future__ import annotations

import contextlib
import json
from pathlib import Path

import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

import foldopt
from foldopt.cli.app import app
from foldopt.inputs.study_file import default_study_path
from test_weather_fetch import RECORDED, pvgis, server  # noqa: F401 (the local PVGIS and its route)

runner = CliRunner()
ROOT = Path(__file__).resolve().parent.parent
WEATHER = str(ROOT / "configs" / "weather" / "723170TYA.CSV")
#: The TMY3 file's own site, as its header gives it.
GREENSBORO = {"name": "GREENSBORO PIEDMONT TRIAD INT", "latitude": 36.1, "longitude": -79.95,
              "altitude": 273.0, "timezone": "UTC-05:00"}
#: A day of a weather file, every fold angle on a coarse grid, the NumPy path: each run a second.
QUICK = ["--days", "2025-06-21", "--step-min", "10", "--angle-step", "5", "--engine", "numpy"]


def cli(tmp_path: Path, *args, figures=contextlib.nullcontext) -> tuple[dict, dict]:
    """A command's JSON document and its run.json (its figures made within ``figures()``)."""
    out = tmp_path / f"out{len(list(tmp_path.glob('out*')))}"
    with figures():
        result = runner.invoke(app, [*map(str, args), "--format", "json", "--out", str(out)])
    assert result.exit_code == 0, result.output
    return json.loads(result.stdout), json.loads((out / "run.json").read_text())


def numbers(document: dict) -> list:
    """What an answer says in numbers: its rows and its result, the run's name left out."""
    result = {key: value for key, value in document["answer"]["result"].items() if key != "name"}
    return [document["rows"], result, document["answer"]["designs"]]


def site_of(meta: dict) -> dict:
    return {key: meta["study"]["site"][key] for key in GREENSBORO}


def test_a_weather_file_completes_the_site_it_is_given(tmp_path, monkeypatch, figures_drawn_elsewhere):
    """--weather FILE alone, with the file's --lat/--lon, by --set and from a YAML study: one
    answer, at the file's altitude and with its station's name (with --lat/--lon it ran at 0 m,
    nameless). The answer's figures are drawn once, by the first path."""
    monkeypatch.chdir(tmp_path)
    alone, meta = cli(tmp_path, "sweep", "angle", "--weather", WEATHER, *QUICK)
    assert site_of(meta) == GREENSBORO
    paths = {
        "--lat/--lon": ["sweep", "angle", "--weather", WEATHER, "--lat", "36.1", "--lon", "-79.95",
                        *QUICK],
        "--set": ["sweep", "angle", "--set", f"weather={WEATHER}", "--set",
                  "site={latitude: 36.1, longitude: -79.95}", *QUICK],
    }
    for name, args in paths.items():
        document, meta = cli(tmp_path, *args, figures=figures_drawn_elsewhere)
        assert numbers(document) == numbers(alone), name
        assert site_of(meta) == GREENSBORO, name
    # The embedded study with the file, as a YAML study the user wrote: run, not sweep angle.
    data = yaml.safe_load(default_study_path().read_text())
    for key in ("site", "sky", "geometry", "pv_model"):  # exact mode's own, as the policy gives it
        data.pop(key)
    data["panel"] = {key: data["panel"][key] for key in ("area", "efficiency")}  # |latitude| tilt
    data.update(mode="exact", weather=WEATHER, name="sweep-angle",
                description=alone["answer"]["title"])
    (tmp_path / "study.yaml").write_text(yaml.safe_dump(data))
    document, meta = cli(tmp_path, "run", "study.yaml", "--set", "date=2025-06-21", "--set",
                         "step_min=10", "--set", "fold_angles={start: 5, stop: 180, step: 5}",
                         "--engine", "numpy", figures=figures_drawn_elsewhere)
    assert numbers(document)[0] == numbers(alone)[0]
    assert site_of(meta) == GREENSBORO
    # The API's keywords.
    result = foldopt.sweep(foldopt.default_study(), "angle", weather=WEATHER, date="2025-06-21",
                           step_min=10, fold_angles={"step": 5}, engine="numpy")
    assert result.study.site.altitude == 273.0 and result.study.site.name == GREENSBORO["name"]
    assert float(result.summary.set_index("design").loc["twofold", "t_solar_h"]) == next(
        row["t_solar_h"] for row in alone["rows"] if row["design"] == "twofold")


def test_a_site_moved_away_from_its_file_keeps_none_of_the_files_site(tmp_path, monkeypatch):
    """With force_site a site 500 km away is another place: the file's altitude and name are not
    its own."""
    monkeypatch.chdir(tmp_path)
    _, meta = cli(tmp_path, "sweep", "angle", "--weather", WEATHER, "--lat", "40", "--lon", "-79.95",
                  "--force-site", *QUICK)
    assert meta["study"]["site"]["altitude"] == 0.0 and meta["study"]["site"]["name"] is None


def test_weather_by_name_is_the_file_it_fetched(pvgis, server, tmp_path, figures_drawn_elsewhere):  # noqa: F811
    """--weather pvgis-tmy at a site, the answer read back with weather path --out alone, and
    with the site given: one answer (the fetched run said 250 m in its note and ran at 0 m). Its
    figures are drawn once, by the fetched run."""
    pvgis("ok")
    fetched, meta = cli(tmp_path, "sweep", "angle", "--lat", "45", "--lon", "8", "--weather",
                        "pvgis-tmy", *QUICK)
    kept = runner.invoke(app, ["weather", "path", "--lat", "45", "--lon", "8", "--out", "site.json"])
    assert kept.exit_code == 0, kept.output
    alone, alone_meta = cli(tmp_path, "sweep", "angle", "--weather", "site.json", *QUICK,
                            figures=figures_drawn_elsewhere)
    placed, placed_meta = cli(tmp_path, "sweep", "angle", "--weather", "site.json", "--lat", "45",
                              "--lon", "8", *QUICK, figures=figures_drawn_elsewhere)
    # A study at that place given a source: fetched for the study's site (it was refused: "give
    # --lat/--lon", though the study holds them).
    data = yaml.safe_load(default_study_path().read_text())
    data["site"] = {"latitude": 45.0, "longitude": 8.0, "altitude": 999.0, "name": "elsewhere"}
    data["panel"] = {key: data["panel"][key] for key in ("area", "efficiency")}  # |latitude| tilt
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(data))
    studied, studied_meta = cli(tmp_path, "sweep", "angle", "--config", "s.yaml", "--weather",
                                "pvgis-tmy", *QUICK, figures=figures_drawn_elsewhere)
    assert numbers(fetched) == numbers(alone) == numbers(placed) == numbers(studied)
    sites = [m["study"]["site"] for m in (meta, alone_meta, placed_meta, studied_meta)]
    assert sites[0] == sites[1] == sites[2] == sites[3]  # the answer's altitude, not the study's
    assert sites[0]["altitude"] > 0  # the file's, as its answer gives it
    assert all(str(sites[0]["altitude"]).rstrip("0").rstrip(".") in note or "m" not in note
               for note in fetched["answer"]["lines"] if "altitude" in note)


def test_a_buffer_by_every_path_is_one_answer(tmp_path, monkeypatch, figures_drawn_elsewhere):
    """--storage-wh/--min-soc, --set, a YAML study's storage section, and the API's keyword (the
    answer's figures drawn once, by the first)."""
    monkeypatch.chdir(tmp_path)
    fast = ["--step-min", "10", "--angle-step", "10"]
    options, _ = cli(tmp_path, "sweep", "angle", "--storage-wh", "20", "--min-soc", "0.2", *fast)
    settings_, _ = cli(tmp_path, "sweep", "angle", "--set", "storage.capacity_wh=20", "--set",
                       "storage.min_soc=0.2", *fast, figures=figures_drawn_elsewhere)
    assert numbers(options) == numbers(settings_)
    data = yaml.safe_load(default_study_path().read_text())
    data.update(storage={"capacity_wh": 20, "min_soc": 0.2}, step_min=10,
                fold_angles={"start": 10, "stop": 180, "step": 10})
    (tmp_path / "buffer.yaml").write_text(yaml.safe_dump(data))
    study_file, _ = cli(tmp_path, "run", "buffer.yaml", figures=figures_drawn_elsewhere)
    assert numbers(study_file)[0] == numbers(options)[0]
    api = foldopt.sweep(foldopt.default_study(), "angle", storage={"capacity_wh": 20, "min_soc": 0.2},
                        step_min=10, fold_angles={"step": 10})
    assert json.loads(json.dumps(api.answer.to_dict()["designs"])) == options["answer"]["designs"]


@pytest.mark.parametrize(("args", "first", "second"), [
    (["sweep", "angle", "--storage-wh", "20", "--set", "storage.capacity_wh=30"],
     "--storage-wh = 20", "--set storage.capacity_wh = 30"),
    (["sweep", "angle", "--storage-wh", "20", "--min-soc", "0.3", "--set", "storage.min_soc=0.2"],
     "--min-soc = 0.3", "--set storage.min_soc = 0.2"),
    (["size", "--storage", "--target-h", "24", "--set", "storage.target.powered_h=20"],
     "--target-h = 24", "--set storage.target.powered_h = 20"),
    (["sweep", "angle", "--set", "p_load=2", "--set", "p_load=3"], "--set p_load", "given twice"),
    (["map", "--area", "0.2", "--set", "panel.area=0.3"], "--area = 0.2", "--set panel.area = 0.3"),
    (["optimize", "--vary", "fold_angle", "--set", "optimize.vary=[tilt]"], "--vary", "--set optimize.vary"),
], ids=["storage-wh", "min-soc", "target-h", "set-twice", "map-area", "vary"])
def test_a_field_given_twice_is_refused_naming_both(tmp_path, monkeypatch, args, first, second):
    monkeypatch.chdir(tmp_path)
    result = runner.invoke(app, [*args, "--out", "out"])
    assert result.exit_code == 2, result.output
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and first in lines[0] and second in lines[0], lines
    assert not (tmp_path / "out").exists()


def test_a_keyword_and_axes_for_one_field_is_refused():
    study = foldopt.default_study()
    with pytest.raises(foldopt.ConfigError, match="given twice"):
        foldopt.sweep(study, "latitude", latitude=[0, 10], axes={"site.latitude": [20, 30]})
    with pytest.raises(foldopt.ConfigError, match="given twice"):
        foldopt.sweep(study, "latitude", axes={"site.latitude": [20, 30]}, **{"site.latitude": [0]})


@pytest.mark.parametrize("path", ["cli", "yaml", "api"])
def test_a_boolean_is_no_number_by_any_path(tmp_path, monkeypatch, path):
    """true where a number is expected ran as 1 (a 1 Wh buffer, a 1 W load) without a word."""
    monkeypatch.chdir(tmp_path)
    if path == "api":
        with pytest.raises(foldopt.ConfigError, match=r"^p_load = true: must be a number"):
            foldopt.sweep(foldopt.default_study(), "angle", p_load=True)
        return
    if path == "yaml":
        data = yaml.safe_load(default_study_path().read_text())
        (tmp_path / "s.yaml").write_text(yaml.safe_dump({**data, "p_load": True}))
        args = ["run", "s.yaml"]
        said = "p_load = true: must be a number, not true or false"
    else:
        args = ["sweep", "angle", "--set", "storage.capacity_wh=true"]
        said = "storage.capacity_wh = true: must be a number, not true or false"
    result = runner.invoke(app, [*args, "--out", "out"])
    lines = result.stderr.strip().splitlines()
    assert result.exit_code == 2 and len(lines) == 1 and lines[0].startswith(f"error: {said}"), lines


def test_a_weather_section_with_a_file_and_a_source_is_refused(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    data = yaml.safe_load(default_study_path().read_text())
    data.update(weather={"source": "pvgis-tmy", "path": WEATHER})
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(data))
    result = runner.invoke(app, ["run", "s.yaml", "--offline", "--out", "out"] if False else
                           ["run", "s.yaml", "--out", "out"])
    assert result.exit_code == 2
    assert result.stderr.strip().splitlines() == [
        f"error: weather: names a file ({WEATHER}) and a source (pvgis-tmy); give one: weather.path "
        "(--weather FILE) or weather.source (--weather NAME)"]


@settings(max_examples=6, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(latitude=st.floats(-60, 60), day=st.integers(1, 365), load=st.floats(0.5, 8))
def test_options_set_and_keywords_are_one_request(tmp_path, latitude, day, load):
    """Random sites, days and loads: the command line's options, --set and the API's keywords make
    one plan, to the bit."""
    from foldopt.studies.request import make_request

    date = (foldopt.default_study().date.replace(month=1, day=1).toordinal() + day - 1)
    date = type(foldopt.default_study().date).fromordinal(date).isoformat()
    options = make_request("sweep angle", options={"lat": f"{latitude!r}", "days": date,
                                                   "p_load": f"{load!r}"})
    settings_ = make_request("sweep angle", settings=[f"site.latitude={latitude!r}", f"date={date}",
                                                      f"p_load={load!r}"])
    keywords = make_request("sweep angle", foldopt.default_study(),
                            fields={"latitude": latitude, "date": date, "p_load": load})
    # the same study but for its description, which names where the request started
    studies = [request.plan.base.model_copy(update={"description": ""})
               for request in (options, settings_, keywords)]
    assert studies[0] == studies[1] == studies[2]
    assert options.taken == settings_.taken == keywords.taken
