"""The state-of-charge simulation of a small buffer (foldopt.engine.storage, issue 41 item 2).

Each property is checked against a reference computed another way: metrics.t_solar for no
buffer, the energy balance for an unlimited one and for every one, a plain-Python loop over a
small case (with a tracker's draw too), and a two-day example worked by hand.
"""

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from foldopt.engine import storage
from foldopt.engine.metrics import per_load, t_solar
from foldopt.engine.storage import Buffer, simulate

ENGINES = storage.STORAGE_ENGINES
FEW = settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])


@st.composite
def curves(draw, max_series=3, max_days=3):
    """Power curves (n_series, n_days, n_steps) with dark stretches, and the step [h]."""
    shape = (
        draw(st.integers(1, max_series)),
        draw(st.integers(1, max_days)),
        draw(st.integers(3, 16)),
    )
    level = arrays(float, shape, elements=st.floats(0.0, 20.0))
    lit = arrays(bool, shape)
    return np.where(draw(lit), draw(level), 0.0), 24.0 / shape[2]


def own_draws(data, power):
    """A design's own draw (a tracker's standby and moves) for ``power``: none, or up to 3 W at
    some steps, at times above the power there, as behind a high horizon."""
    if not data.draw(st.booleans()):
        return None
    level = data.draw(arrays(float, power.shape, elements=st.floats(0.0, 3.0)))
    return np.where(data.draw(arrays(bool, power.shape)), level, 0.0)


def cold_steps_drawn(data, power):
    """A buffer's temperature's effects at each step (issue 50), every field drawn: charge and
    discharge blocked at some steps, a usable share and a leak factor, for every series or one
    per series."""
    shape = power.shape if data.draw(st.booleans()) else (1, *power.shape[1:])
    return storage.ColdSteps(
        data.draw(arrays(bool, shape)),
        data.draw(arrays(bool, shape)),
        data.draw(arrays(float, shape, elements=st.floats(0.05, 1.0))),
        data.draw(arrays(float, shape, elements=st.floats(0.0, 8.0))),
    )


@st.composite
def buffers(draw, capacity=None, hysteresis=True, leak=True):
    """A buffer with every option drawn (``capacity`` fixed where given)."""
    min_soc = draw(st.floats(0.0, 0.5))
    return Buffer(
        capacity_wh=draw(st.floats(0.0, 60.0)) if capacity is None else capacity,
        min_soc=min_soc,
        restart_soc=min_soc + (draw(st.floats(0.0, 0.4)) if hysteresis else 0.0),
        charge_efficiency=draw(st.floats(0.6, 1.0)),
        discharge_efficiency=draw(st.floats(0.6, 1.0)),
        self_discharge=draw(st.floats(0.0, 0.3)) if leak else 0.0,
        max_charge_w=draw(st.one_of(st.none(), st.floats(0.5, 10.0))),
        max_discharge_w=draw(st.one_of(st.none(), st.floats(0.5, 10.0))),
        initial_soc=draw(st.one_of(st.none(), st.floats(0.0, 1.0))),
    )


def balance(result):
    """served + drawn + lost + delta stored + losses - harvested, per series and day [Wh]."""
    return (
        result.served_wh
        + result.drawn_wh
        + result.lost_wh
        + np.diff(result.stored_wh, axis=1)
        + result.charge_loss_wh
        + result.discharge_loss_wh
        + result.self_discharge_wh
        - result.harvested_wh
    )


@FEW
@given(curves(), st.data())
def test_no_capacity_is_t_solar(curve, data):
    """With 0 Wh the load runs exactly while P_pv >= P_load (metrics.t_solar, the storage-less
    answer), whatever the controller's other settings; a tracker's net of its own draw, below
    zero where the draw is above the power, included."""
    power, step = curve
    loads = data.draw(arrays(float, power.shape[0], elements=st.floats(0.1, 15.0)))
    buffer = data.draw(buffers(capacity=0.0))
    draw = own_draws(data, power)
    expected = t_solar(power if draw is None else power - draw, loads[:, None], step)
    for engine in ENGINES:
        result = simulate(power, loads, buffer, step, engine=engine, draw=draw)
        np.testing.assert_allclose(result.powered_h, expected, rtol=0, atol=1e-12)
        assert not result.full.any()


