"""Cloud ensembles (foldopt.inputs.weather.ensemble): every member keeps the file's hourly means,
closes ghi = dni cos(zenith) + dhi, stays within its bounds and is dark at night; the same seed
gives the same bits; clear and overcast hours are smooth, broken-cloud hours are not, and the sky's
state carries over from one hour to the next."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from foldopt.inputs.weather.downscale import MAX_CLEARSKY_INDEX
from foldopt.inputs.weather.ensemble import (
    MAX_ENHANCEMENT,
    MIN_COS_ZENITH,
    OVERCAST_PERSISTENCE,
    _overcast,
    _overcast_hours,
    cloud_members,
)


def sky(n_days: int, spi: int, peak: float = 0.8):
    """A clear sky and cos(zenith) at the steps of days of 24 intervals: the sun up from 6 to 18 h,
    no clear light below MIN_COS_ZENITH (as a clear-sky model gives next to none there)."""
    hours = (np.arange(24 * spi) + 0.5) / spi
    cosz = np.tile(peak * np.sin(np.pi * (hours - 6.0) / 12.0), (n_days, 1))
    clear = np.where(cosz >= MIN_COS_ZENITH, 1050.0 * np.clip(cosz, 0.0, None) ** 1.2, 0.0)
    return clear, cosz


def hourly(clear, spi, index, diffuse_share):
    """File-like hourly GHI and DHI of given clear-sky indices and diffuse shares."""
    clear_mean = clear.reshape(clear.shape[0], 24, spi).mean(axis=-1)
    ghi = np.asarray(index, dtype=float) * clear_mean
    return ghi, np.asarray(diffuse_share, dtype=float) * ghi


def interval_means(values, spi):
    return values.reshape(*values.shape[:-1], -1, spi).mean(axis=-1)


def check_invariants(out, ghi, dhi, clear, cosz, spi):
    g, dni, d = out["ghi"], out["dni"], out["dhi"]
    assert g.dtype == np.float64 and g.shape[1:] == clear.shape
    np.testing.assert_allclose(dni * cosz + d, g, rtol=0, atol=1e-6)
    assert (dni >= 0).all() and (d >= 0).all() and (d <= g + 1e-12).all()
    assert (g[:, clear == 0] == 0).all() and (dni[:, cosz < MIN_COS_ZENITH] == 0).all()
    clear_mean = interval_means(clear, spi)
    lit = clear_mean > 0
    index = np.divide(ghi, clear_mean, out=np.zeros_like(ghi), where=lit)
    bound = np.repeat(np.minimum(MAX_ENHANCEMENT * np.maximum(1.0, index), MAX_CLEARSKY_INDEX), spi, axis=-1)
    assert (g <= bound * clear + 1e-9).all()
    for values, target in ((g, ghi), (d, dhi)):
        means = interval_means(values, spi)
        np.testing.assert_allclose(means[:, lit], np.broadcast_to(target, means.shape)[:, lit], rtol=1e-9, atol=1e-9)


def test_means_closure_bounds_and_night():
    spi = 60
    clear, cosz = sky(3, spi)
    rng = np.random.default_rng(5)
    ghi, dhi = hourly(clear, spi, rng.uniform(0.05, 1.15, (3, 24)), rng.uniform(0.1, 1.0, (3, 24)))
    out = cloud_members(ghi, dhi, clear, cosz, spi, 1.0, 4, seed=1)
    assert set(out) == {"ghi", "dni", "dhi"}
    check_invariants(out, ghi, dhi, clear, cosz, spi)


def test_same_seed_same_bits_and_members_independent_of_their_number():
    spi = 60
    clear, cosz = sky(2, spi)
    ghi, dhi = hourly(clear, spi, np.full((2, 24), 0.6), np.full((2, 24), 0.6))
    first = cloud_members(ghi, dhi, clear, cosz, spi, 1.0, 3, seed=42)
    again = cloud_members(ghi, dhi, clear, cosz, spi, 1.0, 3, seed=42)
    other = cloud_members(ghi, dhi, clear, cosz, spi, 1.0, 3, seed=43)
    more = cloud_members(ghi, dhi, clear, cosz, spi, 1.0, 5, seed=42)
    for key in first:
        assert np.array_equal(first[key], again[key])
        assert not np.array_equal(first[key], other[key])
        assert np.array_equal(first[key], more[key][:3])
    assert not np.array_equal(first["ghi"][0], first["ghi"][1])  # members differ


def _noon_index(index, share, members=20, seed=3):
    spi = 60
    clear, cosz = sky(1, spi)
    ghi, dhi = hourly(clear, spi, np.full((1, 24), index), np.full((1, 24), share))
    out = cloud_members(ghi, dhi, clear, cosz, spi, 1.0, members, seed)
    noon = slice(12 * spi, 13 * spi)
    return out["ghi"][:, 0, noon] / clear[0, noon], out


def test_clear_hour_is_near_clear_and_smooth():
    kc, _ = _noon_index(1.0, 0.15)
    assert np.abs(kc - 1.0).max() < 0.03 and kc.std(axis=1).max() < 0.01


def test_overcast_hour_is_smooth():
    kc, out = _noon_index(0.2, 1.0)
    assert np.abs(kc / 0.2 - 1.0).max() < 0.2 and (kc.std(axis=1) / 0.2).max() < 0.06
    assert (out["dni"] == 0).all()  # all diffuse: the sun never shows


def test_broken_hours_vary_more_than_clear_ones():
    broken, _ = _noon_index(0.6, 0.6)
    clear, _ = _noon_index(1.0, 0.15)
    assert np.median(broken.std(axis=1)) > 0.1 > 10 * np.median(clear.std(axis=1))
    assert broken.max() > 1.0 > 0.5 > broken.min()  # sun (cloud-enhanced) and shade


def test_state_carries_over_between_hours():
    """Across an hour boundary the sky keeps its state about as often as between two minutes
    inside an hour: the chain is not reset per hour (a reset would decorrelate it)."""
    spi = 60
    clear, cosz = sky(1, spi)
    ghi, dhi = hourly(clear, spi, np.full((1, 24), 0.6), np.full((1, 24), 0.6))
    g = cloud_members(ghi, dhi, clear, cosz, spi, 1.0, 300, 9)["ghi"][:, 0] / np.where(clear[0] > 0, clear[0], 1)
    sunny = g > 0.75

    def agreement(a, b):
        return np.corrcoef(sunny[:, a], sunny[:, b])[0, 1]

    across = np.mean([agreement(h * spi - 1, h * spi) for h in range(10, 15)])
    inside = np.mean([agreement(h * spi + 29, h * spi + 30) for h in range(10, 15)])
    assert across > 0.6 and abs(across - inside) < 0.2


def test_cloud_cover_sets_the_sunshine():
    spi = 60
    clear, cosz = sky(1, spi)
    ghi, dhi = hourly(clear, spi, np.full((1, 24), 0.9), np.full((1, 24), 0.2))
    cloudless = cloud_members(ghi, dhi, clear, cosz, spi, 1.0, 10, 4, cloud_cover=np.zeros((1, 24)))
    covered = cloud_members(ghi, dhi, clear, cosz, spi, 1.0, 10, 4, cloud_cover=np.full((1, 24), 0.5))
    noon = slice(12 * spi, 13 * spi)
    assert (cloudless["ghi"][:, 0, noon] / clear[0, noon]).std(axis=1).max() < 0.01
    assert np.median((covered["ghi"][:, 0, noon] / clear[0, noon]).std(axis=1)) > 0.1
    check_invariants(covered, ghi, dhi, clear, cosz, spi)


def test_bad_shapes_are_refused():
    clear, cosz = sky(1, 60)
    ghi, dhi = hourly(clear, 60, np.full((1, 24), 0.5), np.full((1, 24), 0.5))
    with pytest.raises(ValueError):
        cloud_members(ghi, dhi, clear[:, :-1], cosz[:, :-1], 60, 1.0, 2, 0)
    with pytest.raises(ValueError):
        cloud_members(ghi, dhi, clear, cosz, 60, 1.0, 0, 0)
    with pytest.raises(ValueError):
        cloud_members(ghi, dhi, clear, cosz, 60, 1.0, 2, 0, cloud_cover=np.zeros((1, 23)))


@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data(), spi=st.sampled_from([1, 4, 12, 60, 120]), n_days=st.integers(1, 2),
       peak=st.floats(0.05, 1.0), with_cover=st.booleans(), seed=st.integers(0, 2**32 - 1))
def test_invariants_over_random_hours(data, spi, n_days, peak, with_cover, seed):
    clear, cosz = sky(n_days, spi, peak)
    shape = (n_days, 24)
    floats = st.lists(st.floats(0.0, 1.3), min_size=24 * n_days, max_size=24 * n_days)
    index = np.array(data.draw(floats)).reshape(shape)
    share = np.clip(np.array(data.draw(floats)).reshape(shape), 0.0, 1.0)
    ghi, dhi = hourly(clear, spi, index, share)
    cover = None
    if with_cover:  # a fraction of the sky, missing (NaN) in some intervals
        cover = np.clip(np.array(data.draw(floats)).reshape(shape), 0.0, 1.0)
        cover[np.array(data.draw(st.lists(st.booleans(), min_size=cover.size, max_size=cover.size))).reshape(shape)] \
            = np.nan
    out = cloud_members(ghi, dhi, clear, cosz, spi, 60.0 / spi, 3, seed, cloud_cover=cover)
    check_invariants(out, ghi, dhi, clear, cosz, spi)


def test_overcast_hours_have_their_chance_and_persist():
    """Each lit interval is overcast in about its chance of the members, and an overcast interval
    is followed by another about as often as Bright et al.'s 8 oktas persist; a dark interval
    between two starts the draw afresh."""
    chance = np.tile([0.2, 0.4, 0.4, 0.4, 0.6, 0.4], 40)
    fresh = np.zeros(chance.size, dtype=bool)
    fresh[::6] = True
    rngs = [np.random.default_rng(child) for child in np.random.SeedSequence(3).spawn(2000)]
    covered = _overcast_hours(chance, fresh, rngs)
    assert np.abs(covered.mean(axis=0) - chance).max() < 0.05
    inside = ~fresh[1:]
    together = (covered[:, 1:] & covered[:, :-1])[:, inside].mean() / covered[:, :-1][:, inside].mean()
    assert together > OVERCAST_PERSISTENCE - 0.02
    across = (covered[:, 6::6] & covered[:, 5:-1:6]).mean() / covered[:, 5:-1:6].mean()
    assert abs(across - 0.2) < 0.05  # independent across a dark interval (the next one's chance)


def test_intermediate_hours_are_smooth_in_some_members_and_broken_in_others():
    spi = 60
    clear, cosz = sky(1, spi)
    ghi, dhi = hourly(clear, spi, np.full((1, 24), 0.4), np.full((1, 24), 0.7))
    out = cloud_members(ghi, dhi, clear, cosz, spi, 1.0, 100, 11)
    check_invariants(out, ghi, dhi, clear, cosz, spi)
    dni = out["dni"][:, 0].reshape(100, 24, spi)[:, 9:15]
    even = (dni > 0).all(axis=-1)  # overcast, or a broken hour whose clouds never part
    chance = _overcast(np.array([0.4]), np.array([50.0]))[0]
    assert 0.3 < chance < even.mean() < 0.95


def test_overcast_chance_falls_with_the_index_and_a_full_cover_is_overcast():
    index = np.linspace(0.1, 0.95, 18)
    chance = _overcast(index, np.full(index.shape, 30.0))
    assert chance[0] > 0.5 and chance[-1] < 0.02 and (np.diff(chance) < 0).all()
    spi = 60
    clear, cosz = sky(1, spi)
    ghi, dhi = hourly(clear, spi, np.full((1, 24), 0.6), np.full((1, 24), 0.5))
    out = cloud_members(ghi, dhi, clear, cosz, spi, 1.0, 10, 4, cloud_cover=np.ones((1, 24)))
    noon = slice(12 * spi, 13 * spi)
    dni = out["dni"][:, 0, noon]  # overcast: the beam even, as a hazy sun
    assert (dni > 0).all() and (dni.std(axis=1) < 0.1 * dni.mean(axis=1)).all()


def test_clear_hours_above_the_clear_sky_follow_a_curve_not_a_staircase():
    """Clear hours brighter than the clear-sky model (its error at a low sun) are not each held at
    their own index: the index runs on across the hours' edges."""
    spi = 60
    clear, cosz = sky(1, spi)
    index = np.clip(1.0 + 0.1 * np.abs(np.arange(24) - 12.0), None, 1.9)[None]
    ghi, dhi = hourly(clear, spi, index, np.full((1, 24), 0.12))
    out = cloud_members(ghi, dhi, clear, cosz, spi, 1.0, 3, 2)
    check_invariants(out, ghi, dhi, clear, cosz, spi)
    kc = out["ghi"][:, 0] / np.where(clear[0] > 0, clear[0], 1.0)
    edges = np.arange(8, 12) * spi
    assert np.abs(kc[:, edges] - kc[:, edges - 1]).max() < 0.03  # the hours' indices step by 0.1


