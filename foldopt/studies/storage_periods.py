"""A buffer's days by period (issue 50): the days' buffer simulation of an annual group
(:func:`foldopt.studies.storage_days.year_storage`) reduced per calendar year
(:func:`storage_years`, ``storage_years.csv``) and per calendar month in the names and units of
PVGIS's off-grid calculator (:func:`storage_monthly`, ``storage_monthly.csv``), both by one
reduction of days by a label (:func:`by_period`); and a target met in a share of the years
(:func:`years_meeting`).

The days partition the periods, so a period's sums add up to the series' and its means, weighted
by its days, average to the series': each statistic of a period is the series' statistic
(:meth:`foldopt.engine.storage.StorageResult.summary`) over the period's days, the same
expression on the same values in the same order, so that a single year's row is the series'
(``storage_annual.csv``) to the bit.

PVGIS's off-grid calculator (SHScalc) [1]_ answers per month ``E_d`` (average energy per day
[Wh/d]: the energy delivered to the load), ``E_lost_d`` (average energy not captured per day
[Wh/d]: the battery full), ``f_f`` and ``f_e`` (percentage of days when the battery became full,
empty [%]), and over the whole series ``E_lost`` and ``E_miss`` (average energy not captured and
missing per day [Wh/d]), with a histogram of the charge state at the end of each hour ``CS`` in
ten bins from the discharge cut-off limit to 100 % (``f_CS`` [%]): the names and the definitions
of its response's ``meta`` (the recorded answer ``jouniverse/pvgis-cli-py``,
``response-examples/off-grid-pv-systems.json``).

The module may import numpy, pandas and :mod:`foldopt.engine`.

References
----------
.. [1] European Commission JRC, PVGIS 5.3, "Off-grid PV systems" (``SHScalc``): the response's
   ``meta.outputs`` (monthly ``E_d``, ``E_lost_d``, ``f_f``, ``f_e``; totals ``d_total``,
   ``f_f``, ``f_e``, ``E_lost``, ``E_miss``; histogram ``CS``, ``f_CS``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from foldopt.engine.storage import SOC_BINS, StorageResult

if TYPE_CHECKING:
    import pandas as pd

#: Histogram columns of ``storage_monthly.csv``: PVGIS's ``f_CS`` of each of the ten bins of the
#: charge state from the cut-off (``min_soc``) to full, the lowest first.
CS_COLUMNS = tuple(f"f_CS_{index + 1:02d}" for index in range(SOC_BINS))


def by_period(result: StorageResult, labels) -> tuple[np.ndarray, dict]:
    """Each series' days reduced per period: the series' statistics over each period's days.

    Parameters
    ----------
    result : foldopt.engine.storage.StorageResult
        (n_series, n_days) days in order.
    labels : array_like
        (n_days,) the period of each day (a year, a month, ``12 * year + month``...).

    Returns
    -------
    periods : numpy.ndarray
        (n_periods,) the labels, sorted.
    columns : dict of numpy.ndarray
        (n_series, n_periods) each: ``days_n``; ``powered_mean_h`` and ``powered_min_h`` (daily
        powered time [h]); ``powered_days_ge24h_pct`` (days with no energy missing [%]);
        ``energy_served_wh``, ``energy_missing_wh`` and ``energy_lost_wh`` (means a day [Wh]);
        ``energy_missing_total_wh`` [Wh]; ``days_full_pct`` and ``days_empty_pct`` (PVGIS's
        [%]).
    """
    labels = np.asarray(labels)
    periods = np.unique(labels)
    n_series = len(result.powered_h)

    def over(days) -> dict:
        # compress keeps each series' days contiguous, as the series' own arrays (a boolean
        # index lays them out by columns): over a period of every day, the same sums to the bit.
        powered, served, missing, lost, full, empty = (
            values.compress(days, axis=1)
            for values in (
                result.powered_h,
                result.served_wh,
                result.missing_wh,
                result.lost_wh,
                result.full,
                result.empty,
            )
        )
        return {
            "days_n": np.full(n_series, powered.shape[1]),
            "powered_mean_h": powered.mean(axis=1),
            "powered_min_h": powered.min(axis=1),
            "powered_days_ge24h_pct": 100.0 * (missing <= 0.0).mean(axis=1),
            "energy_served_wh": served.mean(axis=1),
            "energy_missing_wh": missing.mean(axis=1),
            "energy_missing_total_wh": missing.sum(axis=1),
            "energy_lost_wh": lost.mean(axis=1),
            "days_full_pct": 100.0 * full.mean(axis=1),
            "days_empty_pct": 100.0 * empty.mean(axis=1),
        }

    each = [over(labels == period) for period in periods]
    return periods, {name: np.stack([one[name] for one in each], axis=-1) for name in each[0]}


def cs_hours(soc: np.ndarray, labels, min_soc: float, step_hours: float) -> np.ndarray:
    """Hours each series' charge state spends in each of PVGIS's ten bins from the cut-off to
    full, per period: one state a step, the engine's at the step's centre, for the step's length
    (PVGIS's is the state at the end of each hour, half an hour later on hourly steps); a state
    below the cut-off, the floor leaking, counts in the lowest bin, a full buffer in the highest.

    Parameters
    ----------
    soc : numpy.ndarray
        (n_series, n_days, n_steps) the state of charge [-] at each step's centre
        (:func:`foldopt.engine.storage.simulate`'s ``soc_curves``).
    labels : array_like
        (n_days,) each day's period.
    min_soc : float
        The cut-off [-] in [0, 1).
    step_hours : float

    Returns
    -------
    numpy.ndarray
        (n_series, n_periods, :data:`~foldopt.engine.storage.SOC_BINS`) [h], the periods in
        :func:`by_period`'s order.
    """
    labels = np.asarray(labels)
    periods, index = np.unique(labels, return_inverse=True)
    width = (1.0 - min_soc) / SOC_BINS
    bins = np.clip(np.floor((soc - min_soc) / width), 0, SOC_BINS - 1).astype(np.int64)
    n_series = soc.shape[0]
    cell = (np.arange(n_series)[:, None, None] * periods.size + index[None, :, None]) * SOC_BINS
    counts = np.bincount(
        (cell + bins).ravel(), minlength=n_series * periods.size * SOC_BINS
    ).reshape(n_series, periods.size, SOC_BINS)
    return counts * step_hours


def storage_years(keys: pd.DataFrame, result: StorageResult, dates) -> pd.DataFrame:
    """A buffer's days per calendar year, for each series (a design of one load).

    Parameters
    ----------
    keys : pandas.DataFrame
        (n_series rows) the columns that say which series a row is (``p_load_w``,
        ``design``...), repeated on each of its years.
    result : foldopt.engine.storage.StorageResult
        (n_series, n_days).
    dates : sequence of datetime.date
        (n_days,) the days, in order.

    Returns
    -------
    pandas.DataFrame
        Per series and year: ``keys``' columns, ``year`` and :func:`by_period`'s columns;
        ``powered_worst_month_h`` (the least of the year's months' mean daily powered time) and
        ``worst_month`` (that month, 1-12); ``powered_vs_typical_h``, the year's mean powered
        time less the median of the series' years' [h], and ``worst_year``, True on the series'
        year of least mean powered time (the first of equals).
    """
    years = np.array([date.year for date in dates])
    months = np.array([date.month for date in dates])
    periods, columns = by_period(result, years)
    month_labels, per_month = by_period(result, 12 * years + (months - 1))
    month_mean = per_month["powered_mean_h"]
    worst_month = np.empty(columns["days_n"].shape, dtype=np.int64)
    worst_hours = np.empty(columns["days_n"].shape)
    for at, year in enumerate(periods):
        inside = np.flatnonzero(month_labels // 12 == year)
        pick = inside[np.argmin(month_mean[:, inside], axis=1)]
        worst_month[:, at] = month_labels[pick] % 12 + 1
        worst_hours[:, at] = month_mean[np.arange(len(month_mean)), pick]
    mean = columns["powered_mean_h"]
    worst = np.arange(periods.size) == np.argmin(mean, axis=1)[:, None]
    table = _rows(keys, "year", periods, columns)
    table["powered_worst_month_h"] = worst_hours.ravel()
    table["worst_month"] = worst_month.ravel()
    table["powered_vs_typical_h"] = (mean - np.median(mean, axis=1, keepdims=True)).ravel()
    table["worst_year"] = worst.ravel()
    return table


def storage_monthly(
    keys: pd.DataFrame, result: StorageResult, dates, min_soc: float, step_hours: float
) -> pd.DataFrame:
    """A buffer's days per calendar month (over every year of the series), in PVGIS's off-grid
    calculator's names and units [1]_, for each series (a design of one load).

    Parameters
    ----------
    keys : pandas.DataFrame
        As :func:`storage_years`'.
    result : foldopt.engine.storage.StorageResult
        (n_series, n_days), with its state of charge curves (``soc``).
    dates : sequence of datetime.date
    min_soc : float
        The controller's cut-off [-]: the histogram's lowest edge.
    step_hours : float

    Returns
    -------
    pandas.DataFrame
        Per series and month: ``keys``' columns, ``month`` (1-12), ``d_total`` (days), ``E_d``
        (energy delivered to the load, Wh a day), ``E_lost_d`` (PV energy not captured, the
        battery full, Wh a day), ``f_f`` and ``f_e`` (days the battery became full, empty [%]),
        :data:`CS_COLUMNS` (the share of the month's steps whose charge state lies in each tenth
        of the range from the cut-off to full [%], :func:`cs_hours`); and the series' totals, the same on each of its
        months: ``E_miss`` and ``E_lost`` (energy missing, not captured, Wh a day over every
        day).
    """
    months = np.array([date.month for date in dates])
    periods, columns = by_period(result, months)
    hours = cs_hours(result.soc, months, min_soc, step_hours)
    share = 100.0 * hours / hours.sum(axis=-1, keepdims=True)
    table = _rows(
        keys,
        "month",
        periods,
        {
            "d_total": columns["days_n"],
            "E_d": columns["energy_served_wh"],
            "E_lost_d": columns["energy_lost_wh"],
            "f_f": columns["days_full_pct"],
            "f_e": columns["days_empty_pct"],
            **{name: share[..., index] for index, name in enumerate(CS_COLUMNS)},
        },
    )
    summary = result.summary()
    table["E_miss"] = np.repeat(summary["missing_wh"], periods.size)
    table["E_lost"] = np.repeat(summary["lost_wh"], periods.size)
    return table


def _rows(keys: pd.DataFrame, label: str, periods, columns: dict) -> pd.DataFrame:
    """A row per series of ``keys`` and period, the series' periods together."""
    n_periods = len(periods)
    table = keys.loc[keys.index.repeat(n_periods)].reset_index(drop=True)
    table[label] = np.tile(periods, len(keys))
    for name, value in columns.items():
        table[name] = np.asarray(value).ravel()
    return table


def years_meeting(days_met: np.ndarray, labels, days_pct: float, years_pct: float) -> np.ndarray:
    """Whether a target is met in enough of the years: a year meets it where ``days_pct`` of its
    days do, and the series where ``years_pct`` of its years do.

    Parameters
    ----------
    days_met : numpy.ndarray
        (n, n_days) bool: the days that reach the target's powered time.
    labels : array_like
        (n_days,) each day's year.
    days_pct, years_pct : float
        [%] in (0, 100].

    Returns
    -------
    numpy.ndarray
        (n,) bool.
    """
    labels = np.asarray(labels)
    met = np.stack(
        [
            100.0 * days_met[:, labels == year].mean(axis=1) >= days_pct - 1e-9
            for year in np.unique(labels)
        ],
        axis=-1,
    )
    return 100.0 * met.mean(axis=1) >= years_pct - 1e-9