@FEW
@given(curves(), st.data())
def test_no_capacity_with_a_profile_compares_the_difference(curve, data):
    """A load profile is compared by P - L, both linear between step centres: with 0 Wh the
    powered time is t_solar of the difference against 0, and the served energy that of the load
    over the parts above it (no buffer: never more than harvested)."""
    power, step = curve
    profile = data.draw(arrays(float, power.shape[::2], elements=st.floats(0.1, 15.0)))
    result = simulate(power, profile, Buffer(0.0), step, engine="numba")
    difference = power - profile[:, None, :]
    np.testing.assert_allclose(result.powered_h, t_solar(difference, 0.0, step), atol=1e-12)
    assert (result.served_wh <= result.harvested_wh + 1e-9).all()
    np.testing.assert_allclose(result.served_wh + result.lost_wh, result.harvested_wh, atol=1e-9)


@pytest.mark.parametrize("engine", ENGINES)
def test_a_load_window_counts_time_as_without_a_buffer(engine):
    """A profile that is zero outside 06:00-18:00 counts powered time as the storage-less
    t_solar of a profile does (metrics.per_load: the segments next to a step without load count
    nothing), with no buffer and with one that never runs out; the load's energy is all served."""
    hours = np.arange(24) + 0.5
    window = np.where((hours > 6) & (hours < 18), 4.0, 0.0)
    power = np.full((1, 24), 10.0)
    expected = float(t_solar(per_load(power[0], window), 1.0, 1.0))
    assert expected == pytest.approx(11.0)
    for capacity in (0.0, 100.0):
        result = simulate(power, window[None], Buffer(capacity), 1.0, engine=engine)
        np.testing.assert_allclose(result.powered_h, [[expected]], atol=1e-12)
        np.testing.assert_allclose(result.served_wh, [[48.0]])
        assert result.missing_wh[0, 0] == 0.0


@FEW
@given(curves(max_series=2, max_days=1), st.floats(0.2, 12.0))
@example(curve=(np.full((1, 1, 3), 5.0), 8.0), load=7.0)  # steep: bisected, no periodic state
def test_unlimited_lossless_buffer_meets_the_energy_balance(curve, load):
    """An unlimited lossless buffer in its periodic state runs the load for the share of the day
    the harvest can pay for: powered fraction = min(1, harvested / needed), to one step; where
    no state repeats exactly (passes < 0), the day ends within one step's load of its start."""
    power, step = curve
    needed = load * 24.0
    buffer = Buffer(capacity_wh=10 * needed)  # ten days: never full unless the harvest is ample
    result = simulate(power, load, buffer, step)
    harvested = power.sum(axis=-1) * step
    expected = 24.0 * np.minimum(1.0, harvested / needed)
    np.testing.assert_allclose(result.stored_wh[:, 1], result.stored_wh[:, 0], atol=load * step)
    np.testing.assert_allclose(result.powered_h, expected, rtol=0, atol=step + 1e-9)


