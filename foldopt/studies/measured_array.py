"""t_solar of a real array: its measured DC power against the power a study's PV model predicts
from the array's measured plane-of-array irradiance and air temperature.

The check of docs/validation.rst (and tests/test_validation_measured.py): a data set that holds
an array's DC power, its plane-of-array irradiance and the air temperature, but no horizontal
light, tests the PV model alone (the sky and the geometry have their own checks): the study's
model (:func:`predicted_power`, the engine's :class:`~foldopt.physics.pvmodel.PVModel` and cell
temperature of the study's options) at each measured step, and the t_solar of both curves at
loads that are fractions of the array's measured peak (:func:`t_solar_table`), by foldopt's
metric (:func:`foldopt.engine.metrics.t_solar`, linear between samples) for both.

The module may import numpy, pandas and foldopt's engine and physics; it reads no file.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from foldopt.engine.metrics import t_solar
from foldopt.inputs.pvwatts_section import GAMMA_PDC
from foldopt.inputs.study import Study, make_study
from foldopt.physics.pvmodel import PVModel
from foldopt.physics.temperature import cell_temperature
from foldopt.studies.engine_options import engine_options

#: The loads of the check, as fractions of the array's measured peak (issue 51).
LOAD_FRACTIONS = (0.1, 0.3, 0.5, 0.7)
#: A day's array was free of snow where its DC yield per plane-of-array insolation is at least
#: this share of the data set's median day's: snow on the modules (not on the irradiance sensor)
#: cuts the power, not the measured light. A measured rule, no model's.
SNOW_FREE_SHARE = 0.9
#: The models compared: each is given the array's rating, PVWatts as ``pvwatts.pdc0``, the ideal
#: model as efficiency x area, the single-diode model (the A-300 cells) as the area whose STC power
#: is the rating.
MODELS = ("ideal", "pvwatts", "single-diode")


def predicted_power(study: Study, poa_global, temp_air) -> np.ndarray:
    """The flat panel's power [W] that the study's PV model gives at each measured step.

    Both halves see the measured irradiance; the cells are at the study's temperature model's
    temperature for the measured air temperature and the study's wind speed.

    Parameters
    ----------
    study : Study
        Its PV model, panel (area, efficiency or rating), temperature model and wind speed.
    poa_global : array_like
        Measured plane-of-array irradiance [W/m^2]; below 0 (a sensor's night offset) is 0.
    temp_air : array_like
        Measured air temperature [C].

    Returns
    -------
    numpy.ndarray
        [W], shaped as ``poa_global``.
    """
    options = engine_options(study).electrical
    pv = options.pv()
    poa = np.clip(np.asarray(poa_global, dtype=float), 0.0, None)
    temp_cell = cell_temperature(poa, temp_air, study.wind_speed, options.temperature_model)
    return pv.max_power(poa, temp_cell, options.area)


def as_installed_rating(dc_power, poa_global, module_temp, gamma_pdc) -> float:
    """An array's DC power at 1000 W/m^2 and 25 C [W], translated from its measured steps in
    800 to 1100 W/m^2 by its module temperature: the median of ``P 1000 / E / (1 + gamma_pdc
    (T_module - 25 C))``, the temperature-corrected rating of IEC 61724-1's performance ratio.

    It holds the array as it stands (soiling, wiring, mismatch, age): a rating where no nameplate
    is published with the data.

    Parameters
    ----------
    dc_power, poa_global, module_temp : array_like
        [W], [W/m^2], [C] at each step.
    gamma_pdc : float
        Temperature coefficient of power [1/C].

    Returns
    -------
    float
        [W].
    """
    dc_power, poa, module_temp = (
        np.asarray(a, dtype=float) for a in (dc_power, poa_global, module_temp)
    )
    bright = (poa >= 800.0) & (poa <= 1100.0) & (dc_power > 0.0)
    translated = (
        dc_power[bright] * 1000.0 / poa[bright] / (1.0 + gamma_pdc * (module_temp[bright] - 25.0))
    )
    return float(np.median(translated))


def t_solar_table(
    days: dict, predicted: dict, step_hours: float, peak: float, fractions=LOAD_FRACTIONS
) -> pd.DataFrame:
    """t_solar of the measured and the predicted power of each day, at loads of the peak.

    Parameters
    ----------
    days : dict of str to numpy.ndarray
        Each day's measured DC power [W] at its steps.
    predicted : dict of str to dict of str to numpy.ndarray
        Per model, each day's predicted power [W] at the same steps.
    step_hours : float
        Step length [h].
    peak : float
        The array's measured peak [W]: the loads are ``fractions`` of it.
    fractions : sequence of float, default :data:`LOAD_FRACTIONS`

    Returns
    -------
    pandas.DataFrame
        One row per day and load: ``day``, ``load_fraction``, ``p_load_w``, ``t_solar_measured_h``
        and, per model, ``t_solar_<model>_h`` and ``error_<model>_pct`` (predicted / measured - 1).
    """
    rows = []
    for day, measured in days.items():
        for fraction in fractions:
            load = fraction * peak
            row = {
                "day": day,
                "load_fraction": fraction,
                "p_load_w": load,
                "t_solar_measured_h": float(t_solar(measured, load, step_hours)),
            }
            for model, curves in predicted.items():
                hours = float(t_solar(curves[day], load, step_hours))
                row[f"t_solar_{model}_h"] = hours
                row[f"error_{model}_pct"] = 100.0 * (hours / row["t_solar_measured_h"] - 1.0)
            rows.append(row)
    return pd.DataFrame(rows)


def snow_free_days(frame: pd.DataFrame) -> list:
    """The days of ``frame`` whose array was free of snow (:data:`SNOW_FREE_SHARE`).

    Parameters
    ----------
    frame : pandas.DataFrame
        ``dc_power`` [W] and ``poa_global`` [W/m^2] on a DatetimeIndex.

    Returns
    -------
    list of datetime.date
    """
    by_day = frame.clip(lower=0.0).groupby(frame.index.date)
    ratio = by_day["dc_power"].sum() / by_day["poa_global"].sum()
    return list(ratio.index[ratio >= SNOW_FREE_SHARE * ratio.median()])


def model_study(base: dict, model: str, rating: float, **fields) -> Study:
    """The study of ``base`` whose ``model`` has the array's ``rating`` [W] (:data:`MODELS`);
    ``fields`` are given it too (``pvwatts`` settings to the PVWatts model only)."""
    pvwatts = fields.pop("pvwatts", {})
    if model == "pvwatts":
        fields["pvwatts"] = {"pdc0": rating, **pvwatts}
    if model == "single-diode":
        panel = {"area": rating / PVModel(model).max_power(np.array([1000.0]), 25.0, 1.0)[0]}
    else:
        panel = {"area": rating / 200.0, "efficiency": 0.2}
    return make_study({**base, "pv_model": model, "panel": panel, **fields})


def validation_table(frame: pd.DataFrame, base: dict, step_hours: float, **fields):
    """Every model's t_solar against the measured on the snow-free days of an array's data.

    Parameters
    ----------
    frame : pandas.DataFrame
        ``dc_power`` [W], ``poa_global`` [W/m^2], ``temp_air`` and ``module_temp`` [C] on a
        DatetimeIndex.
    base : dict
        The array's study (its site, date, load: the fields each model's study shares).
    step_hours : float
        The data's step [h].
    **fields
        Study fields given every model (``pvwatts`` settings go to the PVWatts model only).

    Returns
    -------
    table : pandas.DataFrame
        :func:`t_solar_table`'s.
    rating : float
        The array's as-installed rating [W] (:func:`as_installed_rating`).
    days : list of datetime.date
        The snow-free days compared.
    """
    days = snow_free_days(frame)
    kept = frame[np.isin(frame.index.date, days)]
    rating = as_installed_rating(
        kept["dc_power"], kept["poa_global"], kept["module_temp"], GAMMA_PDC
    )
    predicted = {}
    for model in MODELS:
        study = model_study(base, model, rating, **fields)
        power = predicted_power(study, kept["poa_global"].to_numpy(), kept["temp_air"].to_numpy())
        predicted[model] = {day: power[kept.index.date == day] for day in days}
    measured = {day: kept["dc_power"].to_numpy()[kept.index.date == day] for day in days}
    peak = float(kept["dc_power"].max())
    return t_solar_table(measured, predicted, step_hours, peak), rating, days