def test_an_ensemble_whose_every_member_is_best_flat_recommends_flat(tmp_path):
    """Greensboro's TMY3 year as three cloud members, an 8 W load: the flat panel is every member's own
    best (their objectives at every fold angle, annual_fold_angles.csv, independently of the answer's
    choice); the answer recommends it, 180 deg, not the centre of the near-optimal range (it
    recommended 170 deg), its recommendation lies in that range, and no line claims a gain over flat
    for the flat panel; no warning reaches stderr."""
    import json
    from pathlib import Path

    import pandas as pd
    from typer.testing import CliRunner

    from foldopt.cli.app import app

    weather = Path(__file__).resolve().parent.parent / "configs" / "weather" / "723170TYA.CSV"
    out = tmp_path / "out"
    done = CliRunner().invoke(app, ["sweep", "angle", "--weather", str(weather), "--members", "3", "--days",
                                    "1:365:20", "--objective", "mean", "--step-min", "15", "--p-load", "8",
                                    "--angle-step", "10", "--format", "json", "--out", str(out)])
    assert done.exit_code == 0, done.output
    assert done.stderr == ""
    by_angle = pd.read_csv(out / "annual_fold_angles.csv")
    assert by_angle.loc[by_angle["fold_angle_deg"] == 180, "wins_pct"].tolist() == [100.0]
    answer = json.loads(done.stdout)["answer"]
    (near,) = answer["near_optimal"]
    assert near["fold_angle_deg"] == 180.0 == near["recommended_deg"]
    assert near["near_optimal_lo_deg"] < 180.0
    assert any("recommended 180 deg" in line for line in answer["lines"])
    assert not any("% over" in line for line in answer["lines"])