@FEW
@given(curves(max_series=1), st.data())
def test_more_capacity_or_less_load_never_runs_less(curve, data):
    """Powered time never falls as the capacity grows or the load falls, to within one step.

    Holds for a controller without hysteresis (restart_soc = min_soc) and a buffer that does not
    leak, from an empty buffer or in the periodic state. The step: the load reconnects at a part's
    start, so a cut-off that falls elsewhere in a step can shift time by less than one. (With a
    hysteresis band, or a leaking floor, the band and the floor grow with the buffer, and a larger
    one can indeed run the load less: not asserted.)"""
    power, step = curve
    base = data.draw(buffers(hysteresis=False, leak=False))
    start = data.draw(st.sampled_from([None, base.min_soc]))
    capacities = np.sort(data.draw(arrays(float, 5, elements=st.floats(0.0, 80.0))))
    bigger = simulate(
        np.repeat(power, 5, axis=0),
        data.draw(st.floats(0.2, 12.0)),
        base._replace(capacity_wh=capacities, initial_soc=start),
        step,
    )
    hours = bigger.powered_h.sum(axis=1)
    assert (np.diff(hours) >= -step - 1e-9).all(), (capacities, hours)
    loads = np.sort(data.draw(arrays(float, 5, elements=st.floats(0.2, 12.0))))[::-1]
    lighter = simulate(np.repeat(power, 5, axis=0), loads, base._replace(initial_soc=start), step)
    hours = lighter.powered_h.sum(axis=1)
    assert (np.diff(hours) >= -step - 1e-9).all(), (loads, hours)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(curves(), st.data())
def test_energy_is_conserved(curve, data):
    """served + drawn + lost + delta stored + conversion losses + self-discharge = harvested,
    each day, with a design's own draw or without; the draw served is never more than asked."""
    power, step = curve
    loads = data.draw(arrays(float, power.shape[0], elements=st.floats(0.0, 15.0)))
    buffer = data.draw(buffers())
    draw = own_draws(data, power)
    for engine in ENGINES:
        result = simulate(power, loads, buffer, step, engine=engine, draw=draw)
        np.testing.assert_allclose(balance(result), 0.0, atol=1e-9 * (1 + power.sum()))
        asked = 0.0 if draw is None else draw.sum(axis=-1) * step
        # Before the design's own draw (added back to the power it leaves: rounding only).
        np.testing.assert_allclose(
            result.harvested_wh, power.sum(axis=-1) * step, atol=1e-12 * (1 + np.sum(asked))
        )
        assert (result.drawn_wh <= asked + 1e-9).all()
        needed = np.broadcast_to(loads[:, None] * 24.0, result.served_wh.shape)
        np.testing.assert_allclose(result.served_wh + result.missing_wh, needed, atol=1e-9)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(curves(), st.data())
def test_compiled_loop_equals_the_numpy_reference(curve, data):
    """The numba loop and the NumPy reference agree on every output, for constant loads and
    profiles, buffers drawn with every option, one buffer per series, a design's own draw and a
    buffer's temperature."""
    power, step = curve
    n_series, n_days, n_steps = power.shape
    load_shape = data.draw(st.sampled_from([(), (n_series,), (1, n_steps), (n_series, n_days, 1)]))
    load = data.draw(arrays(float, load_shape, elements=st.floats(0.0, 15.0)))
    buffer = data.draw(buffers())
    if data.draw(st.booleans()):  # one capacity per series, as a sizing search runs them
        capacities = data.draw(arrays(float, n_series, elements=st.floats(0.0, 60.0)))
        buffer = buffer._replace(capacity_wh=capacities)
    draw = own_draws(data, power)
    cold = cold_steps_drawn(data, power) if data.draw(st.booleans()) else None
    compiled = simulate(
        power, load, buffer, step, engine="numba", soc_curves=True, draw=draw, cold=cold
    )
    reference = simulate(
        power, load, buffer, step, engine="numpy", soc_curves=True, draw=draw, cold=cold
    )
    for name in storage.StorageResult._fields:
        np.testing.assert_array_equal(getattr(compiled, name), getattr(reference, name), name)
        assert np.isfinite(getattr(compiled, name)).all(), name


@pytest.mark.parametrize("engine", ENGINES)
def test_one_curve_serves_many_capacities(engine):
    """One power curve against several capacities (a sizing search) is the same as the curve
    repeated once per capacity."""
    power = np.where(np.arange(24) % 24 < 12, 8.0, 0.0)[None, None, :].repeat(3, axis=1)
    buffer = Buffer(capacity_wh=np.array([0.0, 5.0, 20.0, 80.0]), min_soc=0.1, restart_soc=0.3)
    shared = simulate(power, 3.0, buffer, 1.0, engine=engine)
    repeated = simulate(np.repeat(power, 4, axis=0), 3.0, buffer, 1.0, engine=engine)
    assert shared.powered_h.shape == (4, 3)
    for name in storage.StorageResult._fields:
        np.testing.assert_array_equal(getattr(shared, name), getattr(repeated, name), name)


