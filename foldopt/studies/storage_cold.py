"""The buffer in the cold (issue 50): a study's ``storage`` section and its days' air temperature
as the engine takes them (:func:`cold_steps`), and what the cold costs (:func:`cold_columns`): the
hours and days the charger is blocked, and the powered time lost beside the same run with the
cold off. The physics is :mod:`foldopt.physics.buffer_temperature`'s, the model
:func:`foldopt.engine.storage.simulate`'s.

The module may import numpy, :mod:`foldopt.engine` and :mod:`foldopt.physics`.
"""

from __future__ import annotations

import numpy as np

from foldopt.engine.storage import ColdSteps
from foldopt.physics.buffer_temperature import (
    allowed,
    buffer_temperature,
    capacity_fraction,
    leak_factor,
)

#: The section's fields through which the temperature acts (none set: nothing acts).
COLD_FIELDS = ("charge_min_c", "discharge_min_c", "capacity_curve", "self_discharge_doubling_c")


def acts(storage) -> bool:
    """Whether a study's buffer feels its temperature: ``cold`` on and some limit, curve or
    leak's dependence set (its own or its preset's)."""
    return (
        storage is not None
        and storage.cold is not False
        and any(getattr(storage, name) is not None for name in COLD_FIELDS)
    )


def sky_air_temperature(sky) -> np.ndarray:
    """The air temperature of each block's steps [C], (n_blocks, n_steps): a weather file's (the
    air's own, not the cells' equivalent with the wind folded in), else the study's ``temp_air``
    at every step (a clear sky's).

    Parameters
    ----------
    sky : foldopt.engine.sky.Sky
    """
    if sky.air_steps is not None:
        return np.asarray(sky.air_steps, dtype=float)
    return np.broadcast_to(np.asarray(sky.temp_air, dtype=float)[:, None], sky.dni.shape)


def cold_steps(storage, temp_air) -> ColdSteps | None:
    """What the buffer's temperature does at each step, as
    :func:`foldopt.engine.storage.simulate` takes it; None where it does nothing (:func:`acts`
    false, or a temperature at which every charge and discharge is allowed, all the capacity
    usable and the leak the stated one), so that the run is the one without it, to the bit, and
    the answer says nothing of a cold that costs nothing.

    Parameters
    ----------
    storage : foldopt.inputs.storage_section.Storage
    temp_air : array_like
        The air temperature [C] at each step, (n_steps,) a day or (n_days, n_steps).

    Returns
    -------
    foldopt.engine.storage.ColdSteps or None
        Fields shaped as ``temp_air``.
    """
    if not acts(storage):
        return None
    temperature = buffer_temperature(temp_air, storage.enclosure_offset_c or 0.0)
    steps = ColdSteps(
        charge=allowed(temperature, storage.charge_min_c),
        discharge=allowed(temperature, storage.discharge_min_c),
        capacity=capacity_fraction(temperature, storage.capacity_curve),
        leak=leak_factor(temperature, storage.self_discharge_doubling_c),
    )
    warm = (
        steps.charge.all()
        and steps.discharge.all()
        and (steps.capacity == 1.0).all()
        and (steps.leak == 1.0).all()
    )
    return None if warm else steps


def charge_blocked(storage, temp_air, step_hours: float) -> dict:
    """The hours the charger is blocked and the days on which it is at some step
    (``charge_blocked_h``, ``charge_blocked_days_n``), over the days of ``temp_air`` (n_days,
    n_steps) [C]."""
    steps = cold_steps(storage, np.atleast_2d(temp_air))
    blocked = np.zeros(np.shape(np.atleast_2d(temp_air)), bool) if steps is None else ~steps.charge
    return {
        "charge_blocked_h": float(blocked.sum() * step_hours),
        "charge_blocked_days_n": int(blocked.any(axis=-1).sum()),
    }


def cold_columns(powered, warm, months) -> dict:
    """What the cold costs each series, beside the same run with the cold off.

    Parameters
    ----------
    powered, warm : numpy.ndarray
        Daily powered time [h] with the cold and with it off, (n, n_days).
    months : sequence of int
        Each day's month (1-12), (n_days,).

    Returns
    -------
    dict of numpy.ndarray
        (n,) each: ``cold_lost_mean_h`` (powered time lost a day, the days' mean),
        ``cold_lost_worst_month_h`` (the month losing most: its days' mean) and
        ``cold_worst_month`` (that month, 1-12; 0 where no month loses any).
    """
    lost = np.asarray(warm, dtype=float) - np.asarray(powered, dtype=float)
    months = np.asarray(months)
    present = np.unique(months)
    by_month = np.stack([lost[:, months == m].mean(axis=1) for m in present], axis=1)
    worst = np.argmax(by_month, axis=1)
    rows = np.arange(lost.shape[0])
    return {
        "cold_lost_mean_h": lost.mean(axis=1),
        **{f"cold_lost_month{month:02d}_mean_h": by_month[:, i] for i, month in enumerate(present)},
        "cold_lost_worst_month_h": by_month[rows, worst],
        "cold_worst_month": np.where(by_month[rows, worst] > 0.0, present[worst], 0),
    }


def per_series(steps: ColdSteps | None, reshape) -> ColdSteps | None:
    """``steps`` with each field made by ``reshape`` (as the series of days are laid out)."""
    return None if steps is None else ColdSteps(*(reshape(np.asarray(field)) for field in steps))
