"""The study's storage section (issue 41, item 1) and PVGIS's hourconsumption load (item 5): every
bad value is one line naming its field or option with exit 2, a preset fills only the fields left
out, a study without storage is the study it was, and PVGIS's 24 fractions of a day's energy are
the watt profile they stand for."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

import foldopt
from foldopt import names
from foldopt.cli.app import app
from foldopt.inputs.load_profile import describe_load, load_shape
from foldopt.inputs.storage_section import IDEAL, PRESETS
from foldopt.inputs.study import make_study
from foldopt.inputs.study_file import default_study_path

ROOT = Path(__file__).resolve().parent.parent
runner = CliRunner()
#: The embedded study's data, and a cheap sweep's options (hourly steps, a 30-degree grid).
EMBEDDED = yaml.safe_load(default_study_path().read_text())
QUICK = ["--step-min", "60", "--angle-step", "30"]
#: PVGIS-like shares of a camera's day: a night base, more by day, an evening peak (sum 1).
SHARES = [0.03] * 7 + [0.05] * 10 + [0.06] * 3 + [0.0275] * 4


def _study(storage=None, **changes):
    data = {**EMBEDDED, **changes}
    if storage is not None:
        data["storage"] = storage
    return make_study(data)


# ---- bad values: one line naming the field (the option where one set it), exit 2 ----------------

BAD = [
    ("capacity-negative", ["--storage-wh", "-1"], ["--storage-wh = -1.0", "[0, 1e+06] Wh"]),
    ("capacity-text", ["--storage-wh", "lots"], ["--storage-wh", "number"]),
    # the option given is named, not the one missing (--min-soc alone made a buffer with no capacity)
    ("capacity-missing", ["--min-soc", "0.2"], ["error: --min-soc:", "capacity_wh", "--storage-wh"]),
    ("min-soc-one", ["--storage-wh", "10", "--min-soc", "1"], ["--min-soc = 1.0", "[0, 1)"]),
    ("min-soc-nan", ["--storage-wh", "10", "--min-soc", "nan"], ["--min-soc", "[0, 1)"]),
    (
        "restart-below-min",
        ["--storage-wh", "10", "--min-soc", "0.3", "--set", "storage.restart_soc=0.1"],
        ["storage: restart_soc (0.1) is below min_soc (0.3)"],
    ),
    (
        "restart-below-preset-min",
        ["--storage-wh", "10", "--set", "storage.preset=lifepo4", "--set", "storage.restart_soc=0.1"],
        ["restart_soc (0.1)", "min_soc (0.2, the lifepo4 preset's)"],
    ),
    (
        "charge-efficiency-zero",
        ["--storage-wh", "10", "--set", "storage.charge_efficiency=0"],
        ["storage.charge_efficiency = 0", "(0, 1]"],
    ),
    (
        "discharge-efficiency-above-one",
        ["--storage-wh", "10", "--set", "storage.discharge_efficiency=1.5"],
        ["storage.discharge_efficiency = 1.5", "(0, 1]"],
    ),
    (
        "self-discharge-whole",
        ["--storage-wh", "10", "--set", "storage.self_discharge=1"],
        ["storage.self_discharge = 1", "[0, 1) per day"],
    ),
    (
        "max-charge-zero",
        ["--storage-wh", "10", "--set", "storage.max_charge_w=0"],
        ["storage.max_charge_w = 0", "(0, 1e+06] W"],
    ),
    (
        "max-discharge-negative",
        ["--storage-wh", "10", "--set", "storage.max_discharge_w=-5"],
        ["storage.max_discharge_w = -5", "(0, 1e+06] W"],
    ),
    (
        "initial-soc-above-one",
        ["--storage-wh", "10", "--set", "storage.initial_soc=1.2"],
        ["storage.initial_soc = 1.2", "[0, 1]"],
    ),
    (
        "preset-misspelt",
        ["--storage-wh", "10", "--set", "storage.preset=lifepo"],
        ["storage.preset = 'lifepo'", "supercapacitor, lifepo4", "did you mean 'lifepo4'"],
    ),
    (
        "unknown-field",
        ["--storage-wh", "10", "--set", "storage.capcity_wh=5"],
        ["storage.capcity_wh: unknown field"],
    ),
]


def _assert_one_line(result, words, folder: Path):
    assert result.exit_code == 2, (result.exit_code, result.output)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), result.stderr
    assert "Traceback" not in result.output and result.stdout == ""
    for word in words:
        assert word in lines[0], (word, lines[0])
    assert not (folder / "out").exists()


@pytest.mark.parametrize("args,words", [case[1:] for case in BAD], ids=[case[0] for case in BAD])
def test_a_bad_storage_value_is_one_line_naming_it(tmp_path, monkeypatch, args, words):
    monkeypatch.chdir(tmp_path)
    result = runner.invoke(app, ["sweep", "angle", *args, *QUICK, "--out", "out"])
    _assert_one_line(result, words, tmp_path)


def test_the_optimize_command_takes_the_storage_options_too(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    result = runner.invoke(app, ["optimize", "--storage-wh", "-3", "--out", "out"])
    _assert_one_line(result, ["--storage-wh = -3.0", "[0, 1e+06] Wh"], tmp_path)


#: Storage sections and load profiles of a YAML study, and the words of their one error line.
BAD_FILES = [
    ("storage-not-a-mapping", {"storage": "lifepo4"}, ["storage", "valid dictionary"]),
    ("restart-below-min", {"storage": {"capacity_wh": 5, "min_soc": 0.5, "restart_soc": 0.4}},
     ["restart_soc (0.4) is below min_soc (0.5)"]),
    ("hours-23", {"load_profile": {"hourconsumption": SHARES[:23], "consumptionday": 48}},
     ["load_profile", "hourconsumption: 23 values", "24 fractions"]),
    ("hours-negative",
     {"load_profile": {"hourconsumption": [-0.01, *SHARES[1:]], "consumptionday": 48}},
     ["hourconsumption[0] = -0.01", ">= 0"]),
    ("hours-sum", {"load_profile": {"hourconsumption": [0.02] * 24, "consumptionday": 48}},
     ["sum to 0.48", "must sum to 1"]),
    ("hours-without-energy", {"load_profile": {"hourconsumption": SHARES}},
     ["hourconsumption and consumptionday [Wh] go together"]),
    ("energy-zero", {"load_profile": {"hourconsumption": SHARES, "consumptionday": 0}},
     ["load_profile.consumptionday = 0", "(0, 1e+07] Wh"]),
    ("hours-linear",
     {"load_profile": {"hourconsumption": SHARES, "consumptionday": 48, "interpolation": "linear"}},
     ["interpolation: hourconsumption", "step"]),
    ("hours-and-daily",
     {"load_profile": {"hourconsumption": SHARES, "consumptionday": 48, "daily": {"00:00": 1}}},
     ["one of daily", "not daily and hourconsumption"]),
]


@pytest.mark.parametrize("changes,words", [case[1:] for case in BAD_FILES],
                         ids=[case[0] for case in BAD_FILES])
def test_a_bad_study_file_section_is_one_line_naming_it(tmp_path, monkeypatch, changes, words):
    monkeypatch.chdir(tmp_path)
    data = {**EMBEDDED, "step_min": 60, "fold_angles": {"start": 30, "stop": 180, "step": 30}}
    (tmp_path / "bad.yaml").write_text(yaml.safe_dump({**data, **changes}, sort_keys=False))
    result = runner.invoke(app, ["run", "bad.yaml", "--out", "out"])
    _assert_one_line(result, words, tmp_path)


#: Any value a storage field might be given: in range, beside it, of another type.
_VALUE = st.one_of(st.floats(-0.5, 1.5), st.sampled_from([0, 1, 1e7, float("nan"), "x", None, True]))


@settings(max_examples=200, deadline=None)
@given(section=st.fixed_dictionaries({"capacity_wh": st.one_of(st.floats(-1, 50), st.just("x"))},
                                     optional={name: _VALUE for name in (
                                         "min_soc", "restart_soc", "charge_efficiency",
                                         "discharge_efficiency", "self_discharge", "max_charge_w",
                                         "max_discharge_w", "initial_soc")}
                                     | {"preset": st.sampled_from([*PRESETS, "lead-acid", None])}))
def test_any_storage_section_validates_within_its_limits_or_names_its_fault(section):
    try:
        storage = _study(section).storage
    except foldopt.ConfigError as error:
        assert error.errors and all(line.startswith("storage") for line in error.errors), error.errors
        return
    assert 0 <= storage.capacity_wh <= 1e6
    assert 0 <= storage.min_soc <= storage.restart_soc <= 1 and storage.min_soc < 1
    assert 0 < storage.charge_efficiency <= 1 and 0 < storage.discharge_efficiency <= 1
    assert 0 <= storage.self_discharge < 1
    for given_value in ("max_charge_w", "max_discharge_w"):
        assert getattr(storage, given_value) is None or getattr(storage, given_value) > 0
    assert {name: getattr(storage, name) for name in section if section[name] is not None} == {
        name: value for name, value in section.items() if value is not None}


def test_a_capacity_list_is_a_sweep_axis_each_value_checked():
    from foldopt.inputs.plan import load_plan, make_plan
    from foldopt.inputs.policy import set_path

    data = set_path(set_path(load_plan(default_study_path()).data, "storage.capacity_wh", [0, 10, 20]),
                    "storage.preset", "lifepo4")
    assert make_plan(data).axes == (("storage.capacity_wh", (0, 10, 20)),)
    with pytest.raises(foldopt.ConfigError, match=r"storage.capacity_wh\[1\] = -10: must be in"):
        make_plan(set_path(data, "storage.capacity_wh", [0, -10]))


# ---- the section's values: presets, the ideal buffer, what the study's data keep ----------------

def test_without_a_preset_a_left_out_field_is_the_ideal_buffers():
    storage = _study({"capacity_wh": 12.5}).storage
    assert storage.capacity_wh == 12.5 and storage.preset is None
    assert (storage.min_soc, storage.restart_soc) == (0.0, 0.0)
    assert (storage.charge_efficiency, storage.discharge_efficiency) == (1.0, 1.0)
    assert storage.self_discharge == 0.0
    assert (storage.max_charge_w, storage.max_discharge_w, storage.initial_soc) == (None, None, None)
    hysteresis = _study({"capacity_wh": 5, "min_soc": 0.4}).storage
    assert hysteresis.restart_soc == 0.4  # no hysteresis unless a preset or the user gives one


@pytest.mark.parametrize("preset", list(PRESETS))
def test_a_preset_fills_only_the_fields_left_out(preset):
    values = PRESETS[preset]
    filled = _study({"capacity_wh": 20, "preset": preset}).storage
    assert filled.min_soc == values["min_soc"]
    assert filled.restart_soc == pytest.approx(values["min_soc"] + values["hysteresis"], abs=1e-12)
    assert (filled.charge_efficiency, filled.discharge_efficiency, filled.self_discharge) == (
        values["charge_efficiency"], values["discharge_efficiency"], values["self_discharge"])
    given = {"capacity_wh": 20, "preset": preset, "min_soc": 0.5, "discharge_efficiency": 0.8,
             "max_charge_w": 3.0, "initial_soc": 0.1}
    mixed = _study(given).storage
    assert (mixed.min_soc, mixed.discharge_efficiency, mixed.max_charge_w) == (0.5, 0.8, 3.0)
    assert mixed.initial_soc == 0.1  # below the cut-off: allowed, the load starts off
    assert mixed.restart_soc == pytest.approx(0.5 + values["hysteresis"], abs=1e-12)  # from the given cut-off
    assert mixed.charge_efficiency == values["charge_efficiency"]
    assert mixed.self_discharge == values["self_discharge"]
    # The study's data keep what was given, not what the preset filled.
    assert _study(given).data()["storage"] == given


def test_a_variant_with_another_preset_fills_its_own():
    study = _study({"capacity_wh": 20, "preset": "lifepo4", "min_soc": 0.3})
    other = study.variant(storage={"preset": "supercapacitor"})
    assert other.storage.capacity_wh == 20 and other.storage.min_soc == 0.3  # given, kept
    assert other.storage.self_discharge == PRESETS["supercapacitor"]["self_discharge"]
    assert other.storage.restart_soc == pytest.approx(0.3 + PRESETS["supercapacitor"]["hysteresis"])
    assert other.variant(storage=None).data() == _study().data()


def test_every_preset_is_a_registry_member_within_the_fields_limits():
    assert set(PRESETS) == set(names.STORAGE_PRESETS) and names.STORAGE_PRESETS in names.REGISTRIES
    assert set(IDEAL) == set(next(iter(PRESETS.values())))
    for values in PRESETS.values():
        assert 0 <= values["min_soc"] < values["min_soc"] + values["hysteresis"] <= 1
        assert 0 < values["charge_efficiency"] * values["discharge_efficiency"] <= 1
        assert 0 <= values["self_discharge"] < 1
    # A supercapacitor used down to half its voltage keeps a quarter of its energy (E ~ V^2).
    assert PRESETS["supercapacitor"]["min_soc"] == pytest.approx(0.5**2)
    # LiFePO4's 3 %/month is the preset's daily fraction compounded over 30 days.
    assert 1 - (1 - PRESETS["lifepo4"]["self_discharge"]) ** 30 == pytest.approx(0.03, abs=1e-3)


# ---- a study without storage is the study it was; a study with it round-trips ----------------------

@pytest.mark.parametrize("name", ["shin2015", "annual", "camera-profile", "load-sweep", "optimize"])
def test_a_study_without_storage_keeps_its_data(name):
    path = ROOT / "configs" / f"{name}.yaml"
    loaded = foldopt.load_study(path)
    base = getattr(loaded, "base", loaded)  # a plan's study
    assert base.storage is None and "storage" not in base.data()
    assert make_study({**base.data(), "storage": None}).data() == base.data()


def test_a_study_with_storage_round_trips_through_yaml(tmp_path):
    study = _study({"capacity_wh": 30, "preset": "supercapacitor", "max_discharge_w": 4})
    path = tmp_path / "buffer.yaml"
    path.write_text(yaml.safe_dump(study.data(), sort_keys=False))
    again = foldopt.load_study(path)
    assert again.data() == study.data()
    assert again.storage == study.storage and again.storage.decided == study.storage.decided


# ---- the command line: --storage-wh, --min-soc and --set storage.... -----------------------------

def test_the_options_and_set_reach_the_study(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    args = ["sweep", "angle", "--storage-wh", "10", "--min-soc", "0.2", "--set",
            "storage.restart_soc=0.5", "--set", "storage.preset=lifepo4", *QUICK, "--engine", "numpy",
            "--out", "out", "--quiet"]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    storage = json.loads((tmp_path / "out" / "run.json").read_text())["study"]["storage"]
    lifepo4 = PRESETS["lifepo4"]
    assert storage == {"capacity_wh": 10.0, "min_soc": 0.2, "restart_soc": 0.5, "preset": "lifepo4",
                       "charge_efficiency": lifepo4["charge_efficiency"],
                       "discharge_efficiency": lifepo4["discharge_efficiency"],
                       "self_discharge": lifepo4["self_discharge"], "max_charge_w": None,
                       "max_discharge_w": None, "initial_soc": None, "target": None,
                       "enclosure_offset_c": None, "cold": None,
                       "charge_min_c": lifepo4["charge_min_c"],
                       "discharge_min_c": lifepo4["discharge_min_c"],
                       "capacity_curve": [list(point) for point in lifepo4["capacity_curve"]],
                       "self_discharge_doubling_c": None}


# ---- PVGIS's hourconsumption: the watt profile it stands for --------------------------------------

def test_hourconsumption_is_the_watt_profile_it_stands_for():
    energy = 48.0  # [Wh] a day
    pvgis = _study(load_profile={"hourconsumption": SHARES, "consumptionday": energy}, p_load=None)
    # The reference: each hour's energy spread over its hour, written as the watts of a daily profile.
    watts = {f"{hour:02d}:00": energy * share for hour, share in enumerate(SHARES)}
    reference = _study(load_profile={"daily": watts}, p_load=None)
    assert pvgis.load_profile.daily == pytest.approx(reference.load_profile.daily, rel=1e-12)
    minutes = (np.arange(1440)[None, :] + 0.5) / 60.0
    day = [pvgis.date]
    shape = load_shape(pvgis.load_profile, minutes, day)
    np.testing.assert_allclose(shape, load_shape(reference.load_profile, minutes, day), rtol=1e-12)
    # By hand: minute m of hour h draws energy x share_h [W]; the day uses `energy` Wh.
    by_hand = np.repeat(np.array(SHARES) * energy, 60)[None, :]
    np.testing.assert_allclose(shape, by_hand, rtol=1e-12)
    assert shape.sum() / 60.0 == pytest.approx(energy, rel=1e-12)
    load = describe_load(pvgis)
    assert load["profile"] == "hourconsumption" and load["mean_w"] == pytest.approx(energy / 24)
    # Its data keep PVGIS's form, not the watts worked out from it.
    assert "daily" not in pvgis.data()["load_profile"]
    assert make_study(pvgis.data()).load_profile == pvgis.load_profile


def test_hourconsumption_rounded_shares_are_scaled_to_the_days_energy():
    rounded = [round(share, 2) for share in SHARES]  # 0.0275 -> 0.03: they sum to 1.01
    profile = _study(load_profile={"hourconsumption": rounded, "consumptionday": 24.0},
                     p_load=None).load_profile
    assert sum(profile.daily.values()) == pytest.approx(24.0, rel=1e-12)
