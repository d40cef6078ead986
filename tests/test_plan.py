"""Study files with sweep axes: ranges, lists, dates, and every error at once with its line."""

import datetime as dt

import pytest

from foldopt.inputs.plan import load_plan, make_plan, parse_dates, parse_range
from foldopt.errors import ConfigError

BASE = {"name": "t", "site": {"latitude": 10, "longitude": 0}, "date": "2025-03-20",
        "panel": {"area": 0.1}, "p_load": 2.0}


def test_ranges_are_inclusive_and_reject_empty_or_bad_steps():
    assert parse_range("-60:60:30") == [-60, -30, 0, 30, 60]
    assert parse_range("1:2:0.4") == [1.0, 1.4, 1.8]
    for bad in ("5:1:1", "1:5:0", "1:5:-1", "a:b:c", "1:5"):
        with pytest.raises(ValueError):
            parse_range(bad)


def test_date_specs():
    assert parse_dates("equinoxes-solstices", 2025) == [dt.date(2025, 3, 20), dt.date(2025, 6, 21),
                                                        dt.date(2025, 9, 23), dt.date(2025, 12, 21)]
    assert len(parse_dates("year", 2024)) == 366
    assert parse_dates("1:365:91", 2025) == [dt.date(2025, 1, 1), dt.date(2025, 4, 2), dt.date(2025, 7, 2),
                                             dt.date(2025, 10, 1), dt.date(2025, 12, 31)]
    assert parse_dates("2025-01-30:2025-02-02:1", 2025)[-1] == dt.date(2025, 2, 2)
    assert parse_dates([dt.date(2025, 1, 1), "2025-02-01", 60], 2025)[2] == dt.date(2025, 3, 1)
    with pytest.raises(ValueError, match="outside 2025"):
        parse_dates([366], 2025)


def test_axes_from_lists_ranges_and_the_sweep_section():
    plan = make_plan({**BASE, "site": {"latitude": "-10:10:10", "longitude": 0}, "p_load": [1, 2],
                      "date": "equinoxes-solstices", "sweep": {"panel.tilt": [0, 45], "geometry": ["hinge"]}})
    assert dict(plan.axes)["site.latitude"] == (-10.0, 0.0, 10.0)
    assert plan.n_cases == 3 * 2 * 4 * 2 * 1
    cases = list(plan.cases())
    assert len(cases) == plan.n_cases
    assert {study.panel.tilt for _, study in cases} == {0.0, 45.0}
    # A list of sites is one axis of whole sites; time zones with a colon are not ranges.
    plan = make_plan({**BASE, "site": [{"latitude": 1, "longitude": 2, "timezone": "UTC-08:00"},
                                       {"name": "b", "latitude": -3, "longitude": 4}]})
    assert [s.site.name for _, s in plan.cases()] == [None, "b"]


def test_a_list_valued_field_holds_its_list_and_a_list_of_them_is_an_axis():
    # A horizon's points, a converter's curve and an objective's months are lists themselves: only a
    # list of such lists sweeps them (a list of horizon files too).
    canyon, ridge = [[0, 30], [180, 20]], [[90, 10], [270, 10]]
    curve = [[0.1, 0.9], [1.0, 0.95]]
    data = {**BASE, "mode": "exact", "pv_model": "single-diode", "date": "2025-03-18:2025-03-22:1",
            "site": {**BASE["site"], "horizon": canyon}, "objective": {"statistic": "mean", "months": [3]},
            "circuit": {"converter": {"model": "curve", "curve": curve}}}
    plan = make_plan(data)
    assert [path for path, _ in plan.axes] == ["date"]
    study = plan.study({"date": dt.date(2025, 3, 20)})
    assert study.site.horizon.points == [tuple(point) for point in canyon]
    assert study.objective.months == [3] and study.circuit.converter.curve == [tuple(p) for p in curve]
    plan = make_plan({**data, "site": {**BASE["site"], "horizon": [canyon, ridge]},
                      "objective": {"statistic": "mean", "months": [[3], [3, 4]]}})
    assert dict(plan.axes)["site.horizon"] == (canyon, ridge) and dict(plan.axes)["objective.months"] == ([3], [3, 4])
    with pytest.raises(ConfigError, match=r"site.horizon\[1\] = \[\[0, 95\]\]: point 1: elevation 95"):
        make_plan({**data, "site": {**BASE["site"], "horizon": [canyon, [[0, 95]]]}})


