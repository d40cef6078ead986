"""A small buffer behind a charge controller: the state of charge step by step, and how long the
load runs with it (issue 41). Arrays in, arrays out: power curves, a load and a buffer in; each
day's powered time and energies, and the state of charge, out.

The model is that of a charge controller with a low-voltage disconnect, as in PVGIS's off-grid
calculator [1]_ and SAM's simple battery [2]_. The power curve is the one
:mod:`foldopt.engine.metrics` integrates: sampled at step centres, linear between them and held for
half a step at both ends of each day; a load profile is taken the same way. Each day is cut into
those ``n_steps + 1`` segments, and each segment at the instant where the power crosses the load
(where :func:`foldopt.engine.metrics.t_solar` cuts it) into a part with the power at or above the
load and a part below it. Per part, while the load is on:

- at or above the load, PV serves the load and the surplus charges the buffer through
  ``charge_efficiency``, at most ``max_charge_w`` at each instant and at most the room left; what
  does not fit is *lost*;
- below it, the buffer covers the deficit through ``discharge_efficiency`` from its content above
  ``min_soc``. When the content runs out part of the way, the load runs to that instant (found in
  closed form: the deficit is linear) and is off for the rest of the part; a deficit above
  ``max_discharge_w`` anywhere in the part turns the load off for the whole part. The energy of
  the load while it is off is *missing*.

Once off, the load stays off until the content reaches ``restart_soc`` (the controller's
hysteresis), which is checked at the start of each part; while it is off, all the PV charges the
buffer. Self-discharge takes ``(1 - self_discharge) ** (tau / 24)`` of the content at the end of
each segment of ``tau`` hours (``self_discharge`` a day).

A design's own draw (``draw``: a tracker's standby and drive) is a load on the controller's
output beside the device's: the power the design leaves after it is what is compared with the
load (where :func:`foldopt.engine.metrics.t_solar` compares a tracker's net curve), the buffer
covers its deficit with the load's, and the controller cuts it off and reconnects it with the
load; while they are off, the design's whole power charges the buffer. (A tracker whose drive is
off holds still; the power it would then lose is not modelled.)

The buffer's temperature (``cold``, :class:`ColdSteps`: its effects at each step) acts per
segment at the segment's coldest end, the temperature being linear between step centres as the
power is (a charger blocked at some instant of a segment is taken as blocked over all of it): the
buffer charges over a segment only where it may at both its ends, and so discharges; the share of
the usable range the cold puts out of reach is the larger of the two ends', and raises the cut-off
and the reconnection (:func:`foldopt.physics.buffer_temperature.cold_cut_off`: the energy is still
stored, out of reach until warm); the self-discharge's factor is the mean of the two ends'. A
blocked charge loses the surplus (*lost*, as over a full buffer; with the load off, all the power);
a blocked discharge turns the load off where PV alone does not carry it, as ``max_discharge_w``
does. A load cut off waits for ``restart_soc`` as ever: below it, with the charger blocked, it
stays off even where PV alone would carry it, until the buffer may charge. Without ``cold``
(or with effects that change nothing) every answer is the same to the bit.

Conventions that follow from it:

- With ``capacity_wh = 0`` the load runs exactly in the parts at or above the load: the powered
  time of a constant load is :func:`foldopt.engine.metrics.t_solar` of the same curve, segment for
  segment (the sums may differ in the last bit). A load profile is compared by the difference
  ``P - L`` of the two linear curves, where :func:`foldopt.engine.metrics.per_load` compares the
  ratio ``P / shape`` with a scale: the two agree at step centres and wherever the profile is
  constant over a segment, and differ inside segments over which it changes.
- Powered time counts only segments with load at both ends, as
  :func:`foldopt.engine.metrics.per_load` counts them: a profile that is zero outside a window
  counts no time outside it and loses half a step at each edge, with or without a buffer (the
  energy of the load over those edge segments is served or missing all the same).
- The load reconnects only at a part's start (at most a step apart), so a cut-off late in a part
  keeps it off to the part's end.
- Energy is conserved, each day of every series, to the sums' rounding: ``harvested = served +
  drawn + lost + delta stored + conversion losses + self-discharge``, ``drawn`` the design's own
  draw served. Power is never below zero: a design's own draw is ``draw``, not a curve's
  negative part (which a controller with its load off would have nowhere to take from).
- Days *full* and *empty* are PVGIS's [1]_: days on which the buffer was full at some instant
  (never with no capacity), and days on which it was down to its cut-off at some instant (at
  midnight, or when it ran out under the load; with no capacity, every day).
- A colder series does not power more, to within one step, where the cold blocks the charge
  only, for a controller without hysteresis and a buffer that does not leak, from an empty
  buffer: less is stored at every instant. Where it blocks the discharge or raises the cut-off it
  can: the energy kept for a later, warmer step runs the load longer then (a colder night can
  power the next evening more); so can a leak that slows in the cold, and a periodic state the
  cold makes another.
- Powered time does not fall as the capacity grows, or as the load falls, to within one step,
  for a controller without hysteresis (``restart_soc = min_soc``) and a buffer that does not leak
  (``tests/test_storage_engine.py``). With a hysteresis band or a leak it can: the band
  ``(restart_soc - min_soc) x capacity`` that must be recharged before the load reconnects, and
  the floor ``min_soc x capacity`` that leaks and is refilled, grow with the buffer.

Initial state: ``initial_soc``, or by default the periodic steady state: the series is run from a
full buffer, then from the state it ended in, until the state at its end is that at its start (the
content within ``tolerance`` x the capacity, the load on or off alike). After
:data:`~foldopt.engine.storage_records.PLAIN_ITERATIONS` passes the start is bisected between the
contents that ended higher and lower, until the start is known to the tolerance. If the end
still differs by more, it jumps over the start there (a cut-off or a reconnection a part earlier
or later, or an end that moves much faster than the start): the state is periodic to the model's
resolution if the jump is within one step's load energy (the largest load x ``step_hours``), and
the series is flagged otherwise (``passes`` < 0), as it is after ``max_iterations`` passes; the
last pass is kept. One clear-sky day is thus repeated until its midnight state repeats; a weather year
starts from the state at its own end. A pass stops early at the first midnight whose state the
previous pass had too (from there on the two are the same), so that a year whose buffer fills or
empties at some point costs little more than one pass.

References
----------
.. [1] European Commission JRC, PVGIS, "Off-grid PV systems" (tool SHScalc): outputs f_f
   (percentage of days with the battery fully charged), f_e (percentage of days it became fully
   discharged), E_lost (energy not captured because the battery was full), E_miss (energy
   missing), and a histogram of the battery's charge state.
.. [2] NREL System Advisor Model, "Battery storage: simple battery model" (capacity, minimum state
   of charge, charge and discharge efficiencies and power limits).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from foldopt.engine import storage_records as layout

#: The engines :func:`simulate` runs on.
STORAGE_ENGINES = ("numba", "numpy")
#: State-of-charge bins of the histogram, as PVGIS reports it (0-10 %, ..., 90-100 %).
SOC_BINS = 10


class Buffer(NamedTuple):
    """A buffer and its charge controller. Every field is a float, or an array with one value per
    series (several capacities evaluated at once, as a sizing search does).

    Attributes
    ----------
    capacity_wh : float
        Capacity [Wh], 0 or more (0: no buffer); the controller draws it down to ``min_soc``.
    min_soc : float, default 0
        The controller's cut-off: the buffer is not drawn below it [-, 0..1].
    restart_soc : float, optional
        The state of charge at which the controller reconnects the load [-, ``min_soc``..1];
        default ``min_soc`` (no hysteresis).
    charge_efficiency, discharge_efficiency : float, default 1
        Bus to buffer, buffer to bus [-, 0 excluded..1].
    self_discharge : float, default 0
        Fraction of the content lost a day [-, 0..1 excluded].
    max_charge_w, max_discharge_w : float, optional
        Power into the buffer (at the bus, before the charge efficiency) and out of it (at the
        bus) [W]; default unlimited.
    initial_soc : float, optional
        State of charge at the start of the series [-, 0..1]; default the periodic steady state.
    """

    capacity_wh: float
    min_soc: float = 0.0
    restart_soc: float | None = None
    charge_efficiency: float = 1.0
    discharge_efficiency: float = 1.0
    self_discharge: float = 0.0
    max_charge_w: float | None = None
    max_discharge_w: float | None = None
    initial_soc: float | None = None


class ColdSteps(NamedTuple):
    """What the buffer's temperature does at each step
    (:mod:`foldopt.physics.buffer_temperature` makes them from a chemistry's data). Each field an
    array broadcastable to (n_series or 1, n_days, n_steps) (a size 1 serves every series, day or
    step).

    Attributes
    ----------
    charge, discharge : array_like of bool
        Where the buffer may charge / discharge.
    capacity : array_like of float
        The usable share of the capacity [-] in (0, 1].
    leak : array_like of float
        The self-discharge as a multiple of ``Buffer.self_discharge`` [-], 0 or more.
    """

    charge: np.ndarray
    discharge: np.ndarray
    capacity: np.ndarray
    leak: np.ndarray


class StorageResult(NamedTuple):
    """Each series' days with a buffer. Energies in Wh a day, times in hours a day.

    Attributes
    ----------
    powered_h : (n_series, n_days) float
        Hours the load runs, from PV or from the buffer.
    served_wh, missing_wh : (n_series, n_days) float
        Load energy served, and not served while the load was off.
    lost_wh : (n_series, n_days) float
        PV energy neither served nor taken into the buffer (full, or over ``max_charge_w``).
    harvested_wh : (n_series, n_days) float
        The curve's energy (:func:`foldopt.engine.metrics.energy`, summed in step order), before
        the design's own draw.
    charge_loss_wh, discharge_loss_wh, self_discharge_wh : (n_series, n_days) float
        Conversion losses into and out of the buffer, and its leak.
    drawn_wh : (n_series, n_days) float
        The design's own draw served (a tracker's drive; 0 without one).
    full, empty : (n_series, n_days) bool
        PVGIS's days full and empty (module docstring).
    soc_hours : (n_series, n_days, SOC_BINS) float
        Hours a day the state of charge spends in each tenth (0-10 %, ..., 90-100 %, a full buffer
        in the last): the state at the end of each segment, for the segment's length. With no
        capacity, all in the first.
    stored_wh : (n_series, n_days + 1) float
        Content at each midnight, from the start of the first day to the end of the last (their
        difference is a day's delta stored).
    soc : (n_series, n_days, n_steps) float or None
        State of charge at every step centre, where asked (``soc_curves``).
    passes : (n_series,) int
        Passes over the series run; negative where no periodic state was found (module
        docstring), 1 with an ``initial_soc``.
    """

    powered_h: np.ndarray
    served_wh: np.ndarray
    missing_wh: np.ndarray
    lost_wh: np.ndarray
    harvested_wh: np.ndarray
    charge_loss_wh: np.ndarray
    discharge_loss_wh: np.ndarray
    self_discharge_wh: np.ndarray
    drawn_wh: np.ndarray
    full: np.ndarray
    empty: np.ndarray
    soc_hours: np.ndarray
    stored_wh: np.ndarray
    soc: np.ndarray | None
    passes: np.ndarray

    @property
    def converged(self) -> np.ndarray:
        """(n_series,) bool: the series started from its ``initial_soc`` or its periodic state."""
        return self.passes > 0

    def summary(self) -> dict:
        """Each series over its days, as PVGIS's off-grid tool reports a year [1]_.

        Returns
        -------
        dict of numpy.ndarray
            (n_series,) each: ``powered_h`` (mean hours a day), ``availability_pct`` (load
            energy served, % of demanded; 100 without demand), ``days_without_outage_pct`` (days
            with no energy missing: powered whenever the load demanded power),
            ``missing_wh`` and ``lost_wh`` (means a day), ``days_full_pct`` and
            ``days_empty_pct``; and ``soc_pct`` (n_series, SOC_BINS), the share of the time in
            each tenth of the state of charge. No NaN.
        """
        demanded = (self.served_wh + self.missing_wh).sum(axis=1)
        served = self.served_wh.sum(axis=1)
        availability = np.divide(
            100.0 * served, demanded, out=np.full(served.shape, 100.0), where=demanded > 0
        )
        hours = self.soc_hours.sum(axis=1)
        return {
            "powered_h": self.powered_h.mean(axis=1),
            "availability_pct": availability,
            "days_without_outage_pct": 100.0 * (self.missing_wh <= 0.0).mean(axis=1),
            "missing_wh": self.missing_wh.mean(axis=1),
            "lost_wh": self.lost_wh.mean(axis=1),
            "days_full_pct": 100.0 * self.full.mean(axis=1),
            "days_empty_pct": 100.0 * self.empty.mean(axis=1),
            "soc_pct": 100.0 * hours / hours.sum(axis=1, keepdims=True),
        }


def simulate(
    power,
    load,
    buffer: Buffer,
    step_hours: float,
    engine: str = "numba",
    *,
    soc_curves: bool = False,
    max_iterations: int = 30,
    tolerance: float = 1e-6,
    draw=None,
    cold: ColdSteps | None = None,
) -> StorageResult:
    """Simulate the state of charge of a buffer over power curves and a load.

    Parameters
    ----------
    power : array_like
        Power at step centres [W], 0 or more, (n_series, n_days, n_steps), or (n_series, n_steps)
        for one day (repeated until periodic by default): the design's whole power, before its own
        ``draw``. Each series is sequential over its days. One curve (n_series 1) serves every
        series of the load or the buffer.
    load : float or array_like
        Load [W], 0 or more: a float; (n_series,) one per series; (n_series or 1, n_steps) a daily
        profile; or (n_series or 1, n_days or 1, n_steps or 1).
    buffer : Buffer
        The buffer (fields floats or arrays over the series).
    step_hours : float
        Step length [h]; ``n_steps x step_hours`` is a day.
    engine : {'numba', 'numpy'}
        The compiled loop, or the NumPy reference (vectorised over series, a Python loop over the
        steps: for tests and small cases).
    soc_curves : bool, default False
        Also the state of charge at every step (memory of the power's size).
    max_iterations : int, default 30
        Passes allowed to find the periodic state.
    tolerance : float, default 1e-6
        The periodic state's content is that at the end within ``tolerance x capacity_wh``.
    draw : float or array_like, optional
        The design's own draw [W], 0 or more, shaped as ``load`` may be or as ``power``: a
        tracker's standby and drive, a load on the controller's output beside ``load``
        (module docstring). Default none.
    cold : ColdSteps, optional
        The buffer's temperature's effects at each step (module docstring); default none (a
        buffer at a temperature that changes nothing).

    Returns
    -------
    StorageResult

    Raises
    ------
    ValueError
        An unknown ``engine``, a field of ``buffer`` out of range (named), power that is not
        finite or below 0, a negative load or draw, or shapes that do not fit.
    """
    if engine not in STORAGE_ENGINES:
        raise ValueError(f"engine must be one of {', '.join(STORAGE_ENGINES)}; got {engine!r}")
    power = np.asarray(power, dtype=float)
    if power.ndim == 2:
        power = power[:, None, :]
    if power.ndim != 3 or 0 in power.shape:
        raise ValueError(
            f"power must be (n_series, n_days, n_steps) or (n_series, n_steps); got {power.shape}"
        )
    if not (np.isfinite(power).all() and (power >= 0).all()):
        raise ValueError("power must be finite and 0 or more (a design's own draw goes in draw)")
    load = _load_array(load, power.shape, "load")
    own = _load_array(0.0 if draw is None else draw, power.shape, "draw")
    # The kernel compares the power the design leaves after its own draw with the load (as
    # t_solar does a tracker's net curve: the same difference, to the bit).
    power = np.ascontiguousarray(power if draw is None else power - own)
    # One power curve, load or buffer may serve every series (a sizing search's capacities).
    sizes = [power.shape[0], load.shape[0], own.shape[0]]
    sizes += [np.size(v) for v in buffer if v is not None]
    sizes += [np.shape(field)[0] for field in cold or () if np.ndim(field) == 3]
    n_series = max(sizes)
    if any(size not in (1, n_series) for size in sizes):
        raise ValueError(
            "power, load, buffer fields and cold must have 1 or the same number of series; got "
            f"{sizes}"
        )
    n_days, n_steps = power.shape[1:]
    if not (np.isfinite(step_hours) and step_hours > 0):
        raise ValueError(f"step_hours must be above 0; got {step_hours}")
    params = _parameters(buffer, n_series, step_hours)
    segments = _cold_segments(cold, power.shape, n_series, params)
    if max_iterations < 1 or not tolerance >= 0:
        raise ValueError("max_iterations must be 1 or more and tolerance 0 or more")
    out = np.zeros((n_series, n_days, layout.HISTOGRAM + SOC_BINS))
    state = np.zeros((n_series, n_days + 1, 2))
    soc = np.zeros((n_series, n_days, n_steps) if soc_curves else (1, 1, 1))
    passes = np.zeros(n_series, dtype=np.int64)
    # The compiled loop takes every argument with the one type it was compiled for.
    if engine == "numba":  # numba loads with the compiled loop, not for the NumPy path
        from foldopt.engine.storage_kernel import simulate_series as run
    else:
        run = _simulate_numpy
    run(
        layout.Curves(power, load, own, float(step_hours)),
        params,
        segments,
        layout.Days(out, state, soc, bool(soc_curves)),
        passes,
        int(max_iterations),
        float(tolerance),
    )
    return StorageResult(
        out[..., layout.POWERED],
        out[..., layout.SERVED],
        out[..., layout.MISSING],
        out[..., layout.LOST],
        out[..., layout.HARVESTED],
        out[..., layout.CHARGE_LOSS],
        out[..., layout.DISCHARGE_LOSS],
        out[..., layout.SELF_DISCHARGE],
        out[..., layout.DRAWN],
        out[..., layout.FULL] > 0.5,
        out[..., layout.EMPTY] > 0.5,
        out[..., layout.HISTOGRAM :],
        state[..., 0],
        soc if soc_curves else None,
        passes,
    )


def _load_array(load, shape, name):
    """The load (or a design's own draw, ``name``) as (n_series or 1, n_days or 1, n_steps or 1),
    contiguous (the series are checked by the caller)."""
    load = np.asarray(load, dtype=float)
    if load.ndim == 0:
        load = load.reshape(1, 1, 1)
    elif load.ndim == 1:
        load = load[:, None, None]
    elif load.ndim == 2:
        load = load[:, None, :]
    fits = load.ndim == 3 and all(
        size in (1, full) for size, full in zip(load.shape[1:], shape[1:], strict=True)
    )
    if not fits:
        raise ValueError(
            f"{name} must be a float, (n_series,), (n_series, n_steps) or (n_series, n_days, "
            f"n_steps), each size 1 or full, for power of {shape}; got {np.shape(load)}"
        )
    if not (np.isfinite(load).all() and (load >= 0).all()):
        raise ValueError(f"{name} must be finite and 0 or more")
    return np.ascontiguousarray(load)


def _cold_segments(cold, shape, n_series, params) -> np.ndarray:
    """The steps' :class:`ColdSteps` per segment of each day, as the loops read them (one array,
    :mod:`foldopt.engine.storage_records`' ``COLD_*`` columns; module docstring): at each segment
    the colder end's charge, discharge and capacity, the mean of the two ends' leak factors."""
    if cold is None:
        return np.array([1.0, 1.0, 0.0, np.nan]).reshape(1, 1, 1, 4)
    n_days, n_steps = shape[1:]

    def per_step(name, values):
        values = np.asarray(values, dtype=float)
        values = (
            values.reshape((1,) * (3 - values.ndim) + values.shape) if values.ndim < 3 else values
        )
        if values.ndim != 3 or values.shape[0] not in (1, n_series):
            raise ValueError(
                f"cold {name} must broadcast to (n_series or 1, n_days, n_steps) for power of "
                f"{shape} and {n_series} series; got {np.shape(values)}"
            )
        try:
            return np.broadcast_to(values, (values.shape[0], n_days, n_steps))
        except ValueError:
            raise ValueError(
                f"cold {name} must broadcast to (n_series or 1, n_days, n_steps) for power of "
                f"{shape}; got {values.shape}"
            ) from None

    def ends(values):
        return (
            np.concatenate([values[..., :1], values], axis=-1),
            np.concatenate([values, values[..., -1:]], axis=-1),
        )

    charge, discharge = (
        np.minimum(*ends(per_step(name, getattr(cold, name)) > 0.0))
        for name in ("charge", "discharge")
    )
    capacity = per_step("capacity", cold.capacity)
    leak = per_step("leak", cold.leak)
    if (
        not ((capacity > 0.0) & (capacity <= 1.0)).all()
        or not ((leak >= 0.0) & np.isfinite(leak)).all()
    ):
        raise ValueError("cold capacity must be in (0, 1] and cold leak 0 or more (finite)")
    cut = 1.0 - np.minimum(*ends(capacity))
    a, b = ends(leak)
    factor = 0.5 * (a + b)
    if (factor == 1.0).all():
        keep = np.full((1, 1, 1), np.nan)
    else:
        # The buffer's own share kept over each segment, raised to the factor (the rate's
        # multiple); where the factor is 1, the buffer's own to the bit.
        half = np.zeros(n_steps + 1, dtype=bool)
        half[[0, -1]] = True
        one = (params.keep_step == params.keep_step[0]).all() and (
            params.keep_half == params.keep_half[0]
        ).all()
        rows = slice(0, 1) if one else slice(None)
        own = np.where(half, params.keep_half[rows, None, None], params.keep_step[rows, None, None])
        with np.errstate(invalid="ignore"):
            keep = np.where(factor == 1.0, own, own**factor)
    fields = (charge, discharge, cut, keep)
    common = np.broadcast_shapes(*(np.shape(field) for field in fields))
    return np.ascontiguousarray(
        np.stack([np.broadcast_to(field, common) for field in fields], axis=-1), dtype=float
    )


def _parameters(buffer: Buffer, n_series: int, step_hours: float) -> layout.Parameters:
    """The buffer as the loops read it, each field checked: (n_series,) arrays."""

    def field(name, value, lo, hi, lo_open=False, hi_open=False, default=None):
        value = np.asarray(default if value is None else value, dtype=float)
        inside = (value > lo if lo_open else value >= lo) & (value < hi if hi_open else value <= hi)
        if value.ndim > 1 or value.size not in (1, n_series) or not inside.all():
            lower, upper = "(" if lo_open else "[", ")" if hi_open else "]"
            raise ValueError(
                f"buffer {name} must be a value in {lower}{lo:g}, {hi:g}{upper}, or one per series "
                f"({n_series}); got {value.tolist()}"
            )
        return value

    capacity = field("capacity_wh", buffer.capacity_wh, 0.0, np.inf, hi_open=True)
    min_soc = field("min_soc", buffer.min_soc, 0.0, 1.0)
    restart = field("restart_soc", buffer.restart_soc, 0.0, 1.0, default=min_soc)
    if (restart < min_soc).any():
        raise ValueError(f"buffer restart_soc must be at least min_soc; got {restart.tolist()}")
    eta_c = field("charge_efficiency", buffer.charge_efficiency, 0.0, 1.0, lo_open=True)
    eta_d = field("discharge_efficiency", buffer.discharge_efficiency, 0.0, 1.0, lo_open=True)
    leak = field("self_discharge", buffer.self_discharge, 0.0, 1.0, hi_open=True)
    max_c = field("max_charge_w", buffer.max_charge_w, 0.0, np.inf, default=np.inf)
    max_d = field("max_discharge_w", buffer.max_discharge_w, 0.0, np.inf, default=np.inf)
    initial = (
        np.asarray(np.nan)
        if buffer.initial_soc is None
        else field("initial_soc", buffer.initial_soc, 0.0, 1.0)
    )
    fields = layout.Parameters(
        capacity=capacity,
        min_soc=min_soc,
        restart_soc=restart,
        eta_charge=eta_c,
        eta_discharge=eta_d,
        keep_step=(1.0 - leak) ** (step_hours / 24.0),
        keep_half=(1.0 - leak) ** (step_hours / 48.0),
        max_charge=max_c,
        max_discharge=max_d,
        initial_soc=initial,
    )
    # Each a fresh writable array, whether one value serves every series or each has its own (a
    # broadcast is read-only): the compiled loop is compiled for one type of each.
    return layout.Parameters(
        *(np.array(np.broadcast_to(field, n_series), dtype=float) for field in fields)
    )


# The NumPy reference: the same model written over arrays of series, step by step.


def _clipped_energy(a, b, tau, cap):
    """:func:`foldopt.engine.storage_kernel.clipped_energy` over arrays."""
    lo, hi = np.minimum(a, b), np.maximum(a, b)

    def ramp(x):
        return np.where(
            x <= 0.0, 0.0, np.where(x <= cap, 0.5 * x * x, cap * (0.5 * cap + (x - cap)))
        )

    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        crossing = tau * (ramp(hi) - ramp(lo)) / (hi - lo)
        return np.where(
            (hi <= 0.0) | (tau <= 0.0),
            0.0,
            np.where(
                lo >= cap,
                tau * cap,
                np.where((lo >= 0.0) & (hi <= cap), 0.5 * tau * (a + b), crossing),
            ),
        )


#: The sums of a day that :func:`_part_numpy` adds to, and their columns.
_SUMS = {
    "powered": layout.POWERED,
    "served": layout.SERVED,
    "missing": layout.MISSING,
    "lost": layout.LOST,
    "charge_loss": layout.CHARGE_LOSS,
    "discharge_loss": layout.DISCHARGE_LOSS,
    "self_discharge": layout.SELF_DISCHARGE,
    "drawn": layout.DRAWN,
}


def _charge_numpy(charging, stored, spare, limit, par, day):
    """:func:`foldopt.engine.storage_kernel._charge` over arrays, adding to the ``day``'s
    sums."""
    capacity, eta = par.capacity, par.eta_charge
    room = np.maximum(capacity - stored, 0.0) / eta
    take = np.minimum(spare, limit)
    fills = charging & (take >= room)
    take = np.where(fills, room, take)
    stored = np.where(fills, capacity, np.where(charging, stored + take * eta, stored))
    day["full"] |= fills & (capacity > 0.0)
    day["charge_loss"] += np.where(charging, take * (1.0 - eta), 0.0)
    day["lost"] += np.where(charging, spare - take, 0.0)
    return stored


def _time_to_draw(da, db, tau, energy):
    """:func:`foldopt.engine.storage_kernel.time_to_draw` over arrays."""
    da, db = np.maximum(da, 0.0), np.maximum(db, 0.0)
    # Series whose part this is not (the caller's mask) may overflow or divide by zero.
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        slope = 0.5 * (db - da) / tau
        root = np.sqrt(np.maximum(da * da + 4.0 * slope * energy, 0.0))
        return np.where(
            slope == 0.0,
            np.minimum(energy / da, tau),
            np.where(
                da + root == 0.0,
                np.minimum(np.sqrt(energy / slope), tau),
                np.minimum(2.0 * energy / (da + root), tau),
            ),
        )


class _Part(NamedTuple):
    """One part of every segment (the one first in time, or the second), of every series and
    day: (n_series, n_days, n_steps + 1) arrays, or one segment's (n_series,). What does not
    depend on the buffer's state, computed over the whole arrays at once: the six ``ends``
    (power left after the design's own draw, load, draw at the part's two ends [W]), its length
    ``tau`` [h], whether the power is at or above the load (``surplus``), the load's and the
    draw's energies [Wh] (``need``, ``own``; ``short`` the deficit and ``taken`` what covering
    it takes from the buffer), whether the deficit stays within ``max_discharge_w``
    (``within``), the surplus the running load leaves (``spare_on``) and the power with the
    load off (``spare_off``), and the charge limits over the part running or off
    (``limit_on``, ``limit_off``)."""

    ends: tuple
    tau: np.ndarray
    surplus: np.ndarray
    need: np.ndarray
    own: np.ndarray
    short: np.ndarray
    taken: np.ndarray
    within: np.ndarray
    spare_on: np.ndarray
    spare_off: np.ndarray
    limit_on: np.ndarray
    limit_off: np.ndarray

    def at(self, d, j):
        """Day ``d``'s segment ``j`` of every series."""
        return _Part(tuple(a[:, d, j] for a in self.ends), *(a[:, d, j] for a in self[1:]))


def _part_energies(ends, tau, surplus, par) -> _Part:
    """A part's energies, as :func:`foldopt.engine.storage_kernel._part` computes them before
    it reads the state (the fields of :class:`_Part`), over whole arrays; ``par``'s fields
    (n_series, 1, 1)."""
    pa, pb, la, lb, da, db = ends
    pv = 0.5 * tau * (pa + pb)
    need = 0.5 * tau * (la + lb)
    short = np.maximum(need - pv, 0.0)
    whole_a, whole_b = pa + da, pb + db
    return _Part(
        ends=ends,
        tau=tau,
        surplus=surplus,
        need=need,
        own=0.5 * tau * (da + db),
        short=short,
        taken=short / par.eta_discharge,
        within=np.maximum(la - pa, lb - pb) <= par.max_discharge,
        spare_on=np.maximum(pv - need, 0.0),
        spare_off=_clipped_energy(whole_a, whole_b, tau, np.inf),
        limit_on=_clipped_energy(pa - la, pb - lb, tau, par.max_charge),
        limit_off=_clipped_energy(whole_a, whole_b, tau, par.max_charge),
    )


def _part_numpy(part: _Part, demand, stored, on, par, cold, day):
    """:func:`foldopt.engine.storage_kernel._part` over arrays of series (``part`` one
    segment's, ``demand``: whether the load runs at both ends of the segment, where its time
    counts; ``cold`` the segment's cut-off and reconnection [Wh] and whether the buffer may
    charge and discharge), adding to the ``day``'s sums; returns the content and the load's
    state."""
    tau, surplus, need = part.tau, part.surplus, part.need
    floor, restart, charge, discharge = cold
    active = tau > 0.0
    on = on | (active & (stored >= restart))
    run = active & on & surplus
    usable = stored - floor
    eta_d = par.eta_discharge
    able = active & on & ~surplus & discharge & (usable > 0.0) & part.within
    covered = able & (part.short <= eta_d * usable)
    partial = able & ~covered
    cut = active & on & ~surplus & ~covered
    off = active & ~on | cut
    whole = run | covered
    served = np.where(whole, need, 0.0)
    drawn = np.where(whole, part.own, 0.0)
    ran = np.where(whole, tau, 0.0)
    loss = np.where(covered, part.taken - part.short, 0.0)
    stored = np.where(covered, stored - part.taken, stored)
    spare_off, limit_off = part.spare_off, part.limit_off
    if partial.any():
        # The buffer carries the load part of the way, to its cut-off; the rest is off, and
        # what follows is of the rest of the part (the other series keep the whole part's).
        pa, pb, la, lb, da, db = part.ends
        until = _time_to_draw(la - pa, lb - pb, tau, eta_d * usable)
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            x = until / tau
            pm, lm, dm = pa + x * (pb - pa), la + x * (lb - la), da + x * (db - da)
            served = np.where(partial, 0.5 * until * (la + lm), served)
            drawn = np.where(partial, 0.5 * until * (da + dm), drawn)
            loss = np.where(partial, usable - eta_d * usable, loss)
            ran = np.where(partial, until, ran)
            rest = tau - until
            need = np.where(partial, 0.5 * rest * (lm + lb), need)
            rest_a, rest_b = pm + dm, pb + db
            spare_off = np.where(partial, _clipped_energy(rest_a, rest_b, rest, np.inf), spare_off)
            limit_off = np.where(
                partial, _clipped_energy(rest_a, rest_b, rest, par.max_charge), limit_off
            )
        stored = np.where(partial, floor, stored)
    day["served"] += served
    day["drawn"] += drawn
    day["discharge_loss"] += loss
    day["powered"] += np.where(demand, ran, 0.0)
    on = on & ~cut
    day["empty"] |= cut & (stored <= floor)
    day["missing"] += np.where(off, need, 0.0)
    # Off, the controller has the load and the design's own draw off: the whole power charges.
    spare = np.where(run, part.spare_on, np.where(off, spare_off, 0.0))
    limit = np.where(run & charge, part.limit_on, np.where(off & charge, limit_off, 0.0))
    return _charge_numpy(run | off, stored, spare, limit, par, day), on


def _segments(curves: layout.Curves, par: layout.Parameters):
    """Each day's segments and their two parts, over whole arrays (n_series, n_days, n_steps + 1):
    the part with the power (less the design's own draw) at or above the load and the one below
    it, in their order, each a :class:`_Part`; whether the load runs at both ends of each
    segment; and which segments are the half steps at the day's ends."""
    power, load, draw, step_hours = curves

    def ends(curve):
        curve = np.broadcast_to(curve, power.shape)
        return (
            np.concatenate([curve[..., :1], curve], axis=-1),
            np.concatenate([curve, curve[..., -1:]], axis=-1),
        )

    (p0, p1), (l0, l1), (d0, d1) = ends(power), ends(load), ends(draw)
    half = np.zeros(p0.shape[-1], dtype=bool)
    half[[0, -1]] = True
    tau = np.where(half, 0.5 * step_hours, step_hours)
    e0, e1 = p0 - l0, p1 - l1
    with np.errstate(invalid="ignore", divide="ignore"):
        crossing = np.maximum(e0, e1) / np.abs(e0 - e1)
    above = np.where((e0 >= 0) & (e1 >= 0), 1.0, np.where((e0 < 0) & (e1 < 0), 0.0, crossing))
    rising = e0 < 0.0  # below the load first
    split = np.where(rising, 1.0 - above, above)
    ps, ls = p0 + split * (p1 - p0), l0 + split * (l1 - l0)
    ds = d0 + split * (d1 - d0)
    t_above, t_below = tau * above, tau * (1.0 - above)
    per_series = layout.Parameters(*(field[:, None, None] for field in par))
    first = _part_energies(
        (p0, ps, l0, ls, d0, ds), np.where(rising, t_below, t_above), ~rising, per_series
    )
    second = _part_energies(
        (ps, p1, ls, l1, ds, d1), np.where(rising, t_above, t_below), rising, per_series
    )
    return first, second, (l0 > 0.0) & (l1 > 0.0), half


def _cold_levels(cold: np.ndarray, par: layout.Parameters, half):
    """Every segment's cut-off and reconnection [Wh], whether the buffer may charge and
    discharge, and the share of the content it keeps (the buffer's own where the cold array's
    is NaN), as :func:`foldopt.engine.storage_kernel._levels` and ``_at`` read them: arrays
    (n_series, n_days or 1, n_steps + 1 or 1), the cold array's sizes."""
    par = layout.Parameters(*(field[:, None, None] for field in par))
    cut = cold[..., layout.COLD_CUT]
    floor = (par.min_soc + cut * (1.0 - par.min_soc)) * par.capacity
    restart = (par.restart_soc + cut * (1.0 - par.restart_soc)) * par.capacity
    charge, discharge = cold[..., layout.COLD_CHARGE] > 0.0, cold[..., layout.COLD_DISCHARGE] > 0.0
    keep = cold[..., layout.COLD_KEEP]
    keep = np.where(np.isnan(keep), np.where(half, par.keep_half, par.keep_step), keep)
    return floor, restart, charge, discharge, keep


def _run_numpy(
    curves: layout.Curves, par: layout.Parameters, cold: np.ndarray, stored, on, days: layout.Days
):
    """One pass over the days of a set of series (:func:`foldopt.engine.storage_kernel._run`
    without merging), the steps in turn and the series at once."""
    power, _, draw, step_hours = curves
    out, state, soc, soc_curves = days
    n_series, n_days, n_steps = power.shape
    first, second, demand, half = _segments(curves, par)
    first_lasts, second_lasts = ((part.tau > 0.0).any(axis=0) for part in (first, second))
    levels = _cold_levels(cold, par, half)
    capacity = par.capacity
    level = np.zeros((n_series, n_days, n_steps + 1))

    def at(d, j):  # a size 1 of the cold array serves every day or segment
        return [a[:, d if a.shape[1] > 1 else 0, j if a.shape[2] > 1 else 0] for a in levels]

    for d in range(n_days):
        floor, restart = at(d, 0)[:2]
        on = on | (stored >= restart)
        state[:, d, 0], state[:, d, 1] = stored, on
        # The day's sums, each series' added to part by part in the compiled loop's order.
        sums = {name: np.zeros(n_series) for name in _SUMS}
        sums["full"] = (capacity > 0.0) & (stored >= capacity)
        sums["empty"] = stored <= floor
        for j in range(n_steps + 1):
            *limits, keep = at(d, j)
            for part, lasts in ((first, first_lasts), (second, second_lasts)):
                if lasts[d, j]:  # a part of no length in every series changes nothing
                    stored, on = _part_numpy(
                        part.at(d, j), demand[:, d, j], stored, on, par, limits, sums
                    )
            kept = np.where(keep < 1.0, stored * keep, stored)
            sums["self_discharge"] += stored - kept
            stored = kept
            with np.errstate(invalid="ignore", divide="ignore"):
                level[:, d, j] = np.where(capacity > 0.0, stored / capacity, 0.0)
        row = out[:, d]
        for name, column in _SUMS.items():
            row[:, column] = sums[name]
        row[:, layout.FULL], row[:, layout.EMPTY] = sums["full"], sums["empty"]
        whole = power[:, d] + np.broadcast_to(draw, power.shape)[:, d]
        row[:, layout.HARVESTED] = np.cumsum(whole, axis=-1)[:, -1] * step_hours
    # Each segment's state at its end, for the segment's length, in the segments' order.
    n_bins = out.shape[-1] - layout.HISTOGRAM
    bins = np.clip((level * n_bins).astype(np.int64), 0, n_bins - 1)
    histogram = np.zeros((n_series, n_days, n_bins))
    series, day = np.indices(bins.shape)[:2]
    np.add.at(histogram, (series, day, bins), np.where(half, 0.5 * step_hours, step_hours))
    out[..., layout.HISTOGRAM :] = histogram
    if soc_curves:
        soc[...] = level[..., :n_steps]
    on = on | (stored >= at(0, 0)[1])
    state[:, n_days, 0], state[:, n_days, 1] = stored, on
    return stored, on


def _simulate_numpy(curves, params, cold, days, passes, max_iterations, tolerance):
    """:func:`foldopt.engine.storage_kernel.simulate_series` over arrays of series, each series's
    passes as :func:`foldopt.engine.storage_kernel._series` runs them."""
    out, state, soc, soc_curves = days
    n_series = out.shape[0]
    power, load, draw = (np.broadcast_to(a, (n_series, *a.shape[1:])) for a in curves[:3])
    cold = np.broadcast_to(cold, (n_series, *cold.shape[1:]))
    step_hours, par = curves.step_hours, params
    capacity = par.capacity
    given = ~np.isnan(par.initial_soc)
    stored = np.where(given, par.initial_soc * capacity, capacity)
    on = np.where(given, stored >= _cold_levels(cold, par, False)[1][:, 0, 0], True)
    resolution = load.reshape(n_series, -1).max(axis=1) * step_hours
    low, high = np.zeros(n_series), capacity.copy()
    todo = np.ones(n_series, dtype=bool)
    while todo.any():
        pick = np.flatnonzero(todo)
        sub_out, sub_state = out[pick], state[pick]
        sub_soc = soc[pick] if soc_curves else soc
        end, end_on = _run_numpy(
            layout.Curves(power[pick], load[pick], draw[pick], step_hours),
            layout.Parameters(*(field[pick] for field in par)),
            cold[pick],
            stored[pick],
            on[pick],
            layout.Days(sub_out, sub_state, sub_soc, soc_curves),
        )
        out[pick], state[pick] = sub_out, sub_state
        if soc_curves:
            soc[pick] = sub_soc
        passes[pick] += 1
        tol = tolerance * capacity[pick]
        done = given[pick] | ((np.abs(end - stored[pick]) <= tol) & (end_on == on[pick]))
        lo = np.where(end > stored[pick], stored[pick], low[pick])
        hi = np.where(end < stored[pick], stored[pick], high[pick])
        located = ~done & (hi - lo <= tol)  # the end jumps over the start (kernel's _series)
        done |= located & (np.abs(end - stored[pick]) <= resolution[pick])
        stuck = ~done & (located | (passes[pick] >= max_iterations))
        passes[pick[stuck]] *= -1
        plain = (passes[pick] < layout.PLAIN_ITERATIONS) & (lo <= end) & (end <= hi)
        low[pick], high[pick] = lo, hi
        stored[pick] = np.where(plain, end, 0.5 * (lo + hi))
        on[pick] = end_on
        todo[pick[done | stuck]] = False