def loop(
    power, load, step, capacity, min_soc, restart, eta_c, eta_d, leak, max_c, max_d, e, own=None
):
    """The model as the module docstring states it, written plainly for one series from a content
    ``e`` [Wh]: segments between step centres, split where the power less the design's own draw
    ``own`` (per step, like ``power``) crosses the (constant) load, integrals and the instant the
    buffer runs out found numerically. Returns per day (powered h, served, missing, lost, own
    draw served Wh) and the content at the end."""
    fine = 4000  # sub-intervals of a part for the integrals
    own = np.zeros_like(power) if own is None else own

    def integral(f, a, b, p):
        t = a + (np.arange(fine) + 0.5) * (b - a) / fine
        return float(np.sum(f(p(t)))) * (b - a) / fine

    def linear(day, knots):
        # The curve at step centres, linear between them and held to midnight.
        values = np.concatenate([[day[0]], day, [day[-1]]])
        return lambda t: np.interp(t, knots, values)

    on = e >= restart * capacity
    days = []
    for day, day_own in zip(power, own, strict=True):
        knots = np.concatenate([[0.0], (np.arange(day.size) + 0.5) * step, [day.size * step]])
        whole, drive = linear(day, knots), linear(day_own, knots)
        values = np.concatenate([[day[0]], day, [day[-1]]]) - np.concatenate(
            [[day_own[0]], day_own, [day_own[-1]]]
        )
        powered = served = missing = lost = drawn_own = 0.0
        for t0, t1, p0, p1 in zip(knots[:-1], knots[1:], values[:-1], values[1:], strict=True):

            def p(t, t0=t0, t1=t1, p0=p0, p1=p1):
                # What the design leaves for the load after its own draw.
                return p0 + (p1 - p0) * (t - t0) / (t1 - t0)

            cuts = [t0, t1]
            if (p0 - load) * (p1 - load) < 0:
                cuts.insert(1, t0 + (t1 - t0) * (load - p0) / (p1 - p0))
            for a, b in zip(cuts[:-1], cuts[1:], strict=False):
                if not on and e >= restart * capacity:
                    on = True
                above = p(0.5 * (a + b)) >= load
                if on and above:
                    served += load * (b - a)
                    drawn_own += integral(lambda x: x, a, b, drive)
                    powered += b - a
                    spare = integral(lambda x: x - load, a, b, p)
                    take = min(integral(lambda x: np.minimum(x - load, max_c), a, b, p), spare)
                    take = min(take, (capacity - e) / eta_c)
                    e, lost = e + take * eta_c, lost + spare - take
                    continue
                if on:
                    usable = e - min_soc * capacity
                    peak = max(load - p(a), load - p(b))
                    if usable > 0 and peak <= max_d:
                        deficit = integral(lambda x: load - x, a, b, p)
                        if deficit <= eta_d * usable:
                            e -= deficit / eta_d
                            served += load * (b - a)
                            drawn_own += integral(lambda x: x, a, b, drive)
                            powered += b - a
                            continue
                        lo, hi = a, b  # the instant the buffer reaches its cut-off
                        for _ in range(60):
                            mid = 0.5 * (lo + hi)
                            drawn = integral(lambda x: load - x, a, mid, p)
                            lo, hi = (mid, hi) if drawn < eta_d * usable else (lo, mid)
                        served += load * (lo - a)
                        drawn_own += integral(lambda x: x, a, lo, drive)
                        powered += lo - a
                        e, a = min_soc * capacity, lo
                    on = False
                # Off: the load and the design's own draw; its whole power charges.
                missing += load * (b - a)
                offered = integral(lambda x: np.maximum(x, 0.0), a, b, whole)
                take = min(integral(lambda x: np.clip(x, 0.0, max_c), a, b, whole), offered)
                take = min(take, (capacity - e) / eta_c)
                e, lost = e + take * eta_c, lost + offered - take
            e *= (1 - leak) ** ((t1 - t0) / 24)
        days.append((powered, served, missing, lost, drawn_own))
    return np.array(days), e


