"""Panel sizing: the flat-area equivalent and Shin et al.'s cost/benefit sizing (Sec. IV-A).

The flat-area equivalent of a design (Shin et al. Sec. VII: "we need about 2.61x larger PV panel
to achieve the same t_solar with the flat panel") is the factor k by which a flat panel's area
must grow for its ``t_solar`` to match. It assumes power proportional to area, as for the ideal
model and for panels grown by adding identical cells. Since ``t_solar(k P, L) = t_solar(P, L/k)``,
k follows from one root search for the load.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from foldopt.engine import evaluation as engines
from foldopt.inputs.costs import C_GRID, DAYS_PER_YEAR, LIFETIME_YEARS, PAPER_COST_PER_M2  # noqa: F401 (re-exported)
from foldopt.engine.metrics import load_for_t_solar
from foldopt.names import FLAT_FOLD_ANGLE

if TYPE_CHECKING:
    import pandas as pd


def flat_area_ratio(p_flat, p_load, target_t_solar, step_hours):
    """Factor by which the flat panel's area must grow to reach ``target_t_solar``.

    Parameters
    ----------
    p_flat : array_like
        The flat panel's power over the day [W], 1-D.
    p_load : float
        [W].
    target_t_solar : float
        [h].
    step_hours : float
        [h].

    Returns
    -------
    float
        Area multiple [-]; NaN if no flat panel of any size reaches the target (longer than the
        flat panel's daylight).
    """
    return p_load / load_for_t_solar(p_flat, target_t_solar, step_hours)


@dataclass(frozen=True)
class SizingResult:
    """A panel sizing (:func:`foldopt.size`): ``table`` per design and area, ``best`` the area of
    each design with the largest lifetime net benefit, ``parameters`` the costs, price and
    lifetime used, ``answer`` the :class:`foldopt.studies.answer.Answer` every view renders."""

    study: object
    table: pd.DataFrame
    best: pd.DataFrame
    parameters: dict
    request: object = None

    @functools.cached_property
    def answer(self):
        from foldopt.studies.result_answers import of_sizing

        return of_sizing(
            self.table,
            self.best,
            self.study,
            self.parameters,
            self.request.defaults if self.request is not None else None,
        )


def best_areas(table: pd.DataFrame) -> pd.DataFrame:
    """The row of each design with the largest net benefit.

    Parameters
    ----------
    table : pandas.DataFrame
        :func:`size_panel`'s table.

    Returns
    -------
    pandas.DataFrame
        One row per design, in the table's order of designs.
    """
    return table.loc[table.groupby("design", sort=False)["net_benefit_usd"].idxmax()].reset_index(
        drop=True
    )


def stc_power_per_area(pv) -> float:
    """Rated power per panel area (:meth:`foldopt.physics.pvmodel.PVModel.rating`): at STC
    (1000 W/m^2, 25 C), PVWatts' before its system losses.

    Parameters
    ----------
    pv : PVModel
        :class:`foldopt.physics.pvmodel.PVModel`.

    Returns
    -------
    float
        [W/m^2].

    Examples
    --------
    >>> from foldopt.physics.pvmodel import PVModel
    >>> stc_power_per_area(PVModel("ideal", efficiency=0.2))
    200.0
    """
    return pv.rating(1.0)


def size_panel(
    day,
    areas,
    cost_per_m2: float | None = None,
    cost_per_w: float | None = None,
    c_grid: float = C_GRID,
    years: float = LIFETIME_YEARS,
    days_per_year: float = DAYS_PER_YEAR,
):
    """Net benefit of flat and optimally folded twofold panels over a range of areas.

    Shin et al. Sec. IV-A, Eq. 7: the benefit of the panel is the grid energy it replaces,
    ``B_pv = C_grid * t_solar * P_load``, here per day of the study taken as representative and
    summed over ``days_per_year`` and ``years``. The cost is per m^2 of panel or per W of STC
    rating. Power is proportional to area (see the module docstring), so ``t_solar`` at area
    ``A`` is that of the study's panel against the load ``P_load * A_0 / A``: one pass covers
    every area and, for the twofold panel, every fold angle of the study's grid.

    Parameters
    ----------
    day : foldopt.studies.day.Day
    areas : array_like
        Panel areas [m^2].
    cost_per_m2, cost_per_w : float
        Panel cost [$ per m^2] or [$ per W at STC]; exactly one.
    c_grid : float, default 0.22
        Grid energy price [$/kWh].
    years, days_per_year : float
        Lifetime [years] and days counted per year.

    Returns
    -------
    pandas.DataFrame
        One row per area and design (``flat``, ``twofold``): ``area_m2``, ``fold_angle_deg``,
        ``t_solar_h``, ``benefit_usd``, ``cost_usd``, ``net_benefit_usd``.
    """
    import pandas as pd

    if (cost_per_m2 is None) == (cost_per_w is None):
        raise ValueError("give exactly one of cost_per_m2 and cost_per_w")
    study = day.study
    if study.load_profile is not None:
        from foldopt.errors import ConfigError

        raise ConfigError(
            [
                "load_profile: sizing scales a constant load with the panel's area (Shin et al. Sec. "
                "IV-A); use a constant p_load"
            ]
        )
    areas = np.asarray(areas, dtype=float)
    reference_area = study.panel.area
    p_load = study.p_load * reference_area / areas
    fold_angles = np.asarray(study.fold_angles.grid())
    # Every curve against every load in one pass of the kernel, with no (areas x angles x steps) array.
    curves = np.vstack([day.flat_power()[None, :], day.combined_power(fold_angles)])
    # (1 + angles, areas)
    all_hours = engines.curve_metrics(curves, p_load, day.step_hours).t_solar[:, 0, :]
    twofold_hours = all_hours[1:].T
    best = twofold_hours.shape[1] - 1 - np.argmax(twofold_hours[:, ::-1], axis=1)
    hours = {
        "flat": (np.full(areas.size, FLAT_FOLD_ANGLE), all_hours[0]),
        "twofold": (fold_angles[best], twofold_hours[np.arange(areas.size), best]),
    }
    unit_cost = (
        cost_per_m2
        if cost_per_m2 is not None
        else cost_per_w * stc_power_per_area(day.electrical.pv)
    )
    rows = []
    for design, (fold_angle, t) in hours.items():
        benefit = c_grid * t * study.p_load / 1000.0 * days_per_year * years
        cost = unit_cost * areas
        rows.append(
            pd.DataFrame(
                {
                    "design": design,
                    "area_m2": areas,
                    "fold_angle_deg": fold_angle,
                    "t_solar_h": t,
                    "benefit_usd": benefit,
                    "cost_usd": cost,
                    "net_benefit_usd": benefit - cost,
                }
            )
        )
    return pd.concat(rows, ignore_index=True)