def test_all_errors_at_once_with_their_yaml_lines(tmp_path):
    path = tmp_path / "bad.yaml"
    path.write_text(
        "name: t\n"
        "site:\n"
        "  latitude: [10, 95]\n"
        "  longitude: 0\n"
        "date: 2025-03-20\n"
        "panel: {area: 0.1, colour: red}\n"
        "p_load: '5:1:1'\n"
        "sweep:\n"
        "  panel.tilt: [10, 120]\n"
    )
    with pytest.raises(ConfigError) as caught:
        load_plan(path)
    errors = caught.value.errors
    assert "p_load = '5:1:1': empty range: stop is below start (line 7)" in errors, errors
    # Range errors stop before validation; fix the range and the rest appear together.
    path.write_text(path.read_text().replace("'5:1:1'", "'1:5:1'"))
    with pytest.raises(ConfigError) as caught:
        load_plan(path)
    errors = caught.value.errors
    assert "site.latitude[1] = 95: must be in [-90, 90] deg (line 3)" in errors
    assert "panel.colour: unknown field (line 6)" in errors
    assert "sweep.panel.tilt[1] = 120: must be in [0, 90] deg (line 9)" in errors
    assert len(errors) == 3


def test_wrong_types_and_limits():
    with pytest.raises(ConfigError, match="site.latitude"):
        make_plan({**BASE, "site": {"latitude": "north", "longitude": 0}})
    with pytest.raises(ConfigError, match="year"):
        make_plan({**BASE, "year": 1800})
    with pytest.raises(ConfigError, match="sweep: expected a mapping"):
        make_plan({**BASE, "sweep": [1, 2]})
    with pytest.raises(ConfigError, match="empty list"):
        make_plan({**BASE, "p_load": []})
    with pytest.raises(ConfigError, match=r"= '-90:90:0.001': 180,001 values; at most 10,000 per axis"):
        make_plan({**BASE, "site": {"latitude": "-90:90:0.001", "longitude": 0}})
    with pytest.raises(ConfigError, match=r"sweep: 260,281 cases; the limit is 200,000 \(FOLDOPT_MAX_CASES"):
        make_plan({**BASE, "site": {"latitude": "-90:90:0.5", "longitude": "-180:180:0.5"}})
    with pytest.raises(ConfigError, match=r"110,492 site-days x 180 fold angles x 1,440 steps = 2.9e\+10 "
                                          r"evaluations; the limit is 2e\+10"):
        make_plan({**BASE, "site": {"latitude": "-60:60:0.1", "longitude": 0}, "date": "1:365:4",
                   "fold_angles": {"start": 1, "stop": 180, "step": 1}, "step_min": 1})


def test_a_study_is_resolved_when_it_is_made():
    """Every default that depends on other fields is decided when a study is validated, once (the
    engine resolved it again in 16 places); what was decided is no setting of the user's, so a
    variant at another latitude or in another mode decides its own, and a study whose weather file
    is unread is refused where it would run."""
    import foldopt
    from foldopt.studies.blocks import Blocks

    study = make_plan(BASE).base
    assert (study.panel.tilt, study.panel.azimuth, study.site.timezone) == (10.0, 180.0, "UTC+00:00")
    assert (study.geometry, study.temperature_model, study.sky) == ("hinge", "sapm", "ineichen")
    assert study.data() == make_plan(study.data()).base.data()
    assert not {"geometry", "temperature_model", "sky"} & set(study.data())
    assert {"tilt", "azimuth"}.isdisjoint(study.data()["panel"]) and "timezone" not in study.data()["site"]
    south = study.variant(site={"latitude": -33.9, "longitude": 151.2})
    assert (south.panel.tilt, south.panel.azimuth, south.site.timezone) == (33.9, 0.0, "UTC+10:00")
    paper = study.variant(mode="paper")
    assert (paper.geometry, paper.temperature_model, paper.sky) == ("azimuth-split", "fixed", "meinel")
    given = make_plan({**BASE, "panel": {"area": 0.1, "tilt": 5.0}, "sky": "meinel"}).base
    assert (given.data()["panel"]["tilt"], given.data()["sky"]) == (5.0, "meinel")  # given: kept
    assert given.variant(mode="paper").sky == "meinel" and given.variant(p_load=3.0).panel.tilt == 5.0
    unread = foldopt.Study(name="u", weather="configs/weather/723170TYA.CSV", date="2025-06-21", p_load=2.0,
                           panel={"area": 0.1}, step_min=60)
    assert unread.site is None and unread.panel.tilt is None
    with pytest.raises(ConfigError, match="weather: the file is not read yet"):
        Blocks.of_dates(unread, [unread.date])