@pytest.mark.parametrize("engine", ENGINES)
def test_plain_python_loop(engine):
    """A small case with every option on (hysteresis, losses, leak, both power limits), two
    days from a given state, against the plain loop above."""
    rng = np.random.default_rng(7)
    power = np.where(rng.random((2, 12)) < 0.7, rng.uniform(0.0, 12.0, (2, 12)), 0.0)
    options = dict(
        capacity=15.0, min_soc=0.1, restart=0.35, eta_c=0.9, eta_d=0.85, leak=0.2, max_c=4.0
    )
    buffer = Buffer(
        capacity_wh=15.0,
        min_soc=0.1,
        restart_soc=0.35,
        charge_efficiency=0.9,
        discharge_efficiency=0.85,
        self_discharge=0.2,
        max_charge_w=4.0,
        max_discharge_w=3.2,
        initial_soc=0.3,
    )
    # A tracker's drive: a standby of 0.8 W where there is light and moves at some steps, above
    # the power at some of them (the drive's deficit then runs from the buffer, or is off).
    own = np.where(power > 0, 0.3, 0.0) + np.where(rng.random((2, 12)) < 0.3, 1.5, 0.0)
    for draw in (None, own):
        days_of = None if draw is None else draw[None]
        result = simulate(power[None], 3.0, buffer, 2.0, engine=engine, draw=days_of)
        days, end = loop(power, 3.0, 2.0, **options, max_d=3.2, e=0.3 * 15.0, own=draw)
        if draw is None:  # the case reaches both ends of the buffer
            assert result.empty.any() and result.full.any()
        got = np.stack(
            [
                result.powered_h,
                result.served_wh,
                result.missing_wh,
                result.lost_wh,
                result.drawn_wh,
            ],
            -1,
        )
        np.testing.assert_allclose(got[0], days, rtol=0, atol=1e-5)
        np.testing.assert_allclose(result.stored_wh[0, -1], end, atol=1e-5)
    assert days[:, 4].sum() > 0 and (own.sum(axis=1) * 2.0 > days[:, 4]).any()


# The hand-checked example: 4 steps a day (6 h), centres at 3, 9, 15 and 21 h, power samples 0,
# 10, 10 and 0 W, linear between centres and held to midnight; a 4 W load (96 Wh a day).
# The power crosses 4 W at 5.4 h (rising 0 -> 10 W from 3 to 9 h) and at 18.6 h.
# No buffer: t_solar = 3.6 + 6 + 3.6 = 13.2 h. Harvest = (0 + 10 + 10 + 0) x 6 = 120 Wh.
# Surplus above 4 W: 5.4-9 h 0.5 x 3.6 x 6 = 10.8 Wh; 9-15 h 6 x 6 = 36 Wh; 15-18.6 h 10.8 Wh.
# Deficit: 0-3 h 12 Wh; 3-5.4 h 0.5 x 2.4 x 4 = 4.8 Wh; 18.6-21 h 4.8 Wh; 21-24 h 12 Wh.
# A 20 Wh lossless buffer, cut-off 0, no hysteresis, empty at the first midnight:
# Day 1. 0-3 h: nothing stored, the load is off (missing 12 Wh). 3-5.4 h: still nothing to draw,
#   off (missing 9.6 Wh); the PV (0.5 x 2.4 x 4 = 4.8 Wh) charges: 4.8 Wh. 5.4-9 h: on, served
#   14.4 Wh, +10.8 Wh: 15.6 Wh. 9-15 h: served 24 Wh, +4.4 Wh fills the buffer, 31.6 Wh lost.
#   15-18.6 h: served 14.4 Wh, 10.8 Wh lost. 18.6-21 h: 4.8 Wh drawn: 15.2 Wh. 21-24 h: 12 Wh
#   drawn: 3.2 Wh. Powered 3.6 + 6 + 3.6 + 2.4 + 3 = 18.6 h; served 74.4, missing 21.6, lost
#   42.4 Wh; 74.4 + 42.4 + 3.2 (stored) = 120 Wh harvested.
# Day 2 from 3.2 Wh: 0-3 h: the 4 W load runs 0.8 h on 3.2 Wh, then off (missing 8.8 Wh);
#   3-5.4 h as day 1 (off, missing 9.6, charged to 4.8 Wh); from 5.4 h as day 1. Powered
#   0.8 + 18.6 = 19.4 h; served 3.2 + 74.4 = 77.6, missing 18.4, lost 42.4 Wh; ends at 3.2 Wh:
#   day 2 is the periodic state of the repeated day.
# A dark day 3 (no power at all) from 3.2 Wh: the load runs 0.8 h and is off the rest of the day:
#   served 3.2, missing 92.8, lost 0 Wh; the buffer is never full. A sunny day 4 from 0 Wh is day 1
#   again. PVGIS's percentages of these four days: full 3/4 (days 1, 2, 4), empty 4/4.
# With restart_soc 0.5 (10 Wh) on day 1: at 5.4 h only 4.8 Wh are stored, so the load stays off
#   from 5.4 to 9 h too (missing 14.4 Wh more) while all the PV, 0.5 x 3.6 x (4 + 10) = 25.2 Wh,
#   charges: 15.2 Wh fill the buffer, 10 Wh lost; from 9 h on as before: powered 15 h.
HAND_POWER = np.array([[0.0, 10.0, 10.0, 0.0]] * 2)


@pytest.mark.parametrize("engine", ENGINES)
def test_two_days_by_hand(engine):
    """The example above, day by day, and the periodic state of its repeated day."""
    assert t_solar(HAND_POWER[0], 4.0, 6.0) == pytest.approx(13.2)
    empty = simulate(HAND_POWER[None], 4.0, Buffer(20.0, initial_soc=0.0), 6.0, engine=engine)
    np.testing.assert_allclose(empty.powered_h[0], [18.6, 19.4])
    np.testing.assert_allclose(empty.served_wh[0], [74.4, 77.6])
    np.testing.assert_allclose(empty.missing_wh[0], [21.6, 18.4])
    np.testing.assert_allclose(empty.lost_wh[0], [42.4, 42.4])
    np.testing.assert_allclose(empty.harvested_wh[0], [120.0, 120.0])
    np.testing.assert_allclose(empty.stored_wh[0], [0.0, 3.2, 3.2], atol=1e-12)
    assert empty.full[0].all() and empty.empty[0].all()
    four = np.concatenate([HAND_POWER, np.zeros((1, 4)), HAND_POWER[:1]])
    days = simulate(four[None], 4.0, Buffer(20.0, initial_soc=0.0), 6.0, engine=engine)
    np.testing.assert_allclose(days.powered_h[0], [18.6, 19.4, 0.8, 18.6])
    np.testing.assert_allclose(days.missing_wh[0], [21.6, 18.4, 92.8, 21.6])
    np.testing.assert_allclose(days.lost_wh[0], [42.4, 42.4, 0.0, 42.4], atol=1e-12)
    assert days.full[0].tolist() == [True, True, False, True] and days.empty[0].all()
    summary = days.summary()
    assert summary["days_full_pct"][0] == 75.0 and summary["days_empty_pct"][0] == 100.0
    assert summary["days_without_outage_pct"][0] == 0.0
    served = 74.4 + 77.6 + 3.2 + 74.4
    np.testing.assert_allclose(summary["availability_pct"], [100 * served / (4 * 96)])
    np.testing.assert_allclose(summary["powered_h"], [(18.6 + 19.4 + 0.8 + 18.6) / 4])
    np.testing.assert_allclose(summary["missing_wh"], [(21.6 + 18.4 + 92.8 + 21.6) / 4])
    np.testing.assert_allclose(summary["soc_pct"].sum(axis=1), [100.0])
    periodic = simulate(HAND_POWER[:1], 4.0, Buffer(20.0), 6.0, engine=engine)
    np.testing.assert_allclose(periodic.powered_h, [[19.4]])
    np.testing.assert_allclose(periodic.stored_wh, [[3.2, 3.2]])
    assert periodic.converged.all()
    band = Buffer(20.0, restart_soc=0.5, initial_soc=0.0)
    late = simulate(HAND_POWER[None, :1], 4.0, band, 6.0, engine=engine)
    np.testing.assert_allclose(late.powered_h, [[15.0]])
    np.testing.assert_allclose(late.missing_wh, [[21.6 + 14.4]])
    np.testing.assert_allclose(late.lost_wh, [[10.0 + 31.6 + 10.8 + 4.4]])


def test_state_of_charge_kept_where_asked():
    """The state of charge at every step only with soc_curves; its histogram covers the day."""
    power = HAND_POWER[None]
    plain = simulate(power, 4.0, Buffer(20.0, initial_soc=0.0), 6.0)
    assert plain.soc is None
    kept = simulate(power, 4.0, Buffer(20.0, initial_soc=0.0), 6.0, soc_curves=True)
    # Day 1 at the step centres 3, 9, 15 and 21 h (the example above): 0, 15.6 Wh, full, 15.2 Wh.
    np.testing.assert_allclose(kept.soc[0, 0], [0.0, 15.6 / 20, 1.0, 15.2 / 20])
    np.testing.assert_allclose(kept.soc_hours.sum(axis=-1), 24.0)


@pytest.mark.parametrize("engine", ENGINES)
def test_a_vanishing_buffer_is_no_buffer(engine):
    """Capacities near the smallest floats: the state-of-charge bin stays in range (a bin taken
    as capacity / content once wrote outside the histogram) and a part the buffer carries for an
    instant stays an instant (the time to run out, from a deficit rate rounded just below zero
    at the crossing, once came out as the whole part: energy created)."""
    power = np.array([[[9.0, 1e-12, 9.0]], [[10.0, 0.0, 10.0]]])
    loads = np.array([2.79012896, 3.2797116289983625])
    for capacity in (5e-324, 4.848823108381772e-239, 5.9e-198):
        result = simulate(power, loads, Buffer(capacity), 8.0, engine=engine)
        np.testing.assert_allclose(result.powered_h, t_solar(power, loads[:, None], 8.0), atol=1e-9)
        np.testing.assert_allclose(balance(result), 0.0, atol=1e-9)


@pytest.mark.parametrize("engine", ENGINES)
def test_days_empty_are_days_at_the_cut_off(engine):
    """PVGIS's days empty: the buffer at its cut-off at some instant. A load above
    max_discharge_w is off all day with the buffer full (not empty); two dark days after a
    sunny one are both empty, the second at the cut-off from its first instant."""
    sunny_then_dark = np.concatenate([HAND_POWER[:1], np.zeros((2, 4))])
    full = Buffer(20.0, initial_soc=1.0)
    result = simulate(sunny_then_dark[None], 4.0, full, 6.0, engine=engine)
    assert result.empty[0].tolist() == [False, True, True]
    assert result.missing_wh[0, 2] == pytest.approx(96.0)
    limited = Buffer(20.0, max_discharge_w=3.0, initial_soc=1.0)
    result = simulate(np.zeros((1, 1, 4)), 4.0, limited, 6.0, engine=engine)
    assert not result.empty.any() and result.full.all() and result.powered_h[0, 0] == 0.0


def test_summary_without_demand_or_capacity_has_no_nan():
    """A load of 0 W demands nothing (availability 100 %), and a buffer of 0 Wh spends all its
    time in the lowest tenth: the summary holds no NaN."""
    result = simulate(HAND_POWER[None], 0.0, Buffer(0.0), 6.0)
    summary = result.summary()
    assert all(np.isfinite(value).all() for value in summary.values())
    assert summary["availability_pct"][0] == 100.0 and summary["soc_pct"][0, 0] == 100.0


@pytest.mark.parametrize(
    ("change", "field"),
    [
        ({"capacity_wh": -1.0}, "capacity_wh"),
        ({"min_soc": 1.5}, "min_soc"),
        ({"min_soc": 0.5, "restart_soc": 0.2}, "restart_soc"),
        ({"charge_efficiency": 0.0}, "charge_efficiency"),
        ({"self_discharge": 1.0}, "self_discharge"),
        ({"initial_soc": 2.0}, "initial_soc"),
        ({"capacity_wh": [[1.0, 2.0]]}, "capacity_wh"),
        ({"capacity_wh": [1.0, 2.0], "min_soc": [0.1, 0.2, 0.3]}, "same number of series"),
    ],
)
def test_bad_buffer_names_the_field(change, field):
    with pytest.raises(ValueError, match=field):
        simulate(HAND_POWER[None], 4.0, Buffer(20.0)._replace(**change), 6.0)


def test_unknown_engine_lists_the_engines():
    with pytest.raises(ValueError, match="numba, numpy"):
        simulate(HAND_POWER[None], 4.0, Buffer(20.0), 6.0, engine="fortran")


def test_power_below_zero_is_refused_a_design_s_own_draw_goes_in_draw():
    """A net curve's negative part had nowhere to come from while the load was off (energy
    created); a tracker's draw is a load of its own, and its net curve is refused."""
    net = HAND_POWER[None] - 1.0
    with pytest.raises(ValueError, match="0 or more .*draw"):
        simulate(net, 4.0, Buffer(20.0), 6.0)
    with pytest.raises(ValueError, match="draw must be finite and 0 or more"):
        simulate(HAND_POWER[None], 4.0, Buffer(20.0), 6.0, draw=-1.0)


@pytest.mark.parametrize("energy", [5e-324, 1e-310, 1e-300])
def test_a_buffer_next_to_nothing_runs_a_part_next_to_no_time(energy):
    """From a crossing (no deficit at the part's start) a buffer of a denormal energy ran the whole
    part (4 slope energy underflowed to 0 and the root was 2 energy / 0): found by
    tests/test_storage_answer.py's energy balance (capacity 5e-324 Wh at 65 N). The time is the
    root of slope t^2 = energy (slope 0.5 db / tau), written here with Python's decimals, and the
    energy balances with the smallest capacities as with none."""
    from decimal import Decimal, getcontext

    from foldopt.engine.storage_kernel import time_to_draw

    getcontext().prec = 50
    db, tau = 0.0177, 0.0725  # [W], [h]: a part leaving the load at sunrise
    exact = float((Decimal(energy) * Decimal(2) * Decimal(tau) / Decimal(db)).sqrt())
    for ran in (time_to_draw(0.0, db, tau, energy), storage._time_to_draw(0.0, db, tau, energy)):
        assert float(ran) == pytest.approx(exact, rel=1e-6)
    hours = (np.arange(288) + 0.5) / 12
    power = np.clip(0.5 * np.sin((hours - 6.0) / 12.0 * np.pi), 0.0, None)[None]
    load = float(power[0, 80])  # the power at a step centre: a part starts at a crossing
    for engine in ("numba", "numpy"):
        run = simulate(power, load, Buffer(capacity_wh=energy), 1 / 12, engine)
        went = (run.served_wh + run.lost_wh + np.diff(run.stored_wh, axis=1) + run.charge_loss_wh
                + run.discharge_loss_wh + run.self_discharge_wh)  # fmt: skip
        np.testing.assert_allclose(run.harvested_wh - went, 0.0, atol=1e-12)
        none = simulate(power, load, Buffer(capacity_wh=0.0), 1 / 12, engine)
        assert run.served_wh[0, 0] == pytest.approx(none.served_wh[0, 0], abs=1e-12)
